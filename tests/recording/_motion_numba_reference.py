"""The at-rest detector's loops as numba compiled them before they were written in C
(``src/hrgtc/recording/_motion_native.c``): the reference ``test_motion_native.py`` compares
the C kernels with, bit for bit. Imported by the tests only (it imports numba); a verbatim
copy of ``hrgtc.recording._motion_kernel`` as it was, so it does not change when that
module does.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

_JIT = {"cache": True, "nogil": True, "fastmath": False}


class ChannelTests(NamedTuple):
    """The constants of :func:`segment_tests` for one channel, one argument of the kernel
    (numba takes a namedtuple): the baseline's blocks, the variance test's rows, the
    shortest run, the level limit, the first differences' σ and centre, the MAD-to-σ
    factor, the variance and clipping limits, the channel's maximum (``high``) and
    minimum (``low``) over the whole recording, the samples a clip needs, whether the
    channel's σ is positive, and ``held`` (see :func:`segment_tests`)."""

    baseline_blocks: int
    var_rows: int
    min_run: int
    level_limit: float
    diff_sigma: float
    diff_centre: float
    mad_to_sigma: float
    variance_limit: float
    clip_limit: float
    high: float
    low: float
    clip_samples: int
    sigma_positive: bool
    held: bool

#: The differences ``d = x[i + 1] - x[i]`` that :func:`bracket` and :func:`gather` select.
FORWARD = 0  # d where d > 0
INSIDE = 1  # d where breaks[i] is False
DEVIATION = 2  # |d - centre| where breaks[i] is False
INSIDE_FORWARD = 3  # d where breaks[i] is False and d > 0


@njit(inline="always", **_JIT)
def _valid(x: np.ndarray, breaks: np.ndarray, i: int, mode: int) -> bool:
    # branch-free (a select, not a jump): the loops that call it stay vectorisable
    inside = (mode == FORWARD) | (not breaks[i])
    forward = ((mode != FORWARD) & (mode != INSIDE_FORWARD)) | (x[i + 1] - x[i] > 0)
    return inside & forward


@njit(inline="always", **_JIT)
def _value(x: np.ndarray, i: int, mode: int, centre: float) -> float:
    d = x[i + 1] - x[i]
    return abs(d - centre) if mode == DEVIATION else d


@njit(**_JIT)
def _gather(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float,
            count: int) -> np.ndarray:
    out = np.empty(count)
    k = 0
    for i in range(x.size - 1):
        if _valid(x, breaks, i, mode):
            out[k] = _value(x, i, mode, centre)
            k += 1
    return out


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


