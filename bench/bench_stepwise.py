"""Stepwise regression over 10 candidate columns: sufficient statistics vs naive refits.

Ours: the rows are generated in chunks of one million and fed to
:class:`hrgtc.drift.QRAccumulator` (the full matrix is never held), then
:func:`hrgtc.drift.stepwise.stepwise_from_accumulator` selects the terms from the
statistics alone. Naive: the same rows in one matrix and the same MATLAB
``stepwisefit`` rules, but a statsmodels OLS refit for every candidate at every
step. The naive run happens in its own subprocess so that its memory (the full
1 M x 10 matrix and statsmodels' copies) does not count against ours.

Timed: ours = accumulation + selection (data generation reported apart);
naive = the selection on data already in memory. A second line,
``stepwise_10col_in_memory``, times :func:`hrgtc.drift.stepwise.stepwise` on the same
rows held in one matrix (as a drift fit calls it): accumulation, selection and the
extended-precision refinement of the final model's coefficients, which runs once.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from hrgtc.drift.regression import EXTENDED_PRECISION
from hrgtc.drift.stepwise import (
    GramAccumulator,
    StepwiseRules,
    stepwise,
    stepwise_from_accumulator,
)

FULL_ROWS = 1_000_000  # the naive loop refits statsmodels per candidate: 1 M keeps make bench short
QUICK_ROWS = 250_000
CHUNK_ROWS = 1_000_000
SEED = 20120515
NAMES = tuple(f"x{k + 1}" for k in range(10))
# y depends on four of the ten columns; columns have offsets, scales and correlations.
TRUE_COEFFICIENTS = {0: 0.8, 2: -0.5, 5: 0.05, 8: 1.2}
SCALES = np.array([1.0, 2.0, 0.5, 10.0, 1.0, 30.0, 0.1, 1.0, 3.0, 1.0])
OFFSETS = np.array([0.0, 5.0, -2.0, 100.0, 0.0, 1e3, 4425.0, 0.0, -7.0, 1.0])
NOISE_STD = 2.0
PENTER, PREMOVE = 0.05, 0.10


def _peak_rss_mb() -> float:
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)


def chunk(index: int, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """Rows of chunk ``index``: deterministic, independent of how chunks are grouped."""
    rng = np.random.default_rng([SEED, index])
    X = rng.standard_normal((rows, len(NAMES)))
    X[:, 1] += 0.6 * X[:, 0]  # correlated candidates
    X[:, 4] += 0.8 * X[:, 2]
    X *= SCALES
    X += OFFSETS
    y = 3.0 + NOISE_STD * rng.standard_normal(rows)
    for column, coefficient in TRUE_COEFFICIENTS.items():
        y += coefficient * X[:, column]
    return X, y


def chunks(n: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """All n rows, one chunk at a time."""
    for index, start in enumerate(range(0, n, CHUNK_ROWS)):
        yield chunk(index, min(CHUNK_ROWS, n - start))


def run_ours(n: int) -> dict:
    """Chunked accumulation, then stepwise from the statistics."""
    acc = GramAccumulator(NAMES)
    fit_seconds = generate_seconds = 0.0
    t0 = time.perf_counter()
    for X, y in chunks(n):
        t1 = time.perf_counter()
        generate_seconds += t1 - t0
        acc.partial_fit(X, y)
        t0 = time.perf_counter()
        fit_seconds += t0 - t1
    t1 = time.perf_counter()
    result = stepwise_from_accumulator(acc, rules=StepwiseRules(PENTER, PREMOVE))
    fit_seconds += time.perf_counter() - t1
    return {"seconds": fit_seconds, "generate_seconds": generate_seconds,
            "peak_rss_mb": _peak_rss_mb(), "selected": list(result.selected),
            "params": result.result.params.tolist(),
            "steps": [f"{s.action} {s.term}" for s in result.history]}


def run_in_memory(n: int, repeat: int = 3) -> dict:
    """The rows in one matrix: :func:`stepwise` with its refinement of the final model.

    Steady state, as the naive side (whose statsmodels is imported before its clock
    starts): one small call first loads the compiled refinement kernel (numba's import
    and its on-disk cache, a once-per-process cost like an import), then the median of
    ``repeat`` timed calls.
    """
    X, y = _matrix(n)
    stepwise(X[:1000], y[:1000], names=NAMES, rules=StepwiseRules(PENTER, PREMOVE),
             refine=EXTENDED_PRECISION)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = stepwise(X, y, names=NAMES, rules=StepwiseRules(PENTER, PREMOVE),
                          refine=EXTENDED_PRECISION)
        times.append(time.perf_counter() - t0)
    seconds = float(np.median(times))
    return {"seconds": seconds, "selected": list(result.selected),
            "params": result.result.params.tolist(), "refined": EXTENDED_PRECISION}


def _matrix(n: int) -> tuple[np.ndarray, np.ndarray]:
    X = np.empty((n, len(NAMES)))
    y = np.empty(n)
    for index, start in enumerate(range(0, n, CHUNK_ROWS)):
        X[start:start + CHUNK_ROWS], y[start:start + CHUNK_ROWS] = \
            chunk(index, min(CHUNK_ROWS, n - start))
    return X, y


def naive_stepwise(X: np.ndarray, y: np.ndarray) -> dict:
    """MATLAB stepwisefit rules with a statsmodels OLS refit for every candidate."""
    import statsmodels.api as sm  # imported by _naive_main before its clock starts

    included: list[int] = []
    steps, fits = [], 0
    while True:
        best: tuple[int, float] | None = None
        for j in (j for j in range(X.shape[1]) if j not in included):
            cols = sorted([*included, j])
            fit = sm.OLS(y, sm.add_constant(X[:, cols], has_constant="add")).fit()
            fits += 1
            p = float(fit.pvalues[cols.index(j) + 1])
            if best is None or p < best[1]:
                best = (j, p)
        if best is not None and best[1] < PENTER:
            included.append(best[0])
            steps.append(f"added {NAMES[best[0]]}")
            continue
        cols = sorted(included)
        final = sm.OLS(y, sm.add_constant(X[:, cols], has_constant="add")).fit()
        fits += 1
        if not cols or final.pvalues[1:].max() <= PREMOVE:
            break
        worst = cols[int(np.argmax(final.pvalues[1:]))]
        included.remove(worst)
        steps.append(f"removed {NAMES[worst]}")
    return {"selected": [NAMES[j] for j in cols], "params": final.params.tolist(),
            "steps": steps, "fits": fits}


def _naive_main(n: int) -> None:
    import statsmodels.api  # noqa: F401 - the import is not the method's cost

    X, y = _matrix(n)
    t0 = time.perf_counter()
    out = naive_stepwise(X, y)
    out["seconds"] = time.perf_counter() - t0
    out["peak_rss_mb"] = _peak_rss_mb()
    print(json.dumps(out), flush=True)


def run(quick: bool = False) -> list[dict]:
    """Ours vs naive on 1 M rows (250 000 with ``quick``): streamed, then in memory."""
    n = QUICK_ROWS if quick else FULL_ROWS
    ours = run_ours(n)
    proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--naive", str(n)],
                          capture_output=True, text=True, check=True)
    naive = json.loads(proc.stdout.strip().splitlines()[-1])
    same = ours["selected"] == naive["selected"]
    a, b = np.array(ours["params"]), np.array(naive["params"])
    rel = float(np.max(np.abs(a - b) / np.abs(b))) if same else float("nan")
    return [{"name": "stepwise_10col", "n": n, "columns": len(NAMES),
             "seconds": round(ours["seconds"], 3), "rate": round(n / ours["seconds"]),
             "peak_rss_mb": ours["peak_rss_mb"],
             "generate_seconds": round(ours["generate_seconds"], 3),
             "naive_seconds": round(naive["seconds"], 3),
             "naive_peak_rss_mb": naive["peak_rss_mb"], "naive_fits": naive["fits"],
             "speedup": round(naive["seconds"] / ours["seconds"], 1),
             "same_selected": same, "max_rel_coef_diff": rel,
             "selected": ours["selected"], "steps": ours["steps"],
             "naive_steps": naive["steps"]},
            _in_memory_line(n, naive)]


def _in_memory_line(n: int, naive: dict) -> dict:
    ours = run_in_memory(n)
    same = ours["selected"] == naive["selected"]
    a, b = np.array(ours["params"]), np.array(naive["params"])
    rel = float(np.max(np.abs(a - b) / np.abs(b))) if same else float("nan")
    return {"name": "stepwise_10col_in_memory", "n": n, "columns": len(NAMES),
            "seconds": round(ours["seconds"], 3), "rate": round(n / ours["seconds"]),
            "refined": ours["refined"], "naive_seconds": round(naive["seconds"], 3),
            "speedup": round(naive["seconds"] / ours["seconds"], 1), "same_selected": same,
            "max_rel_coef_diff": rel, "selected": ours["selected"]}


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--naive":
        _naive_main(int(sys.argv[2]))
    else:
        print(json.dumps(run(quick="--quick" in sys.argv)))
