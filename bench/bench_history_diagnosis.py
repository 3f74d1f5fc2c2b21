"""Why the worst held-out runs of ``bench_history_heldout.py --history`` miss 1.15x: each
cause taken away in turn, on the same seeds and the same noise (docs/history.md, "Why the
worst runs").

Per seed, on the campaign of :mod:`bench_history_heldout` (unit-play, the play's power-on
state drawn per run):

* ``true_width``: the history step (:func:`hrgtc.pipeline.terms.add_history`) with the
  width fixed at the truth, 2 °C, in place of the one learned (cause a: the width);
* ``law_terms``: the law's own terms (f, f^2, f^3, g, f*g, play; the true width) fitted
  with no selection (cause c: the selection);
* ``law_terms_heldout_known``: the same, the held-out runs starting with the play's state
  where the power-on rule puts it (cause b, held out);
* ``law_terms_all_known``: the training runs too (cause b, training): what is left is the
  gyro's noise through the fitted coefficients and the statistic (causes d).

Each run's row also has ``expected``: ``sqrt(1 + (e/floor)^2)``, the ratio the model's own
error ``e`` (the true bias less the correction) would give without its chance correlation
with the noise over one run (cause d). One JSON line per variant (median [95 %], worst run,
worst heating or cooling stretch, runs above 1.15x of 60); ``-v`` writes the rows to stderr.

Usage: ``python bench/bench_history_diagnosis.py --seeds=20 [-v]``.
"""

from __future__ import annotations

import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_heldout import _measure, _stability
from bench_history_heldout import ALL_KEYS, HELDOUT_KEYS, TARGET, _campaign, _fit, _interval

#: The law of unit-play in the drift grammar, at its true width.
LAW = {"terms": ("f", "f^2", "f^3", "g", "f*g", "play"), "play_width_c": 2.0}
VARIANTS = ("true_width", "law_terms", "law_terms_heldout_known", "law_terms_all_known")


def _expected(path: Path, model, fs: float) -> float:
    """sqrt(1 + (e/floor)^2) of one run, e = true bias - correction (10 s blocks)."""
    from hrgtc import recording
    from hrgtc.compensate import Compensator

    run = recording.read(path)
    skip = round(model.drift.settings.warmup_s * fs)
    noise = run.rate_dph - run.metadata.input_rate_dph - run["bias_dph"]
    compensated = Compensator(model).transform(run)["rate_comp_dph"]
    error = (compensated - run.metadata.input_rate_dph - noise)[skip:]
    noise = noise[skip:]
    return float(np.hypot(1.0, _stability(error, fs) / _stability(noise, fs)))


def _rows(model, files: dict, fs: float, seed: int, variant: str) -> list[dict]:
    rows = []
    for name, path in files["heldout"].items():
        row = {"variant": variant, "seed": seed, "run": name, **_measure(path, model, fs)}
        row["ratio"] = row["comp"] / row["floor"]
        row["expected"] = _expected(path, model, fs)
        row["terms"] = list(model.drift.selected)
        rows.append(row)
    return rows


def _seed(seed: int, tmp: Path, fs: float, hours: float) -> list[dict]:
    from hrgtc.pipeline.terms import ALL_IN, add_history

    rows: list[dict] = []
    for variant, known in (("law_terms", ()), ("law_terms_heldout_known", HELDOUT_KEYS),
                           ("law_terms_all_known", ALL_KEYS)):
        files = _campaign(seed, tmp / variant, fs, hours, known=known)
        if variant == "law_terms":
            step = add_history(lambda options, f=files: _fit(f, options), (2.0,)).model
            rows += _rows(step, files, fs, seed, "true_width")
        rows += _rows(_fit(files, {**ALL_IN, **LAW}), files, fs, seed, variant)
    return rows


def _worst(row: dict) -> float:
    return max(row["ratio"], row.get("heating_ratio", 0.0), row.get("cooling_ratio", 0.0))


def summary(rows: list[dict], seconds: float) -> list[dict]:
    rng = np.random.default_rng(29)
    out = []
    for variant in VARIANTS:
        sel = [r for r in rows if r["variant"] == variant]
        ratios = [r["ratio"] for r in sel]
        low, high = _interval(ratios, rng)
        out.append({"name": f"history_diagnosis_{variant}", "n": len(sel),
                    "seconds": round(seconds, 1),
                    "ratio_median": round(statistics.median(ratios), 3),
                    "ratio_ci95": [round(low, 3), round(high, 3)],
                    "ratio_worst": round(max(ratios), 3),
                    "stretch_worst": round(max(_worst(r) for r in sel), 3),
                    "runs_over_target": sum(_worst(r) > TARGET for r in sel),
                    "expected_median": round(statistics.median(r["expected"] for r in sel), 3),
                    "expected_worst": round(max(r["expected"] for r in sel), 3),
                    "ratio_minus_expected_range": [
                        round(min(r["ratio"] - r["expected"] for r in sel), 3),
                        round(max(r["ratio"] - r["expected"] for r in sel), 3)]})
    return out


if __name__ == "__main__":
    count = next((int(a.split("=", 1)[1]) for a in sys.argv if a.startswith("--seeds=")), 20)
    start, rows = time.perf_counter(), []
    with tempfile.TemporaryDirectory() as folder:
        for seed in range(1, count + 1):
            rows += _seed(seed, Path(folder) / str(seed), 1.0, 5.0)
    for line in summary(rows, time.perf_counter() - start):
        print(json.dumps(line), flush=True)
    if "-v" in sys.argv:
        for row in rows:
            print(json.dumps({k: (round(v, 3) if isinstance(v, float) else v)
                              for k, v in row.items()}), file=sys.stderr)