@njit(**_JIT)
def difference_sample(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float,
                      size: int) -> tuple:
    """``(count, sample)``: how many differences ``mode`` selects, and about ``size`` of
    them at a regular stride of the indices."""
    n = x.size - 1
    count = 0
    for i in range(n):
        count += _valid(x, breaks, i, mode)
    stride = max(n // size, 1)
    sample = np.empty(n // stride + 1)
    s = 0
    for i in range(0, n, stride):
        if _valid(x, breaks, i, mode):
            sample[s] = _value(x, i, mode, centre)
            s += 1
    return count, sample[:s]


@njit(**_JIT)
def bracket(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float, lo: float,
            hi: float) -> tuple:
    """``(below, equal_lo, between, equal_hi)`` of the differences ``mode`` selects:
    how many lie below ``lo``, equal ``lo``, strictly between (their values), equal ``hi``
    (with ``lo == hi``, all equal ones are counted once, as ``equal_lo``)."""
    n = x.size - 1
    inside = np.empty(n)  # pages are touched only as far as the values kept
    below = equal_lo = equal_hi = kept = 0
    for i in range(n):
        valid = _valid(x, breaks, i, mode)
        v = _value(x, i, mode, centre)
        below += valid & (v < lo)
        equal_lo += valid & (v == lo)
        equal_hi += valid & (v == hi) & (hi != lo)
        inside[kept] = v
        kept += valid & (lo < v) & (v < hi)
    return below, equal_lo, inside[:kept], equal_hi


@njit(**_JIT)
def gather(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float,
           count: int) -> np.ndarray:
    """The ``count`` differences ``mode`` selects."""
    return _gather(x, breaks, mode, centre, count)


@njit(**_JIT)
def first_not_finite(values: np.ndarray) -> int:
    """Index of the first value that is not finite (-1: none)."""
    for i in range(values.size):
        if not np.isfinite(values[i]):
            return i
    return -1


@njit(**_JIT)
def find_breaks(time_s: np.ndarray, gap_s: float) -> np.ndarray:
    """``breaks[i]``: the step from sample i to i + 1 is longer than ``gap_s`` or does not
    go forward."""
    out = np.empty(max(time_s.size - 1, 0), dtype=np.bool_)
    for i in range(out.size):
        step = time_s[i + 1] - time_s[i]
        out[i] = (step > gap_s) | (step <= 0)
    return out


@njit(**_JIT)
def steps_over(time_s: np.ndarray, limit: float) -> np.ndarray:
    """``np.flatnonzero(np.diff(time_s) > limit)`` without the differences' array."""
    out = np.empty(max(time_s.size - 1, 0), dtype=np.int64)  # touched only as far as kept
    kept = 0
    for i in range(out.size):
        out[kept] = i
        kept += (time_s[i + 1] - time_s[i]) > limit
    return out[:kept].copy()


@njit(**_JIT)
def segment_index(breaks: np.ndarray) -> np.ndarray:
    """Segment of each sample (``breaks[i]``: a new segment at sample i + 1)."""
    out = np.empty(breaks.size + 1, dtype=np.int64)
    if out.size == 0:
        return out
    k = 0
    out[0] = 0
    for i in range(breaks.size):
        if breaks[i]:
            k += 1
        out[i + 1] = k
    return out


@njit(**_JIT)
def _small_median(values: np.ndarray) -> float:
    """Median of at most five values (an odd count: the middle one)."""
    ordered = np.sort(values)
    return ordered[ordered.size // 2]


@njit(**_JIT)
def _anchors(t: np.ndarray, values: np.ndarray, edges: np.ndarray,
             baseline_blocks: int) -> tuple:
    """``(medians, centres, slopes)`` of the baseline of one segment: the running median
    of the block medians at the block centres, and the slopes between them."""
    blocks = edges.size - 1
    medians = np.empty(blocks)
    centres = np.empty(blocks)
    for k in range(blocks):
        a, b = edges[k], edges[k + 1]
        medians[k] = median(values[a:b])
        centres[k] = 0.5 * (t[a] + t[b - 1])
    if blocks >= 3:  # symmetric windows (shrinking at the ends)
        half = baseline_blocks // 2
        running = np.empty(blocks)
        for k in range(blocks):
            r = min(half, k, blocks - 1 - k)
            running[k] = _small_median(medians[k - r:k + r + 1])
        medians = running
    slopes = (medians[1:] - medians[:-1]) / (centres[1:] - centres[:-1])
    return medians, centres, slopes


@njit(inline="always", **_JIT)
def _level_at(x: float, j: int, medians: np.ndarray, centres: np.ndarray,
              slopes: np.ndarray) -> tuple:
    """``(level, j)``: the baseline at time ``x`` (np.interp's arithmetic, the end slopes
    continued beyond the outer centres); ``j`` the interval of the last call (the times
    of a segment increase)."""
    last = medians.size - 1
    if last == 0:
        return medians[0], j
    if x < centres[0]:
        return medians[0] + slopes[0] * (x - centres[0]), j
    if x > centres[last]:
        return medians[last] + slopes[last - 1] * (x - centres[last]), j
    if x == centres[last]:
        return medians[last], j
    while centres[j + 1] <= x:
        j += 1
    if centres[j] == x:
        return medians[j], j
    return slopes[j] * (x - centres[j]) + medians[j], j


@njit(inline="always", **_JIT)
def _held(x: float, j: int, medians: np.ndarray, centres: np.ndarray) -> tuple:
    """``(left, right)``: the baseline anchors on either side of time ``x`` (the outer one
    twice beyond the outer centres); ``j`` the interval :func:`_level_at` found."""
    last = medians.size - 1
    if last == 0 or x <= centres[0]:
        return medians[0], medians[0]
    if x >= centres[last]:
        return medians[last], medians[last]
    return medians[j], medians[j + 1]


@njit(inline="always", **_JIT)
def _run_step(on: bool, i: int, start: int, minimum: int, out: np.ndarray) -> int:
    """One sample of a streamed run finder: the start of the current run of True (-1:
    none); a run of at least ``minimum`` is OR-ed into ``out`` when it ends."""
    if on:
        return i if start < 0 else start
    if start >= 0 and i - start >= minimum:
        for k in range(start, i):
            out[k] = True
    return -1


@njit(**_JIT)
def _variance_test(values: np.ndarray, var_rows: int, centre: float, mad_to_sigma: float,
                   limit: float, variance: np.ndarray) -> None:
    """The variance test of one segment: a block of ``var_rows`` first differences (the
    last takes the remainder) is loud when ``mad_to_sigma * MAD > limit``.

    The MAD of a block is computed only where counting cannot decide: with ``centre``
    (the channel's median difference) and ``delta`` a quarter of the limit on the MAD,
    a block whose median lies within ``delta`` of ``centre`` has its MAD within
    ``delta`` of the median of ``|d - centre|``; so if that median is below
    ``0.75`` of the limit (or above ``1.25``; a relative margin of 1e-6 covers the
    rounding), the verdict is known from four counts.
    """
    m = values.size
    blocks = m // var_rows
    threshold = limit / mad_to_sigma
    delta = 0.25 * threshold
    quiet = threshold * (1.0 - 1e-6) - delta
    loud = threshold * (1.0 + 1e-6) + delta
    low, high = centre - delta, centre + delta
    scratch = np.empty(2 * var_rows)
    for k in range(blocks):
        a = k * var_rows
        b = (k + 1) * var_rows if k < blocks - 1 else m - 1
        count = b - a
        k_lo, k_hi = (count - 1) // 2, count // 2
        below = upto = near = far = 0
        for i in range(a, b):
            d = values[i + 1] - values[i]
            below += d < low
            upto += d <= high
            deviation = abs(d - centre)
            near += deviation <= quiet
            far += deviation <= loud
        if below <= k_lo and upto >= k_hi + 1 and near >= k_hi + 1:
            continue  # the MAD is below the limit
        if not (below <= k_lo and upto >= k_hi + 1 and far <= k_lo):
            for i in range(a, b):
                scratch[i - a] = values[i + 1] - values[i]
            block = scratch[:count]
            middle = np.median(block)
            spread = np.median(np.abs(block - middle))
            if not mad_to_sigma * spread > limit:
                continue
        stop = m if k == blocks - 1 else (k + 1) * var_rows
        for i in range(a, stop):
            variance[i] = True


@njit(**_JIT)
def segment_tests(t: np.ndarray, values: np.ndarray, edges: np.ndarray, tests: ChannelTests,
                  out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Level, variance and clipping tests of one channel over one segment, OR-ed into
    ``level``, ``variance`` and ``clipped`` (views of the segment; ``out`` is
    ``(level, variance, clipped, stepped)``), with the constants ``tests``. ``stepped``:
    the runs off the interpolated baseline alone (a step of the still level bends it; see
    :func:`isolated_runs`). ``held``: a channel whose still level never drifts between two
    anchors (an accelerometer: gravity), so anchors that disagree are a step and a sample
    between them is at rest only near one of them (a tilt along the interpolation is not)."""
    level, variance, clipped, stepped = out
    baseline_blocks, var_rows, min_run = tests.baseline_blocks, tests.var_rows, tests.min_run
    level_limit, diff_sigma, diff_centre = tests.level_limit, tests.diff_sigma, tests.diff_centre
    mad_to_sigma, variance_limit = tests.mad_to_sigma, tests.variance_limit
    clip_limit, high, low, clip_samples = tests.clip_limit, tests.high, tests.low, \
        tests.clip_samples
    sigma_positive, held = tests.sigma_positive, tests.held
    m = values.size
    medians, centres, slopes = _anchors(t, values, edges, baseline_blocks)
    j = 0
    run_level = run_high = run_low = run_step = -1
    for i in range(m + 1):
        on_level = on_high = on_low = on_step = False
        if i < m:
            base, j = _level_at(t[i], j, medians, centres, slopes)
            v = values[i]
            # off the interpolated baseline and off both anchors around it: a step of the
            # still level between two anchors (a new orientation) is not motion
            left, right = _held(t[i], j, medians, centres)
            on_step = sigma_positive and abs(v - base) > level_limit
            on_level = ((on_step or (sigma_positive and held
                                     and abs(right - left) > level_limit))
                        and abs(v - left) > level_limit and abs(v - right) > level_limit)
            on_high = v == high and abs(high - base) > clip_limit
            on_low = v == low and abs(low - base) > clip_limit
        run_level = _run_step(on_level, i, run_level, min_run, level)
        run_step = _run_step(on_step, i, run_step, min_run, stepped)
        run_high = _run_step(on_high, i, run_high, clip_samples, clipped)
        run_low = _run_step(on_low, i, run_low, clip_samples, clipped)
    if diff_sigma > 0 and m >= var_rows:
        _variance_test(values, var_rows, diff_centre, mad_to_sigma, variance_limit, variance)


@njit(**_JIT)
def guard(found: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], starts: np.ndarray,
          stops: np.ndarray, after: int, before: int, moving: np.ndarray,
          guarded: np.ndarray) -> None:
    """``moving``: the samples found by any test (``found``: the level, variance, clipping
    and accelerometer masks), each run extended by the guard inside its segment
    (``starts``, ``stops``); ``guarded``: those marked by the guard alone."""
    level, variance, clipped, accel = found
    for k in range(starts.size):
        a, b = starts[k], stops[k]
        start = -1
        for i in range(a, b + 1):
            on = i < b and (level[i] | variance[i] | clipped[i] | accel[i])
            if on and start < 0:
                start = i
            elif not on and start >= 0:
                for j in range(max(start - before, a), min(i + after, b)):
                    moving[j] = True
                start = -1
    for i in range(moving.size):
        guarded[i] = moving[i] & ~(level[i] | variance[i] | clipped[i] | accel[i])



@njit(**_JIT)
def isolated_runs(stepped: np.ndarray, near: np.ndarray, out: np.ndarray) -> None:
    """OR into ``out`` each run of ``stepped`` none of whose samples is ``near``."""
    n = stepped.size
    start = -1
    touched = False
    for i in range(n + 1):
        on = i < n and stepped[i]
        if on:
            if start < 0:
                start, touched = i, False
            touched |= near[i]
        elif start >= 0:
            if not touched:
                for k in range(start, i):
                    out[k] = True
            start = -1
