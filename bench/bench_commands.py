"""Whole commands against independent scripts, timed in the same run (issue 27, item 8).

Each line times two commands as fresh processes, hyperfine-style: the two alternate
(A B, B A, ...), each figure is the median of ``repeats`` runs of the whole process
(interpreter start, imports, reading, writing), and ``ratio`` is the median of the
ratios of each alternated pair (``ratio_of_medians`` beside it). Peak RSS of each is its
process's own (``wait4``).

* ``command_help``: ``hrgtc --help`` against ``python -c "import numpy"`` (goal <= 1.5);
* ``command_allan_oadev``: a script that loads 10^7 samples (``.npy``) and calls
  :func:`hrgtc.evaluation.allan.allan_deviation` against the same script calling
  ``allantools.oadev`` (goal: allantools / ours >= 8; ``speed_ratio`` is allantools'
  seconds over ours); the deviations must agree to 1e-9. Alternated with them, the
  script's floor (interpreter, numpy, ``np.load``, ``np.save``: ``floor_*``) and the floor
  with numba's start (its import and the first cached kernel loaded: ``numba_start_*``);
  ``*_speed_ratio`` is allantools' seconds over each, the most any such script can reach;
* ``command_calibrate_demo``: ``hrgtc calibrate`` on the demo campaign (7 soaks of 5 h
  and a 5 h cool-down at 200 Hz, ``hrgtc demo``'s files) against
  ``bench/plain_calibrate.py``, the paper's method in plain numpy on the same files
  (goal <= 2);
* ``command_compensate_file``: ``hrgtc compensate`` file to file (10 M rows) with the
  default options and with ``--motion keep`` against ``bench/plain_compensate.py``, a
  pyarrow streaming script (goal <= 1).

``--quick``: small sizes, 3 repeats; ``--calibrate``: the calibrate line alone. With
``HRGTC_BENCH_BEFORE=/path/to/src`` (the ``src`` folder of an earlier checkout, e.g.
``git archive COMMIT src | tar -x -C /tmp/before``)
every hrgtc command is also run from that tree in the same alternation, and each line
gains ``before_seconds`` and ``before_ratio`` (and ``before_motion_keep_*``): before and
after against the same reference in the same run.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parent
PYTHON = sys.executable
HRGTC = str(Path(sys.executable).with_name("hrgtc"))
BEFORE = os.environ.get("HRGTC_BENCH_BEFORE")


def before(argv: list[str]) -> list[str]:
    """``argv`` run on the hrgtc of :data:`BEFORE` (its ``src`` first on the path)."""
    if argv[0] == HRGTC:
        argv = [PYTHON, "-c", "import sys; sys.argv[0] = 'hrgtc'; from hrgtc.cli import main; "
                "sys.exit(main())", *argv[1:]]
    return ["env", f"PYTHONPATH={BEFORE}", *argv]


#: The commands' environment: Python writes its bytecode (``__pycache__``), as a user's
#: install has it after the first run; with ``PYTHONDONTWRITEBYTECODE`` set (as in some
#: sandboxes) every run of a command would compile hrgtc's modules from source again
#: (0.2-0.3 s of CPU for ``compensate``, most of ``hrgtc --help``'s own time), while the
#: scripts' numpy, pyarrow and allantools come with theirs.
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def _run(argv: list[str]) -> tuple[float, float]:
    """Wall seconds and peak RSS [MB] of one command (its output discarded)."""
    start = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               env=ENV)
    _, status, usage = os.wait4(process.pid, 0)
    seconds = time.perf_counter() - start
    process.returncode = os.waitstatus_to_exitcode(status)
    stderr = process.stderr.read().decode(errors="replace") if process.stderr else ""
    if process.stderr:
        process.stderr.close()
    if process.returncode != 0:
        raise RuntimeError(f"{argv[:3]} failed ({process.returncode}): {stderr[-2000:]}")
    return seconds, round(usage.ru_maxrss / 1024.0, 1)


def _label(argv: list[str]) -> str:
    """A command's short name: its program and first words (a ``-c`` script by its
    first import)."""
    words = []
    for arg in argv[:4]:
        if "\n" in arg:
            arg = next((line for line in arg.splitlines() if "allan" in line), "<script>")
            arg = f"<{arg.strip()}>"
        words.append(Path(arg).name if arg in (PYTHON, HRGTC) or arg.endswith(".py") else arg)
    return " ".join(words)


def compare(name: str, ours: list[str], theirs: list[str], repeats: int,
            more: dict[str, list[str]] | None = None, **extra: object) -> dict:
    """Alternate ``ours`` and ``theirs`` (and each of ``more``) ``repeats`` times."""
    more = dict(more or {})
    if BEFORE:
        more.update({f"before_{k}" if k else "before": before(argv)
                     for k, argv in (("", ours), *more.items())})
    commands = {"ours": ours, "theirs": theirs, **more}
    runs: dict[str, list[tuple[float, float]]] = {key: [] for key in commands}
    for argv in commands.values():  # one untimed run each: page cache and compiled
        _run(argv)  # kernels, as a user's second call finds them
    for k in range(repeats):
        order = list(commands) if k % 2 == 0 else list(commands)[::-1]
        for key in order:
            runs[key].append(_run(commands[key]))
    seconds = {key: [s for s, _ in value] for key, value in runs.items()}
    median = {key: statistics.median(value) for key, value in seconds.items()}
    pairs = [a / b for a, b in zip(seconds["ours"], seconds["theirs"], strict=True)]
    line = {"name": name, "n": repeats, "seconds": round(median["ours"], 3),
            "rate": round(1.0 / median["ours"], 4),
            "reference_seconds": round(median["theirs"], 3),
            "ratio": round(statistics.median(pairs), 3),
            "ratio_of_medians": round(median["ours"] / median["theirs"], 3),
            "ratio_each_pair": [round(r, 3) for r in pairs],
            "peak_rss_mb": max(m for _, m in runs["ours"]),
            "reference_peak_rss_mb": max(m for _, m in runs["theirs"]),
            "command": _label(ours), "reference": _label(theirs)}
    for key in more:
        key_pairs = [a / b for a, b in zip(seconds[key], seconds["theirs"], strict=True)]
        line[f"{key}_seconds"] = round(median[key], 3)
        line[f"{key}_ratio"] = round(statistics.median(key_pairs), 3)
        line[f"{key}_peak_rss_mb"] = max(m for _, m in runs[key])
    line.update(extra)
    return line


def help_line(repeats: int) -> dict:
    return compare("command_help", [HRGTC, "--help"], [PYTHON, "-c", "import numpy"], repeats,
                   goal_ratio=1.5)


_ALLAN_OURS = """
import sys, numpy as np
from hrgtc.evaluation.allan import allan_deviation
rate = np.load(sys.argv[1])
result = allan_deviation(rate, 200.0, taus="octave")
np.save(sys.argv[2], np.stack([result.taus_s, result.deviation]))
"""
#: The parts of the whole script's time that no Allan code can remove: the interpreter,
#: numpy's import, loading the .npy and saving a result ("floor"), and the same with the
#: start of a compiled numba kernel (numba's import and the first load of a cached kernel,
#: "numba_start"): allantools' seconds over the floor's bound any speed ratio.
_ALLAN_FLOOR = """
import sys, numpy as np
rate = np.load(sys.argv[1])
np.save(sys.argv[2], np.stack([rate[:24], rate[:24]]))
"""
_ALLAN_NUMBA_START = """
import sys, numpy as np
from hrgtc.evaluation import _allan_kernels
rate = np.load(sys.argv[1])
_allan_kernels.checkpoints(rate[:64], 0.0, 1)
np.save(sys.argv[2], np.stack([rate[:24], rate[:24]]))
"""
_ALLAN_THEIRS = """
import sys, numpy as np
import allantools
rate = np.load(sys.argv[1])
taus, dev, _, _ = allantools.oadev(rate, rate=200.0, data_type="freq", taus="octave")
np.save(sys.argv[2], np.stack([taus, dev]))
"""


def allan_line(folder: Path, n: int, repeats: int) -> dict:
    import numpy as np

    sys.path.insert(0, str(BENCH_DIR))
    from bench_allan import gyro_rate

    data = folder / "rate.npy"
    np.save(data, gyro_rate(n))
    ours, theirs = folder / "ours.npy", folder / "theirs.npy"
    parts = {key: [PYTHON, "-c", script, str(data), str(folder / f"{key}.npy")]
             for key, script in (("floor", _ALLAN_FLOOR), ("numba_start", _ALLAN_NUMBA_START))}
    line = compare("command_allan_oadev", [PYTHON, "-c", _ALLAN_OURS, str(data), str(ours)],
                   [PYTHON, "-c", _ALLAN_THEIRS, str(data), str(theirs)], repeats,
                   more=parts, samples=n, goal_speed_ratio=8.0)
    for key in parts:  # the best speed ratio a script with this start could reach
        line[f"{key}_speed_ratio"] = round(1.0 / line[f"{key}_ratio"], 2)
    a, b = np.load(ours), np.load(theirs)
    same = a.shape == b.shape and bool(np.array_equal(a[0], b[0]))
    line["speed_ratio"] = round(1.0 / line["ratio"], 2)
    line["same_taus"] = same
    line["max_rel_diff"] = float(np.max(np.abs(a[1] / b[1] - 1.0))) if same else None
    return line


def _campaign(folder: Path, quick: bool) -> tuple[list[str], str]:
    """The demo campaign's soaks and cool-down (``hrgtc demo``'s files, not timed)."""
    from hrgtc.settings.fleet import SETPOINTS_C, DemoSettings
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    s = DemoSettings.quick() if quick else DemoSettings()
    soaks = simulate_files([profiles.soak(t, s.soak_hours) for t in SETPOINTS_C],
                           folder / "soaks", "parquet", unit="paper-unit",
                           sample_rate_hz=s.sample_rate_hz, seed=s.seed)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, s.ramp_hours)], folder / "runs",
                          "parquet", unit="paper-unit", sample_rate_hz=s.sample_rate_hz,
                          seed=s.seed + 1)
    return [str(w.path) for w in soaks], str(cool[0].path)


def calibrate_line(folder: Path, quick: bool, repeats: int) -> dict:
    import pyarrow.parquet as pq

    soaks, cool = _campaign(folder, quick)
    rows = sum(pq.ParquetFile(p).metadata.num_rows for p in [*soaks, cool])
    return compare(
        "command_calibrate_demo",
        [HRGTC, "calibrate", "--soak", *soaks, "--drift", cool, "-o",
         str(folder / "unit.json"), "--force"],
        [PYTHON, str(BENCH_DIR / "plain_calibrate.py"), str(folder / "plain.json"),
         "--soak", *soaks, "--drift", cool], repeats, samples=rows, goal_ratio=2.0)


def compensate_line(folder: Path, quick: bool, repeats: int) -> dict:
    import pyarrow.parquet as pq

    sys.path.insert(0, str(BENCH_DIR))
    from bench_compensate import _model
    from hrgtc.model import save_model
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    sample_rate_hz = 20.0 if quick else 200.0
    model_path = str(folder / "unit.json")
    save_model(_model(folder, sample_rate_hz), model_path)
    run = simulate_files([profiles.warmup(-20.0, 20.0, 1.0 if quick else 14.0)],
                         folder / "run", "parquet", sample_rate_hz=sample_rate_hz, seed=3)[0]
    out = str(folder / "out.parquet")
    ours = [HRGTC, "compensate", str(run.path), "-m", model_path, "-o", out, "--force"]
    return compare(
        "command_compensate_file", ours,
        [PYTHON, str(BENCH_DIR / "plain_compensate.py"), model_path, str(run.path), out],
        repeats, more={"motion_keep": [*ours, "--motion", "keep"]},
        samples=pq.ParquetFile(run.path).metadata.num_rows, goal_ratio=1.0)


def run(quick: bool = False) -> list[dict]:
    out = [help_line(7 if quick else 15)]
    with tempfile.TemporaryDirectory() as tmp:
        out.append(allan_line(Path(tmp), 1_000_000 if quick else 10_000_000, 3 if quick else 5))
    with tempfile.TemporaryDirectory() as tmp:
        out.append(calibrate_line(Path(tmp), quick, 3))
    with tempfile.TemporaryDirectory() as tmp:
        out.append(compensate_line(Path(tmp), quick, 3 if quick else 5))
    return out


def calibrate_only(quick: bool) -> list[dict]:
    """``--calibrate``: the calibrate line alone."""
    with tempfile.TemporaryDirectory() as tmp:
        return [calibrate_line(Path(tmp), quick, 3)]


if __name__ == "__main__":
    quick = "--quick" in sys.argv
    for line in calibrate_only(quick) if "--calibrate" in sys.argv else run(quick=quick):
        print(json.dumps(line), flush=True)
