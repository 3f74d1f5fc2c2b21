"""Accumulating the regression statistics of 10 columns: QR factor vs the former Gram matrix.

The drift fit's use: many rows, about ten candidate columns, fed in chunks of
one million rows. Both accumulators see the same chunks in the same run
(:class:`hrgtc.drift.regression.GramAccumulator`, now the TSQR factor, and the former
co-moment accumulator kept in ``gram_accumulator.py``). Each chunk is generated
once and fed to ``REPEATS`` independent pairs of accumulators, the order QR/Gram
alternating from one feed to the next, so every repetition sees the same data
in the same process; ``seconds`` is the median over the repetitions of the
total time per side (``runs_seconds`` lists them) and ``ratio`` is QR over Gram.
The whole selection against the user's alternative (a statsmodels refit for
every candidate at every step) is ``bench_stepwise.py``.

Timed: accumulation (and selection) only; data generation is reported apart.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from bench_stepwise import NAMES, PENTER, PREMOVE, chunks
from gram_accumulator import OldGramAccumulator
from hrgtc.drift.stepwise import GramAccumulator, StepwiseRules, stepwise_from_accumulator

FULL_ROWS = 10_000_000  # 10 chunks of 1 M per repetition (25 M took 40 s of make bench)
QUICK_ROWS = 2_000_000
REPEATS = 3


def _peak_rss_mb() -> float:
    with open("/proc/self/status", encoding="ascii") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return round(int(line.split()[1]) / 1024.0, 1)
    return float("nan")


def accumulate_both(n: int, repeats: int = REPEATS) -> dict:
    """Feed the same chunks to ``repeats`` pairs of accumulators, alternating the order."""
    pairs = [(GramAccumulator(NAMES), OldGramAccumulator()) for _ in range(repeats)]
    seconds = {"qr": [0.0] * repeats, "gram": [0.0] * repeats}
    generate = 0.0
    feed = 0
    t0 = time.perf_counter()
    for X, y in chunks(n):
        generate += time.perf_counter() - t0
        for rep, (qr, gram) in enumerate(pairs):
            order = [("qr", qr), ("gram", gram)] if feed % 2 == 0 else [("gram", gram),
                                                                         ("qr", qr)]
            feed += 1
            for name, acc in order:
                t1 = time.perf_counter()
                acc.partial_fit(X, y)
                seconds[name][rep] += time.perf_counter() - t1
        t0 = time.perf_counter()
    t1 = time.perf_counter()
    result = stepwise_from_accumulator(pairs[0][0], rules=StepwiseRules(PENTER, PREMOVE))
    select = time.perf_counter() - t1
    return {"qr": float(np.median(seconds["qr"])), "gram": float(np.median(seconds["gram"])),
            "qr_runs": seconds["qr"], "gram_runs": seconds["gram"], "select": select,
            "generate": generate, "selected": list(result.selected),
            "steps": [f"{s.action} {s.term}" for s in result.history],
            "params": result.result.params.tolist()}


def run(quick: bool = False) -> list[dict]:
    """One line per figure: Gram accumulation, QR accumulation (with the ratio)."""
    n = QUICK_ROWS if quick else FULL_ROWS
    both = accumulate_both(n)
    peak = _peak_rss_mb()
    common = {"n": n, "columns": len(NAMES), "chunk_rows": 1_000_000, "peak_rss_mb": peak,
              "repeats": REPEATS}
    lines = [
        {"name": "accumulate_gram_10col", **common, "seconds": round(both["gram"], 3),
         "rate": round(n / both["gram"]),
         "runs_seconds": [round(t, 3) for t in both["gram_runs"]]},
        {"name": "accumulate_qr_10col", **common, "seconds": round(both["qr"], 3),
         "runs_seconds": [round(t, 3) for t in both["qr_runs"]],
         "rate": round(n / both["qr"]), "ratio": round(both["qr"] / both["gram"], 3),
         "generate_seconds": round(both["generate"], 3)},
    ]
    return lines


if __name__ == "__main__":
    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
