"""The history step on the real corpus (issue 29, third Done-when): kept only where it wins
held out, and no real file's held-out figure worse than without it.

For each file of ``tests/real_corpus.py`` the path of ``tests/test_real_corpus.py`` (calibrate
on the first 60 % of the time, compensate the rest, the held-out still periods' 60 s means
less each period's mean, as a ratio to the numpy line): today's model, then
:func:`hrgtc.pipeline.terms.add_history` on each axis (a history term kept only where the
leave-one-run-out score beats today's; with one training run there is none, and nothing is
kept), and, to show what the keep rule decides, ``play`` forced on top of today's terms at
the default width::

    PYTHONPATH=src python bench/bench_history_corpus.py            # every file
    PYTHONPATH=src python bench/bench_history_corpus.py vn100      # one
    PYTHONPATH=src python bench/bench_history_corpus.py pan        # the PAN cold test

One JSON line per file and axis: ``ratio_today``, ``ratio_history`` (the model the history
step keeps), ``added``, ``ratio_play_forced``, the scores and ``worse`` (the history
step's figure above today's).
"""

from __future__ import annotations

import json
import sys
import tempfile
import time
import warnings
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / "tests"
_FLAGS = {"terms": "--terms", "play_width_c": "--play-width-c", "select": "--select",
          "penter": "--penter", "premove": "--premove"}


def _cli(args: list) -> None:
    from typer.testing import CliRunner

    from hrgtc.cli import app

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # beyond the trained temperatures, by design
        result = CliRunner().invoke(app, [str(a) for a in args])
    if result.exit_code != 0:
        raise RuntimeError(result.output)


def _options(options: dict) -> list[str]:
    out: list[str] = []
    for key, value in options.items():
        out += [_FLAGS[key], ",".join(value) if isinstance(value, tuple) else str(value)]
    return out


class _Fitted:
    """A model file read back: its axes (what the history step judges) and its path."""

    def __init__(self, path: Path):
        from hrgtc.model import load_model

        self.path, self.axes = path, load_model(path).axes
        self.figures: dict[str, float] = {}


def _fit(real, path: Path, directory: Path, options: dict) -> _Fitted:

    model = directory / f"model-{len(list(directory.glob('model-*.json')))}.json"
    _cli(["calibrate", "--drift", path, *real.args, "--holdout-fraction", "0.4",
          *_options(options), "-o", model, "--force"])
    return _Fitted(model)


def _ratios(real, path: Path, directory: Path, model: _Fitted) -> dict[str, float]:
    import pyarrow.parquet as pq

    from real_corpus import line_figures, split_s

    reading = real.read(path)
    output = directory / "held.parquet"
    _cli(["compensate", path, "--model", model.path, *real.args, "--start",
          f"{split_s(reading):.6f}", "-o", output, "--force"])
    table = pq.read_table(output)
    time_s = table.column("time_s").to_numpy() - reading.origin_s
    compensated = {a: table.column(f"rate_comp_dph_{a}").to_numpy() for a in "xyz"}
    return {axis: f["ratio"] for axis, f in
            line_figures(reading, real.still, time_s, compensated).items()}


def run(real, path: Path, directory: Path) -> list[dict]:
    from hrgtc.pipeline.terms import ALL_IN, add_history

    today = _fit(real, path, directory, {})
    base = _ratios(real, path, directory, today)
    rows = []
    for axis in base:
        choice = add_history(lambda o: today if not o else _fit(real, path, directory, o),
                             axis=axis)
        kept = _ratios(real, path, directory, choice.model)[axis] if choice.added else base[axis]
        terms = (*today.axes[axis].drift.selected, "play")
        forced = _fit(real, path, directory, {**ALL_IN, "terms": terms})
        rows.append({"file": real.name, "axis": axis, "ratio_today": round(base[axis], 4),
                     "ratio_history": round(kept, 4), "added": list(choice.added),
                     "ratio_play_forced": round(_ratios(real, path, directory, forced)[axis], 4),
                     "scores": {k: (None if v == float("inf") else round(v, 4))
                                for k, v in choice.scores.items()},
                     "terms_today": list(today.axes[axis].drift.selected),
                     "worse": kept > base[axis]})
    return rows


#: The PAN cold test (tests/test_against_a_line.py): a burst logger with a raw count, its
#: temperature mapped from the hand log; its figure is the held-out 10 s bias stability.
PAN = TESTS / "data" / "pan-cold-test"
PAN_ARGS = ("--thermometer", "sensor", "--gaps", "bridge", "--time-unit", "ms",
            "--rate-unit", "radps", "--col", "time_s=time (ms),rate_dph_x=gyrox rad/s,"
            "rate_dph_y=gyroy rad/s,rate_dph_z=gyroz rad/s,temperature_c=temp",
            "--temp-ref", PAN / "pan_etu_cold_handlog_2020-03-07.csv",
            "--temp-ref-col", "time_s=Time,temperature_c=C1 (C)", "--temp-ref-start", "15:45")


def _pan_fit(directory: Path, options: dict) -> _Fitted:
    from typer.testing import CliRunner

    from hrgtc.cli import app

    model = directory / f"pan-{len(list(directory.glob('pan-*.json')))}.json"
    args = ["calibrate", "--drift", PAN / "pan_tvc_cold_2020-03-07.csv", *PAN_ARGS,
            "--holdout-fraction", "0.4", *_options(options), "-o", model, "--json"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = CliRunner().invoke(app, [str(a) for a in args])
    if result.exit_code != 0:
        raise RuntimeError(result.output)
    fitted = _Fitted(model)
    document = json.loads(result.stdout[result.stdout.index("{"):])
    fitted.figures = {a: document["axes"][a]["validation"][0]["bias_stability_10s_dph"][
        "compensated"] for a in "xyz"}
    return fitted


def pan(directory: Path) -> list[dict]:
    """The history step on the PAN cold test, per axis (held-out 10 s bias stability)."""
    from hrgtc.pipeline.terms import ALL_IN, add_history

    today = _pan_fit(directory, {})
    rows = []
    for axis in "xyz":
        choice = add_history(lambda o: today if not o else _pan_fit(directory, o), axis=axis)
        terms = (*today.axes[axis].drift.selected, "play")
        forced = _pan_fit(directory, {**ALL_IN, "terms": terms})
        rows.append({"file": "pan-cold-test", "axis": axis,
                     "stability_today_dph": round(today.figures[axis], 4),
                     "stability_history_dph": round(choice.model.figures[axis], 4),
                     "added": list(choice.added),
                     "stability_play_forced_dph": round(forced.figures[axis], 4),
                     "scores": {k: (None if v == float("inf") else round(v, 4))
                                for k, v in choice.scores.items()},
                     "terms_today": list(today.axes[axis].drift.selected),
                     "worse": choice.model.figures[axis] > today.figures[axis]})
    return rows


def main(argv: list[str]) -> int:
    sys.path.insert(0, str(TESTS))
    from real_corpus import CORPUS

    start = time.perf_counter()
    name = argv[0] if argv else ""
    for real in (r for r in CORPUS if r.name.startswith(name)):
        with tempfile.TemporaryDirectory() as directory:
            path = real.unpacked(Path(directory))
            for row in run(real, path, Path(directory)):
                row["seconds"] = round(time.perf_counter() - start, 1)
                print(json.dumps(row), flush=True)
    if "pan-cold-test".startswith(name):
        with tempfile.TemporaryDirectory() as directory:
            for row in pan(Path(directory)):
                row["seconds"] = round(time.perf_counter() - start, 1)
                print(json.dumps(row), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
