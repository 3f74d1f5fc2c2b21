"""Compiled loops of the robust spike filter (:mod:`hrgtc.recording.spikes`).

One pass per channel and chunk computes, bit for bit, what the filter's numpy definition
computes (kept in ``tests/spikes_reference.py`` and compared on random and real records
by ``tests/recording/test_spike_kernel.py``), without a numpy temporary per step:

- the contiguous segments (a step beyond 2 median periods, or not finite, cuts);
- per segment of at least 3 samples, the second differences
  ``x[i] − (x[i−1] + x[i+1]) / 2``, the ``window_s`` windows (runs of one value of
  ``floor((t − min t) / window_s)``), the σ_MAD of each window (the median of the
  absolute finite second differences; a window with fewer than ``min_window`` of them
  takes its segment's) and the threshold ``max(k·σ_MAD, floor)`` of each sample;
- :func:`spike_mask`: the single-sample test of :func:`~hrgtc.recording.spikes.find_spikes`;
  :func:`across_mask`: the test of :func:`~hrgtc.recording.spikes.moving_across`.

The medians are order statistics (a selection in place, or the at-rest detector's
bracketing median for the gap test, give the values numpy's partition gives) and the
mean of the two middle values of an even count is ``(a + b) / 2``, as numpy computes
it; they are taken of absolute values and positive steps, so no zero's sign can differ.
``fastmath`` is off: no product is fused into an add.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hrgtc.recording._motion_kernel import median as _long_median

_JIT = {"cache": True, "nogil": True, "fastmath": False}


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


@njit(**_JIT)
def _sigma_of(values: np.ndarray, n: int, mad_to_sigma: float, second_diff: float) -> float:
    return mad_to_sigma * _median(values, n) / second_diff


@njit(**_JIT)
def segment_limits(ts: np.ndarray, xs: np.ndarray, k: float, floor: float, window_s: float,
                   min_window: int, mad_to_sigma: float, second_diff: float,
                   second: np.ndarray, limit: np.ndarray) -> None:
    """Fill ``second`` (the second differences) and ``limit`` (the threshold of each
    sample) of one segment of at least 3 samples."""
    n = xs.size
    for i in range(1, n - 1):
        second[i] = xs[i] - 0.5 * (xs[i - 1] + xs[i + 1])
    second[0] = second[1]
    second[n - 1] = second[n - 2]
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
    work = np.empty(n)
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
            if np.isfinite(second[i]):
                work[m] = abs(second[i])
                m += 1
        if m >= min_window:
            sigma = _sigma_of(work, m, mad_to_sigma, second_diff)
        else:
            if whole < 0.0:  # |second| of the segment's finite values
                whole_work = np.empty(n)
                count = 0
                for i in range(n):
                    if np.isfinite(second[i]):
                        whole_work[count] = abs(second[i])
                        count += 1
                whole = _sigma_of(whole_work, count, mad_to_sigma, second_diff) if count else 0.0
            sigma = whole
        value = k * sigma
        if value != value or floor != floor:  # np.maximum: NaN if either is NaN
            threshold = np.nan
        else:
            threshold = value if value >= floor else floor
        for i in range(a, b):
            limit[i] = threshold
        a = b


@njit(**_JIT)
def spike_mask(t: np.ndarray, x: np.ndarray, k: float, floor: float, window_s: float,
               gap_periods: float, tolerance: float, min_window: int, mad_to_sigma: float,
               second_diff: float) -> np.ndarray:
    """:func:`hrgtc.recording.spikes.find_spikes` of one channel, given its LSB floor."""
    n = x.size
    spikes = np.zeros(n, dtype=np.bool_)
    stops = segment_stops(t, gap_periods, tolerance)
    second = np.empty(n)
    limit = np.empty(n)
    start = 0
    for stop in stops:
        size = stop - start
        if size >= 3:
            xs = x[start:stop]
            sc = second[start:stop]
            lim = limit[start:stop]
            segment_limits(t[start:stop], xs, k, floor, window_s, min_window, mad_to_sigma,
                           second_diff, sc, lim)
            for i in range(1, size - 1):
                left = abs(xs[i] - xs[i - 1])
                right = abs(xs[i + 1] - xs[i])
                across = abs(xs[i + 1] - xs[i - 1])
                q = lim[i]
                spikes[start + i] = ((left > q) & (right > q) & (abs(sc[i]) > q)
                                     & (across <= q))
            q = lim[0]
            spikes[start] = ((abs(xs[1] - xs[0]) > q) & (abs(xs[0] - xs[2]) > q)
                             & (abs(xs[2] - xs[1]) <= q))
            q = lim[size - 1]
            spikes[stop - 1] = ((abs(xs[size - 1] - xs[size - 2]) > q)
                                & (abs(xs[size - 1] - xs[size - 3]) > q)
                                & (abs(xs[size - 2] - xs[size - 3]) <= q))
        start = stop
    return spikes


@njit(**_JIT)
def across_mask(t: np.ndarray, x: np.ndarray, k: float, floor: float, window_s: float,
                gap_periods: float, tolerance: float, min_window: int, mad_to_sigma: float,
                second_diff: float) -> np.ndarray:
    """:func:`hrgtc.recording.spikes.moving_across` of one channel, given its LSB floor."""
    n = x.size
    moving = np.zeros(n, dtype=np.bool_)
    stops = segment_stops(t, gap_periods, tolerance)
    second = np.empty(n)
    limit = np.empty(n)
    start = 0
    for stop in stops:
        size = stop - start
        if size >= 3:
            xs = x[start:stop]
            lim = limit[start:stop]
            segment_limits(t[start:stop], xs, k, floor, window_s, min_window, mad_to_sigma,
                           second_diff, second[start:stop], lim)
            for i in range(1, size - 1):
                across = abs(xs[i + 1] - xs[i - 1])
                if size >= 5 and 2 <= i < size - 2:
                    wide = abs(xs[i + 2] - xs[i - 2])
                    # np.maximum: NaN if either is NaN
                    if across != across or wide != wide:
                        across = np.nan
                    elif wide > across:
                        across = wide
                moving[start + i] = across > lim[i]
            # the edges: 0 > limit is never True for a limit >= 0
            moving[start] = 0.0 > lim[0]
            moving[stop - 1] = 0.0 > lim[size - 1]
        start = stop
    return moving
