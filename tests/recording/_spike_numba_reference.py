"""The spike filter's loops as they were compiled by numba before they were written in C
(``src/hrgtc/recording/_spike_native.c``): the reference ``test_spike_native.py`` compares
the C kernel with, bit for bit. Imported by the tests only (it imports numba).

The median of the steps of ``segment_stops`` is the motion kernel's as numba compiled it
(``_motion_numba_reference.median``, the reference of the motion kernel's C), so this
reference does not change when ``hrgtc.recording._motion_kernel`` does.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from recording._motion_numba_reference import median as _long_median

_JIT = {"cache": True, "nogil": True, "fastmath": False}


class SpikeRule(NamedTuple):
    """The filter's constants, one argument of the kernels (numba takes a namedtuple):
    the threshold ``max(k·σ_MAD, floor)`` over ``window_s`` windows of at least
    ``min_window`` finite second differences (σ_MAD = ``mad_to_sigma`` × median /
    ``second_diff``), segments cut at a step beyond ``gap_periods`` median periods
    (times ``tolerance``)."""

    k: float
    floor: float
    window_s: float
    gap_periods: float
    tolerance: float
    min_window: int
    mad_to_sigma: float
    second_diff: float


@njit(**_JIT)
def segment_stops(t: np.ndarray, gap_periods: float, tolerance: float) -> np.ndarray:
    """End (exclusive) of each contiguous segment of ``t``, in order; the first starts at 0.

    A step that is not ``<= gap_periods · median(positive finite steps) · tolerance``
    (``tolerance`` = 1 + the gap tolerance) starts a new segment; without any positive
    step the whole is one segment.
    """
    n = t.size
    if n < 2:
        out = np.empty(1 if n else 0, dtype=np.int64)
        if n:
            out[0] = n
        return out
    positive = np.empty(n - 1)
    count = 0
    for i in range(n - 1):
        step = t[i + 1] - t[i]
        if np.isfinite(step) and step > 0:
            positive[count] = step
            count += 1
    if count == 0:
        out = np.empty(1, dtype=np.int64)
        out[0] = n
        return out
    limit = gap_periods * _long_median(positive[:count]) * tolerance
    stops = np.empty(n, dtype=np.int64)
    s = 0
    for i in range(n - 1):
        if not (t[i + 1] - t[i] <= limit):
            stops[s] = i + 1
            s += 1
    stops[s] = n
    return stops[:s + 1]


@njit(**_JIT)
def _select(a: np.ndarray, n: int, k: int) -> float:
    """The k-th smallest of ``a[:n]`` (no NaN), ``a`` reordered in place so that every
    value after index k is at least it (Hoare's partition, median-of-three pivot: a run of
    equal values, as a quantised channel gives, splits in the middle)."""
    lo = 0
    hi = n - 1
    while hi > lo:
        mid = (lo + hi) >> 1
        if a[mid] < a[lo]:
            a[mid], a[lo] = a[lo], a[mid]
        if a[hi] < a[lo]:
            a[hi], a[lo] = a[lo], a[hi]
        if a[hi] < a[mid]:
            a[hi], a[mid] = a[mid], a[hi]
        pivot = a[mid]
        i = lo
        j = hi
        while i <= j:
            while a[i] < pivot:
                i += 1
            while pivot < a[j]:
                j -= 1
            if i <= j:
                a[i], a[j] = a[j], a[i]
                i += 1
                j -= 1
        if k <= j:
            hi = j
        elif k >= i:
            lo = i
        else:
            return a[k]
    return a[k]


@njit(**_JIT)
def _median(a: np.ndarray, n: int) -> float:
    """``np.median(a[:n])`` (no NaN; ``a`` reordered): the middle value, or the mean
    ``(a + b) / 2`` of the two middle values of an even count, as numpy computes it."""
    half = n >> 1
    if n & 1:
        return _select(a, n, half)
    low = _select(a, n, half - 1)
    high = a[half]
    for i in range(half + 1, n):
        if a[i] < high:
            high = a[i]
    return (low + high) / 2


#: Values of a window sampled to bracket its middle ranks, and the bracket's margin in
#: sample ranks (about 2.5 standard errors of a sample quantile).
_SAMPLE = 64
_MARGIN = 10


@njit(**_JIT)
def _bracketed_median(a: np.ndarray, n: int, between: np.ndarray) -> float:
    """``np.median(a[:n])`` (no NaN; ``a`` reordered), mostly without branches: a sorted
    sample of about 64 values brackets the middle ranks, one pass counts what lies below
    the bracket and keeps what lies inside it (in ``between``), and the middle values are
    selected among those (among all of them if the bracket missed). A selection on
    random values mispredicts a branch at every other comparison; the pass does not."""
    if n <= 4 * _SAMPLE:
        return _median(a, n)
    sample = np.sort(a[:n:n // _SAMPLE])
    size = sample.size
    k_lo = (n - 1) // 2
    k_hi = n // 2
    lo = sample[max(k_lo * size // n - _MARGIN, 0)]
    hi = sample[min(k_hi * size // n + _MARGIN, size - 1)]
    below = 0
    equal_lo = 0
    equal_hi = 0
    kept = 0
    for i in range(n):
        v = a[i]
        below += v < lo
        equal_lo += v == lo
        equal_hi += (v == hi) & (hi != lo)
        between[kept] = v
        kept += (lo < v) & (v < hi)
    r_lo = k_lo - below
    r_hi = k_hi - below
    if r_lo < 0 or r_hi >= equal_lo + kept + equal_hi:
        return _median(a, n)
    picked = np.empty(2)
    for j in range(2):
        r = r_lo if j == 0 else r_hi
        if r < equal_lo:
            picked[j] = lo
        elif r < equal_lo + kept:
            picked[j] = _select(between, kept, r - equal_lo)
        else:
            picked[j] = hi
    if k_lo == k_hi:
        return picked[0]
    return (picked[0] + picked[1]) / 2


@njit(**_JIT)
def _sigma_of(values: np.ndarray, n: int, mad_to_sigma: float, second_diff: float,
              between: np.ndarray) -> float:
    return mad_to_sigma * _bracketed_median(values, n, between) / second_diff


#: What :func:`segment_tests` tests: single-sample spikes, or motion across a sample.
SPIKE = 0
ACROSS = 1


@njit(inline="always", **_JIT)
def _second(xs: np.ndarray, i: int, n: int) -> float:
    """``x[i] − (x[i−1] + x[i+1]) / 2``; at a segment's edges, that of the next sample in."""
    j = min(max(i, 1), n - 2)
    return xs[j] - 0.5 * (xs[j - 1] + xs[j + 1])


