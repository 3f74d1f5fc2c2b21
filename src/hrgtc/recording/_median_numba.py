"""The at-rest detector's bracketing median as numba compiled it, for the numba spike
filter (``_spike_kernel.segment_stops`` calls it inside its own compiled loop, which cannot
call C): a verbatim copy of ``_motion_kernel.median`` before that module was written in C
(``_motion_native.c``, whose ``median`` gives the same value bit for bit,
``tests/recording/test_motion_native.py``). Nothing else imports it; it goes when the spike
filter is in C too.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_JIT = {"cache": True, "nogil": True, "fastmath": False}


@njit(**_JIT)
def _pick(sample: np.ndarray, count: int, k_lo: int, k_hi: int, margin: int) -> tuple:
    """Values of ``sample`` (sorted, drawn from ``count`` values) bracketing ranks
    ``k_lo``..``k_hi`` of all of them with ``margin`` sample ranks to spare."""
    s = sample.size
    lo = sample[max(int(k_lo / count * s) - margin, 0)]
    hi = sample[min(int(k_hi / count * s) + margin, s - 1)]
    return lo, hi


@njit(**_JIT)
def median(values: np.ndarray) -> float:
    """``np.median(values)`` of finite values: a sorted sample of 512 brackets the middle
    ranks, one branch-free pass counts what lies below and keeps what lies between, and
    the middle values are selected among those (all of them if the bracket missed)."""
    n = values.size
    if n <= 2048:
        return np.median(values)
    sample = np.sort(values[::n // 512])
    k_lo, k_hi = (n - 1) // 2, n // 2
    lo, hi = _pick(sample, n, k_lo, k_hi, 2 * int(np.sqrt(sample.size)) + 8)
    inside = np.empty(n)
    below = equal_lo = equal_hi = kept = 0
    for i in range(n):
        v = values[i]
        below += v < lo
        equal_lo += v == lo
        equal_hi += (v == hi) & (hi != lo)
        inside[kept] = v
        kept += (lo < v) & (v < hi)
    r_lo, r_hi = k_lo - below, k_hi - below
    if r_lo < 0 or r_hi >= equal_lo + kept + equal_hi:
        return np.median(values)
    between = inside[:kept]
    picked = np.empty(2)
    ordered = between
    for j in range(2):
        r = r_lo if j == 0 else r_hi
        if r < equal_lo:
            picked[j] = lo
        elif r < equal_lo + kept:
            if j == 1 and r_lo == r_hi:
                picked[j] = picked[0]
            elif j == 1 and equal_lo <= r_lo:  # r_lo's value was selected: the next one up
                picked[j] = np.min(ordered[r_lo - equal_lo + 1:])
            else:
                ordered = np.partition(between, r - equal_lo)  # a partitioned copy
                picked[j] = ordered[r - equal_lo]
        else:
            picked[j] = hi
    if k_lo == k_hi:
        return picked[0]
    return (picked[0] + picked[1]) / 2
