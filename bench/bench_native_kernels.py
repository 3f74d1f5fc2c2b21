"""The C kernels against the numba kernels they replaced, each alone, in steady state.

Per kernel: the spike filter's two tests over one channel (``recording/_spike_native.c``;
numba: ``tests/recording/_spike_numba_reference.py``), a 200 Hz stream with spikes, the
command's settings (60 s windows); the df/dt filter's pass (``drift/_rate_native.c``;
numba: ``drift/_rate_numba.filter_run``) over a jittered 200 Hz clock; the soak
plateaus' block index and sums (``thermometry/_plateau_native.c``; numba:
``tests/thermometry/_plateau_numba_reference.py``), 10 s blocks; the refinement's
weighted double-double pass over 6 columns (``drift/_extended_native.c``; numba:
``tests/drift/_extended_numba_reference.py``).

Both sides run in this process on the same arrays; each is called once first (numba loads
or compiles its kernel then), then the two are timed alternately, ``--repeats`` times
(default 9), and the medians are reported with their ratio (numba / C: above 1, C is
faster). CPU seconds of this process (``time.process_time``: the machine is shared).
Prints one JSON line per kernel and size. ``--quick``: the smaller size only.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

SIZES = (1_000_000, 4_000_000)
QUICK_SIZES = (1_000_000,)


def _spike_cases(n: int):
    from hrgtc.recording import _spike_kernel as c
    from hrgtc.recording import spikes
    from recording import _spike_numba_reference as numba

    rng = np.random.default_rng(5)
    t = np.arange(n) / 200.0 + 1.7e9
    x = np.cumsum(rng.standard_normal(n)) * 1e-3 + rng.standard_normal(n)
    x[rng.integers(0, n, n // 1000)] += 30.0
    values = (spikes.SPIKE_K, 1e-3, spikes.SPIKE_WINDOW_S, float(spikes.GAP_PERIODS),
              1.0 + spikes.GAP_TOLERANCE, spikes.MIN_WINDOW_SAMPLES, spikes._MAD_TO_SIGMA,
              spikes._SECOND_DIFF)
    mine, theirs = c.SpikeRule(*values), numba.SpikeRule(*values)
    for test in ("spike_mask", "across_mask"):
        yield test, _bound(getattr(c, test), t, x, mine), _bound(getattr(numba, test), t, x,
                                                                 theirs)


def _bound(function: Callable, *args: object) -> Callable[[], object]:
    return lambda: function(*args)


def _rate_cases(n: int):
    from hrgtc.drift import _rate_kernel as c
    from hrgtc.drift import _rate_numba as numba
    from hrgtc.drift.rate_filter import new_state

    rng = np.random.default_rng(6)
    x = np.cumsum(rng.standard_normal(n)) * 1e-3
    t = 1.7e9 + np.cumsum(rng.uniform(0.004, 0.006, n))  # a jittered 200 Hz clock
    rate, lag, none = np.empty(n), np.empty(n), np.zeros(0, np.int8)
    yield "rate_pass", (lambda: c.rate_pass(x, t, 30.0, none, new_state(), rate, lag)), (
        lambda: numba.filter_run(x, t, 30.0, none, new_state(), rate, lag))


def _plateau_cases(n: int):
    from hrgtc.thermometry import _plateau_kernel as c
    from thermometry import _plateau_numba_reference as numba

    rng = np.random.default_rng(7)
    t = 1.7e9 + np.cumsum(rng.uniform(0.004, 0.006, n))
    freq, chamber = 4417.0 + rng.standard_normal(n), 20.0 + rng.standard_normal(n)
    block = c.block_index(t, 10.0)
    yield "block_index", (lambda: c.block_index(t, 10.0)), (lambda: numba.block_index(t, 10.0))
    yield "block_sums", (lambda: c.block_sums(block, t, freq, 4417.0, chamber)), (
        lambda: numba.block_sums(block, t, freq, 4417.0, chamber))


def _extended_cases(n: int):
    from drift import _extended_numba_reference as numba
    from hrgtc.drift import _extended_kernel as c

    rng = np.random.default_rng(8)
    k = 6
    X = rng.standard_normal((n, k)) + np.arange(k) * 1e3
    y = X @ rng.standard_normal(k) + 4417.0
    scaling = (np.append(np.arange(k) * 1e3, 4417.0), np.full(k + 1, 0.5))
    weights = rng.uniform(0.5, 2.0, n)
    x = (rng.standard_normal(k + 1), np.zeros(k + 1))
    r, f, g = (np.empty(n), np.empty(n)), np.empty(n), (np.empty(k + 1), np.empty(k + 1))
    yield "residual_pass", (lambda: c.residual_pass(X, y, scaling, weights, x, r, f, g, False)), (
        lambda: numba.residual_pass(X, y, scaling, weights, x, r, f, g, False))


CASES: dict[str, Callable] = {"spike": _spike_cases, "rate": _rate_cases,
                              "plateau": _plateau_cases, "extended": _extended_cases}


def _seconds(call: Callable[[], object]) -> float:
    start = time.process_time()
    call()
    return time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--only", nargs="*", choices=sorted(CASES), default=sorted(CASES))
    args = parser.parse_args()
    for kernel in args.only:
        for n in QUICK_SIZES if args.quick else SIZES:
            for name, c_call, numba_call in CASES[kernel](n):
                c_call(), numba_call()  # numba loads (or compiles) its kernel here
                c_s, numba_s = [], []
                for _ in range(args.repeats):
                    c_s.append(_seconds(c_call))
                    numba_s.append(_seconds(numba_call))
                c_median, numba_median = statistics.median(c_s), statistics.median(numba_s)
                print(json.dumps({"name": f"native_{kernel}_{name}", "n": n,
                                  "c_s": round(c_median, 5), "numba_s": round(numba_median, 5),
                                  "numba_over_c": round(numba_median / c_median, 2)}),
                      flush=True)


if __name__ == "__main__":
    main()
