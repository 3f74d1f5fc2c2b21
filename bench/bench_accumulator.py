"""Accumulating the regression statistics of 10 columns: QR factor vs the former Gram matrix.

The drift fit's use: many rows, about ten candidate columns, fed in chunks of
one million rows. Both accumulators see the same chunks in the same run
(:class:`hrgtc.regression.GramAccumulator`, now the TSQR factor, and the former
co-moment accumulator kept in ``gram_accumulator.py``); ``ratio`` is QR time
over Gram time. A third line times the whole selection (accumulation plus
:func:`hrgtc.stepwise.stepwise_from_accumulator`) against the user's
alternative, a statsmodels OLS refit for every candidate at every step on the
rows held in memory (run in a subprocess by ``bench_stepwise.py``), at a
smaller size so the benchmark takes well under two minutes.

Timed: accumulation (and selection) only; data generation is reported apart.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from bench_stepwise import NAMES, PENTER, PREMOVE, chunks
from gram_accumulator import OldGramAccumulator
from hrgtc.stepwise import GramAccumulator, stepwise_from_accumulator

FULL_ROWS = 25_000_000
QUICK_ROWS = 2_000_000
NAIVE_FULL_ROWS = 2_000_000
NAIVE_QUICK_ROWS = 500_000


def _peak_rss_mb() -> float:
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return round(int(line.split()[1]) / 1024.0, 1)
    return float("nan")


def accumulate_both(n: int) -> dict:
    """Feed the same chunks to both accumulators; alternate which goes first."""
    qr, gram = GramAccumulator(NAMES), OldGramAccumulator()
    seconds = {"qr": 0.0, "gram": 0.0}
    generate = 0.0
    t0 = time.perf_counter()
    for index, (X, y) in enumerate(chunks(n)):
        generate += time.perf_counter() - t0
        order = [("qr", qr), ("gram", gram)] if index % 2 == 0 else [("gram", gram), ("qr", qr)]
        for name, acc in order:
            t1 = time.perf_counter()
            acc.partial_fit(X, y)
            seconds[name] += time.perf_counter() - t1
        t0 = time.perf_counter()
    t1 = time.perf_counter()
    result = stepwise_from_accumulator(qr, penter=PENTER, premove=PREMOVE)
    select = time.perf_counter() - t1
    return {"qr": seconds["qr"], "gram": seconds["gram"], "select": select,
            "generate": generate, "selected": list(result.selected),
            "steps": [f"{s.action} {s.term}" for s in result.history],
            "params": result.result.params.tolist()}


def run(quick: bool = False) -> list[dict]:
    """One line per figure: Gram accumulation, QR accumulation (with ratio), selection."""
    n = QUICK_ROWS if quick else FULL_ROWS
    both = accumulate_both(n)
    peak = _peak_rss_mb()
    common = {"n": n, "columns": len(NAMES), "chunk_rows": 1_000_000, "peak_rss_mb": peak}
    lines = [
        {"name": "accumulate_gram_10col", **common, "seconds": round(both["gram"], 3),
         "rate": round(n / both["gram"])},
        {"name": "accumulate_qr_10col", **common, "seconds": round(both["qr"], 3),
         "rate": round(n / both["qr"]), "ratio": round(both["qr"] / both["gram"], 3),
         "generate_seconds": round(both["generate"], 3)},
    ]
    n_naive = NAIVE_QUICK_ROWS if quick else NAIVE_FULL_ROWS
    small = accumulate_both(n_naive)
    ours = small["qr"] + small["select"]
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve().parent
                                               / "bench_stepwise.py"), "--naive", str(n_naive)],
                          capture_output=True, text=True, check=True)
    naive = json.loads(proc.stdout.strip().splitlines()[-1])
    a, b = np.array(small["params"]), np.array(naive["params"])
    same = small["selected"] == naive["selected"]
    lines.append({"name": "stepwise_qr_vs_statsmodels_loop", "n": n_naive,
                  "columns": len(NAMES), "seconds": round(ours, 3), "rate": round(n_naive / ours),
                  "peak_rss_mb": _peak_rss_mb(), "select_seconds": round(small["select"], 4),
                  "statsmodels_seconds": round(naive["seconds"], 3),
                  "statsmodels_peak_rss_mb": naive["peak_rss_mb"],
                  "statsmodels_fits": naive["fits"],
                  "speedup": round(naive["seconds"] / ours, 1), "same_selected": same,
                  "max_rel_coef_diff": float(np.max(np.abs(a - b) / np.abs(b))) if same
                  else float("nan"), "steps": small["steps"]})
    return lines


if __name__ == "__main__":
    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
