"""Do ``hrgtc calibrate``'s results stay the same? Hashes to compare before and after a change.

    python bench/check_calibrate_unchanged.py OUT_DIR [--full]

With ``HRGTC_CHECK_SRC=/path/to/src`` the hrgtc of that ``src`` folder is run (an earlier
checkout: ``git archive COMMIT src | tar -x -C /tmp/before``).

Runs ``hrgtc calibrate --json`` (as a fresh process, the hrgtc on the path of this
interpreter) on

* the quick demo campaign (``DemoSettings.quick()``: the soaks and the cool-down of
  ``bench/bench_commands.py``), and with ``--full`` the full one the benchmark times;
* each real recording of ``tests/real_corpus.py`` as its newcomer's run calls it (the
  column mapping and units, ``--holdout-fraction 0.4``);
* the PAN cold test as ``tests/test_against_a_line.py`` calls it;

and writes into ``OUT_DIR`` each case's ``--json`` document and model file with
``created_utc`` taken out, its messages (standard error: the warnings, in their order),
plus ``hashes.json``: one SHA-256 per case and file. The files
are written into :data:`WORK` (emptied first): a model names its files, so the folder
must be the same before and after. Run it on the checkout before a change and after it, and
``diff -r`` the two folders: any difference is a changed figure to explain.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
HRGTC = str(Path(sys.executable).with_name("hrgtc"))
SRC = os.environ.get("HRGTC_CHECK_SRC")
#: Where the demo campaigns and models are written (the same folder every run;
#: ``HRGTC_CHECK_WORK`` names another, for two checks on one machine at once).
WORK = Path(os.environ.get("HRGTC_CHECK_WORK", "/tmp/hrgtc-check-calibrate"))
PAN = ROOT / "tests" / "data" / "pan-cold-test"
PAN_ARGS = (
    "--thermometer", "sensor", "--gaps", "bridge", "--time-unit", "ms", "--rate-unit", "radps",
    "--col", "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
    "rate_dph_z=gyroz rad/s,temperature_c=temp",
    "--temp-ref", str(PAN / "pan_etu_cold_handlog_2020-03-07.csv"),
    "--temp-ref-col", "time_s=Time,temperature_c=C1 (C)", "--temp-ref-start", "15:45",
    "--holdout-fraction", "0.4")


def _scrub(value: object) -> object:
    """``value`` without ``created_utc`` keys."""
    if isinstance(value, dict):
        return {k: _scrub(v) for k, v in value.items() if k != "created_utc"}
    if isinstance(value, list):
        return [_scrub(v) for v in value]
    return value


def _canonical(text: str) -> str:
    return json.dumps(_scrub(json.loads(text)), indent=1, sort_keys=True) + "\n"


def calibrate(name: str, args: list[str], folder: Path, out: Path) -> dict[str, str]:
    """Run one case; write its scrubbed documents into ``out``; their hashes."""
    model = folder / f"{name}.model.json"
    command = [HRGTC, "calibrate", *args, "-o", str(model), "--force", "--json"]
    env = {**os.environ, "COLUMNS": "200"}
    if SRC:
        command[0:1] = [sys.executable, "-c", "import sys; sys.argv[0] = 'hrgtc'; "
                        "from hrgtc.cli import main; sys.exit(main())"]
        env["PYTHONPATH"] = SRC
    result = subprocess.run(command, capture_output=True, text=True, env=env)
    if result.returncode != 0:
        raise SystemExit(f"{name}: exit {result.returncode}\n{result.stdout}\n{result.stderr}")
    hashes = {}
    stdout = result.stdout[result.stdout.index("{"):]
    for kind, text in (("document", stdout), ("model", model.read_text(encoding="utf-8"))):
        canonical = _canonical(text)
        (out / f"{name}.{kind}.json").write_text(canonical, encoding="utf-8")
        hashes[kind] = hashlib.sha256(canonical.encode()).hexdigest()
    (out / f"{name}.stderr.txt").write_text(result.stderr, encoding="utf-8")
    hashes["stderr"] = hashlib.sha256(result.stderr.encode()).hexdigest()
    print(name, hashes, flush=True)
    return hashes


def cases(folder: Path, full: bool) -> dict[str, list[str]]:
    """Each case's calibrate arguments (the demo campaigns are simulated into ``folder``)."""
    sys.path[:0] = [str(BENCH), str(ROOT / "tests")]
    from bench_commands import _campaign

    from real_corpus import CORPUS

    out = {}
    for label, quick in (("demo_quick", True), *((("demo_full", False),) if full else ())):
        soaks, cool = _campaign(folder / label, quick)
        out[label] = ["--soak", *soaks, "--drift", cool]
    for real in CORPUS:
        out[real.name] = ["--drift", str(real.unpacked(folder)), *real.args,
                          "--holdout-fraction", "0.4"]
    out["pan-cold-test"] = ["--drift", str(PAN / "pan_tvc_cold_2020-03-07.csv"), *PAN_ARGS]
    return out


def main(argv: list[str]) -> int:
    out = Path(argv[0])
    out.mkdir(parents=True, exist_ok=True)
    shutil.rmtree(WORK, ignore_errors=True)
    WORK.mkdir(parents=True)
    hashes = {name: calibrate(name, args, WORK, out)
              for name, args in cases(WORK, "--full" in argv).items()}
    shutil.rmtree(WORK, ignore_errors=True)
    (out / "hashes.json").write_text(json.dumps(hashes, indent=1, sort_keys=True) + "\n",
                                     encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
