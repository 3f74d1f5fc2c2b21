"""The at-rest detector's loops (:mod:`hrgtc.recording.motion`), in C.

Each function computes, bit for bit, what the detector's numpy definition computes
(kept in ``tests/motion_reference.py`` and compared on the fixtures), in one
or two passes over the samples instead of a numpy temporary per step:

- :func:`difference_sample`, :func:`bracket`, :func:`gather`: the pieces of
  ``motion._difference_median``, the median of the first differences of an array
  (all forward steps, those inside segments, or their absolute deviations from a
  centre) without building them;
- :func:`median`: ``np.median`` of one block, by the same bracketing;
- :func:`segment_tests`: the level, variance and clipping tests of one channel over
  one segment (block medians, their running median, the interpolated baseline, the
  runs of at least ``min_run`` samples), OR-ed into the reason masks;
- :func:`guard`: the guard around each run, inside its segment;
- :func:`steps_over`: the time steps longer than a limit (the dropouts).

The loops are the compiled module ``_motion_native`` (``_motion_native.c``, built by
``pip install -e .``); this module allocates their outputs. They were numba kernels,
kept as the reference of ``tests/recording/test_motion_native.py``, which checks that the
two agree bit for bit (numba's own selection and sort algorithms are in the C, so even a
zero median's sign is numba's). numba is not imported: loading its eight cached kernels
cost a command as much as the loops (docs/architecture.md, "The native at-rest
detector"). When the module is missing this raises ``ImportError`` saying how to build
it, rather than falling back unnoticed. The loops release the GIL.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hrgtc.core.native import native_module

_native = native_module("hrgtc.recording._motion_native", "at-rest detector")


class ChannelTests(NamedTuple):
    """The constants of :func:`segment_tests` for one channel: the baseline's blocks, the
    variance test's rows, the shortest run, the level limit, the first differences' σ and
    centre, the MAD-to-σ factor, the variance and clipping limits, the channel's maximum
    (``high``) and minimum (``low``) over the whole recording, the samples a clip needs,
    whether the channel's σ is positive, and ``held`` (see :func:`segment_tests`)."""

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


def median(values: np.ndarray) -> float:
    """``np.median(values)`` of finite values: a sorted sample of 512 brackets the middle
    ranks, one branch-free pass counts what lies below and keeps what lies between, and
    the middle values are selected among those (all of them if the bracket missed)."""
    return _native.median(values)


def difference_sample(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float,
                      size: int) -> tuple:
    """``(count, sample)``: how many differences ``mode`` selects, and about ``size`` of
    them at a regular stride of the indices."""
    n = x.size - 1
    if size < 1:
        raise ValueError(f"difference_sample needs a sample size of at least 1, got {size}")
    stride = max(n // size, 1)
    sample = np.empty(max(n, 0) // stride + 1)
    count, written = _native.difference_sample(x, breaks, mode, centre, stride, sample)
    return count, sample[:written]


def bracket(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float, lo: float,
            hi: float) -> tuple:
    """``(below, equal_lo, between, equal_hi)`` of the differences ``mode`` selects:
    how many lie below ``lo``, equal ``lo``, strictly between (their values), equal ``hi``
    (with ``lo == hi``, all equal ones are counted once, as ``equal_lo``)."""
    inside = np.empty(max(x.size - 1, 0))  # pages are touched only as far as the values kept
    below, equal_lo, kept, equal_hi = _native.bracket(x, breaks, mode, centre, lo, hi, inside)
    return below, equal_lo, inside[:kept], equal_hi


def gather(x: np.ndarray, breaks: np.ndarray, mode: int, centre: float,
           count: int) -> np.ndarray:
    """The ``count`` differences ``mode`` selects (ValueError if that is not their count)."""
    out = np.empty(count)
    _native.gather(x, breaks, mode, centre, out)
    return out


def first_not_finite(values: np.ndarray) -> int:
    """Index of the first value that is not finite (-1: none)."""
    return _native.first_not_finite(values)


def find_breaks(time_s: np.ndarray, gap_s: float) -> np.ndarray:
    """``breaks[i]``: the step from sample i to i + 1 is longer than ``gap_s`` or does not
    go forward."""
    out = np.empty(max(time_s.size - 1, 0), dtype=np.bool_)
    _native.find_breaks(time_s, gap_s, out)
    return out


def steps_over(time_s: np.ndarray, limit: float) -> np.ndarray:
    """``np.flatnonzero(np.diff(time_s) > limit)`` without the differences' array."""
    out = np.empty(max(time_s.size - 1, 0), dtype=np.int64)  # touched only as far as kept
    return out[:_native.steps_over(time_s, limit, out)].copy()


def segment_index(breaks: np.ndarray) -> np.ndarray:
    """Segment of each sample (``breaks[i]``: a new segment at sample i + 1)."""
    out = np.empty(breaks.size + 1, dtype=np.int64)
    _native.segment_index(breaks, out)
    return out


def segment_tests(t: np.ndarray, values: np.ndarray, edges: np.ndarray, tests: ChannelTests,
                  out: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Level, variance and clipping tests of one channel over one segment, OR-ed into
    ``level``, ``variance`` and ``clipped`` (views of the segment; ``out`` is
    ``(level, variance, clipped, stepped)``), with the constants ``tests``. ``stepped``:
    the runs off the interpolated baseline alone (a step of the still level bends it; see
    :func:`isolated_runs`). ``held``: a channel whose still level never drifts between two
    anchors (an accelerometer: gravity), so anchors that disagree are a step and a sample
    between them is at rest only near one of them (a tilt along the interpolation is not)."""
    _native.segment_tests(t, values, edges, tests, *out)


def guard(found: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray], starts: np.ndarray,
          stops: np.ndarray, after: int, before: int, moving: np.ndarray,
          guarded: np.ndarray) -> None:
    """``moving``: the samples found by any test (``found``: the level, variance, clipping
    and accelerometer masks), each run extended by the guard inside its segment
    (``starts``, ``stops``); ``guarded``: those marked by the guard alone."""
    _native.guard(*found, starts, stops, after, before, moving, guarded)


def isolated_runs(stepped: np.ndarray, near: np.ndarray, out: np.ndarray) -> None:
    """OR into ``out`` each run of ``stepped`` none of whose samples is ``near``."""
    _native.isolated_runs(stepped, near, out)


#: xxHash64's first two primes: the lanes' starting values (:func:`digest_start`).
_P1, _P2 = 11400714785074694791, 14029467366897019727


def digest_start() -> np.ndarray:
    """A fresh digest state (four lanes and a count of words, as int64)."""
    lanes = [(_P1 + _P2) % 2**64, _P2, 0, 2**64 - _P1, 0]
    return np.array(lanes, dtype=np.uint64).view(np.int64)


def digest_update(state: np.ndarray, values: np.ndarray) -> None:
    """Feed the bits of ``values`` (float64, contiguous) into ``state``; feeding an array in
    pieces gives the digest of the whole."""
    _native.digest_update(state, values)


def digest(state: np.ndarray) -> int:
    """The 64-bit digest of the values fed so far: a change of one value always changes
    it, more changes with a chance of about 2^-64 (``_motion_native.c``)."""
    return _native.digest(state)