@njit(inline="always", **_JIT)
def _test(xs: np.ndarray, i: int, n: int, q: float, mode: int) -> bool:
    """The test ``mode`` of sample i of a segment of n >= 3 samples, threshold q."""
    if mode == SPIKE:
        if i == 0:  # away from both of the next two samples, which agree
            return ((abs(xs[1] - xs[0]) > q) & (abs(xs[0] - xs[2]) > q)
                    & (abs(xs[2] - xs[1]) <= q))
        if i == n - 1:
            return ((abs(xs[n - 1] - xs[n - 2]) > q) & (abs(xs[n - 1] - xs[n - 3]) > q)
                    & (abs(xs[n - 2] - xs[n - 3]) <= q))
        return ((abs(xs[i] - xs[i - 1]) > q) & (abs(xs[i + 1] - xs[i]) > q)
                & (abs(_second(xs, i, n)) > q) & (abs(xs[i + 1] - xs[i - 1]) <= q))
    if i == 0 or i == n - 1:
        return 0.0 > q  # the edges: never for a threshold >= 0
    across = abs(xs[i + 1] - xs[i - 1])
    if n >= 5 and 2 <= i < n - 2:
        wide = abs(xs[i + 2] - xs[i - 2])
        if across != across or wide != wide:  # np.maximum: NaN if either is NaN
            across = np.nan
        elif wide > across:
            across = wide
    return across > q


@njit(**_JIT)
def segment_tests(ts: np.ndarray, xs: np.ndarray, rule: SpikeRule, mode: int,
                  out: np.ndarray) -> None:
    """The test ``mode`` of every sample of one segment of at least 3 samples, into ``out``.

    Window by window: the window's σ_MAD from its absolute finite second differences (the
    segment's when it has fewer than ``min_window``), the threshold
    ``max(k·σ_MAD, floor)``, then the test of each of its samples; no array as long as
    the segment is filled (a fresh array costs its page faults).
    """
    k, floor, window_s, min_window = rule.k, rule.floor, rule.window_s, rule.min_window
    mad_to_sigma, second_diff = rule.mad_to_sigma, rule.second_diff
    n = xs.size
    # the window origin: the smallest time that is not NaN (0 without a finite one)
    any_finite = False
    origin = np.inf
    for i in range(n):
        v = ts[i]
        if np.isfinite(v):
            any_finite = True
        if v < origin:
            origin = v
    if not any_finite:
        origin = 0.0
    whole = -1.0  # the segment's σ, computed when a window needs it
    a = 0
    previous = np.floor((ts[0] - origin) / window_s)
    work = np.empty(n)  # only a window's length is touched, unless the segment's σ is needed
    between = np.empty(n)
    for b in range(1, n + 1):
        if b < n:
            block = np.floor((ts[b] - origin) / window_s)
            step = block - previous
            previous = block
            if not (step != 0.0):
                continue
        # the window a:b
        m = 0
        for i in range(a, b):
            second = _second(xs, i, n)
            work[m] = abs(second)
            m += np.isfinite(second)
        if m >= min_window:
            sigma = _sigma_of(work, m, mad_to_sigma, second_diff, between)
        else:
            if whole < 0.0:  # |second| of the segment's finite values
                count = 0
                for i in range(n):
                    second = _second(xs, i, n)
                    work[count] = abs(second)
                    count += np.isfinite(second)
                whole = (_sigma_of(work, count, mad_to_sigma, second_diff, between)
                         if count else 0.0)
            sigma = whole
        value = k * sigma
        if value != value or floor != floor:  # np.maximum: NaN if either is NaN
            threshold = np.nan
        else:
            threshold = value if value >= floor else floor
        for i in range(a, b):
            out[i] = _test(xs, i, n, threshold, mode)
        a = b


@njit(**_JIT)
def _channel_test(t: np.ndarray, x: np.ndarray, rule: SpikeRule, mode: int) -> np.ndarray:
    out = np.zeros(x.size, dtype=np.bool_)
    start = 0
    for stop in segment_stops(t, rule.gap_periods, rule.tolerance):
        if stop - start >= 3:
            segment_tests(t[start:stop], x[start:stop], rule, mode, out[start:stop])
        start = stop
    return out


@njit(**_JIT)
def spike_mask(t: np.ndarray, x: np.ndarray, rule: SpikeRule) -> np.ndarray:
    """:func:`hrgtc.recording.spikes.find_spikes` of one channel, given its LSB floor."""
    return _channel_test(t, x, rule, SPIKE)


@njit(**_JIT)
def across_mask(t: np.ndarray, x: np.ndarray, rule: SpikeRule) -> np.ndarray:
    """:func:`hrgtc.recording.spikes.moving_across` of one channel, given its LSB floor."""
    return _channel_test(t, x, rule, ACROSS)
