"""The at-rest detector's numpy definition, as it was before its loops were compiled.

:func:`detect_motion_reference` is the plain numpy text of
:func:`hrgtc.recording.motion.detect_motion` (one numpy step per line, a Python loop per
run); ``tests/recording/test_motion_kernel.py`` checks that the compiled detector gives
the same masks, bit for bit, on every fixture.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.recording.motion import (
    BASELINE_BLOCKS,
    GAP_FACTOR,
    HANDLING_S,
    MAD_TO_SIGMA,
    REASONS,
    VARIANCE_MIN_SAMPLES,
    MotionMask,
    MotionSettings,
)
from hrgtc.settings.reading import DROPOUT_S


# --------------------------------------------------------------------------- helpers
def segments_of(time_s: np.ndarray, gap_factor: float = GAP_FACTOR) -> np.ndarray:
    """Segment index of each sample: a new segment after each gap or backward step.

    """
    time_s = np.asarray(time_s, dtype=np.float64)
    if time_s.size < 2:
        return np.zeros(time_s.size, dtype=np.int64)
    step = np.diff(time_s)
    forward = step[step > 0]
    period = float(np.median(forward)) if forward.size else 1.0
    breaks = (step > gap_factor * period) | (step <= 0)
    return np.concatenate([[0], np.cumsum(breaks)]).astype(np.int64)


def _bounds(segment: np.ndarray) -> list[tuple[int, int]]:
    edges = np.flatnonzero(np.diff(segment) != 0) + 1
    starts = np.concatenate([[0], edges])
    stops = np.concatenate([edges, [segment.size]])
    return [(int(a), int(b)) for a, b in zip(starts, stops, strict=True)]


def _period(time_s: np.ndarray, segment: np.ndarray) -> float:
    step = np.diff(time_s)[np.diff(segment) == 0]
    step = step[step > 0]
    return float(np.median(step)) if step.size else 1.0


def _rows(seconds: float, period: float, minimum: int = 1) -> int:
    return max(round(seconds / period), minimum)


def _mad(rows: np.ndarray) -> np.ndarray:
    """Median absolute deviation of each row (no consistency factor)."""
    centre = np.median(rows, axis=1, keepdims=True)
    return np.median(np.abs(rows - centre), axis=1)


def _resolution(values: np.ndarray) -> float:
    """Smallest step between distinct values (the quantum of a quantised stream; from the
    first 200,000 values, which show it as well as all of them)."""
    distinct = np.unique(values[:200_000][np.isfinite(values[:200_000])])
    if distinct.size < 2:
        return 0.0
    return float(np.min(np.diff(distinct)))


def _baseline(time_s: np.ndarray, values: np.ndarray, rows: int, held: bool = False
              ) -> np.ndarray | tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Robust running level of one segment: block medians, their running median, interpolated.
    ``held``: also the anchors on either side of each sample (the outer one beyond the ends)."""
    n = values.size
    blocks = max(n // rows, 1)
    edges = np.linspace(0, n, blocks + 1).astype(np.int64)
    medians = np.array([np.median(values[a:b]) for a, b in itertools.pairwise(edges)]) \
        if blocks < 64 or n % blocks else np.median(values.reshape(blocks, -1), axis=1)
    centres = np.array([0.5 * (time_s[a] + time_s[b - 1]) for a, b in
                        itertools.pairwise(edges)])
    if blocks >= 3:  # symmetric windows (shrinking at the ends): a linear drift is kept
        half = BASELINE_BLOCKS // 2
        reach = [min(half, k, blocks - 1 - k) for k in range(blocks)]
        medians = np.array([np.median(medians[k - r:k + r + 1]) for k, r in enumerate(reach)])
    level = np.interp(time_s, centres, medians)
    if blocks >= 2:  # beyond the outer block centres: continue the end slopes
        head = time_s < centres[0]
        tail = time_s > centres[-1]
        slope0 = (medians[1] - medians[0]) / (centres[1] - centres[0])
        slope1 = (medians[-1] - medians[-2]) / (centres[-1] - centres[-2])
        level[head] = medians[0] + slope0 * (time_s[head] - centres[0])
        level[tail] = medians[-1] + slope1 * (time_s[tail] - centres[-1])
    if not held:
        return level
    j = np.clip(np.searchsorted(centres, time_s, side="right") - 1, 0, medians.size - 1)
    left, right = medians[j], medians[np.minimum(j + 1, medians.size - 1)]
    outside = (time_s <= centres[0]) | (time_s >= centres[-1])
    left = np.where(time_s <= centres[0], medians[0], left)
    right = np.where(outside, left, right)
    return level, left, right


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)


def _long_runs(mask: np.ndarray, minimum: int) -> np.ndarray:
    """``mask`` keeping only runs of at least ``minimum`` consecutive True."""
    out = np.zeros_like(mask)
    for a, b in zip(*_runs(mask), strict=True):
        if b - a >= minimum:
            out[a:b] = True
    return out


def _dilate(mask: np.ndarray, after: int, before: int) -> np.ndarray:
    """Extend each True run by ``after`` samples after it and ``before`` before it."""
    out = mask.copy()
    n = mask.size
    for a, b in zip(*_runs(mask), strict=True):
        out[max(a - before, 0):min(b + after, n)] = True
    return out


@dataclass
class _Channel:
    name: str
    values: np.ndarray
    sigma: float = 0.0
    diff_sigma: float = 0.0
    lsb: float = 0.0


def _prepare(name: str, values: np.ndarray, segment: np.ndarray) -> _Channel:
    """A channel's at-rest noise: robust σ of its first differences inside segments."""
    same = np.diff(segment) == 0
    diffs = np.diff(values)[same]
    lsb = _resolution(values)
    diff_sigma = MAD_TO_SIGMA * float(np.median(np.abs(diffs - np.median(diffs)))) \
        if diffs.size else 0.0
    # white noise: a difference has twice the variance of a sample; the quantum floors it
    sigma = max(diff_sigma / math.sqrt(2.0), lsb)
    return _Channel(name, values, sigma, max(diff_sigma, lsb), lsb)


# --------------------------------------------------------------------------- detection
def detect_motion_reference(
    time_s: Any,
    rates: Mapping[str, Any] | Any,
    *,
    accel: Mapping[str, Any] | None = None,
    input_rate: Any = None,
    settings: MotionSettings | None = None,
) -> MotionMask:
    """Mark the samples of a recording that are not at rest.

    Parameters
    ----------
    time_s
        Sample times (gaps allowed: each contiguous segment is treated alone). [s]
    rates
        The gyro rate, one array, or several axes as name -> array (motion on any
        axis marks the sample). [any rate unit, e.g. °/h]
    accel
        Accelerometer axes, name -> array (optional). [any unit]
    input_rate
        The known input rate (a number or one per sample), subtracted from every rate
        before the level test: a rate table's steps are not motion. [unit of ``rates``]
    settings
        Thresholds and windows (:class:`MotionSettings`).

    Returns
    -------
    MotionMask

    """
    s = settings or MotionSettings()
    time_s = np.asarray(time_s, dtype=np.float64)
    if time_s.ndim != 1:
        raise InputError("time_s must be one-dimensional")
    n = time_s.size
    channels = dict(rates) if isinstance(rates, Mapping) else {"rate": rates}
    arrays: dict[str, np.ndarray] = {}
    for name, values in channels.items():
        arrays[name] = np.asarray(values, dtype=np.float64)
        if input_rate is not None:
            arrays[name] = arrays[name] - np.asarray(input_rate, dtype=np.float64)
    accel_names = []
    for name, values in dict(accel or {}).items():
        arrays[name] = np.asarray(values, dtype=np.float64)
        accel_names.append(name)
    for name, values in arrays.items():
        if values.shape != (n,):
            raise InputError(f"motion channel {name!r} has {values.size} samples, time_s has "
                             f"{n}; give one value per sample")
        if not np.all(np.isfinite(values)):
            row = int(np.flatnonzero(~np.isfinite(values))[0])
            raise InputError(f"motion channel {name!r} is not finite at row {row}; drop or "
                             "repair non-finite samples first (--spikes drop)")
    reasons = {r: np.zeros(n, dtype=bool) for r in REASONS}
    segment = segments_of(time_s)
    if n == 0:
        return MotionMask(np.zeros(0, dtype=bool), reasons, np.zeros(0, dtype=bool), {}, s)
    period = _period(time_s, segment)
    prepared = [_prepare(name, values, segment) for name, values in arrays.items()]
    base_rows = _rows(s.baseline_s, period, 8)
    var_rows = _rows(s.window_s, period, VARIANCE_MIN_SAMPLES)
    min_run = max(_rows(s.min_motion_s, period), 2)
    for a, b in _bounds(segment):
        t = time_s[a:b]
        stepped = {"level": np.zeros(b - a, dtype=bool),
                   "accelerometer": np.zeros(b - a, dtype=bool)}
        for channel in prepared:
            level_mask, var_mask, clip_mask, step_mask = _channel_tests(
                channel, t, channel.values[a:b], base_rows, var_rows, min_run, s,
                channel.name in accel_names)
            if channel.name in accel_names:
                reasons["accelerometer"][a:b] |= level_mask | var_mask | clip_mask
                stepped["accelerometer"] |= step_mask
            else:
                reasons["level"][a:b] |= level_mask
                reasons["variance"][a:b] |= var_mask
                reasons["clipped"][a:b] |= clip_mask
                stepped["level"] |= step_mask
        # a step of the still level: motion only when no motion was found within a block
        near = _dilate(reasons["level"][a:b] | reasons["variance"][a:b]
                       | reasons["clipped"][a:b] | reasons["accelerometer"][a:b],
                       base_rows, base_rows)
        for kind, runs in stepped.items():
            for start, stop in zip(*_runs(runs), strict=True):
                if not near[start:stop].any():
                    reasons[kind][a + start:a + stop] = True
    found = reasons["level"] | reasons["variance"] | reasons["clipped"] | reasons["accelerometer"]
    after, before = _rows(s.guard_s, period, 0), _rows(s.guard_before_s, period, 0)
    moving = np.zeros(n, dtype=bool)
    for a, b in _bounds(segment):  # a guard never reaches across a gap
        moving[a:b] = _dilate(found[a:b], after, before)
    reasons["guard"] = moving & ~found
    reasons["short_still"] = np.zeros(n, dtype=bool)
    # still runs next to handling (a moving run of guards + HANDLING_S or more), shorter
    # than min_still_s, judged across dropouts
    joined = np.cumsum(np.r_[0, np.diff(time_s) > max(GAP_FACTOR * period, DROPOUT_S)])
    handling_s = s.guard_s + s.guard_before_s + HANDLING_S
    for a, b in _bounds(joined):
        if s.min_still_s <= 0 or not moving[a:b].any():
            continue
        runs = sorted([(lo, hi, False) for lo, hi in zip(*_runs(~moving[a:b]), strict=True)]
                      + [(lo, hi, True) for lo, hi in zip(*_runs(moving[a:b]), strict=True)])
        for k, (lo, hi, is_moving) in enumerate(runs):
            if is_moving or time_s[a + hi - 1] - time_s[a + lo] >= s.min_still_s:
                continue
            near = [runs[j] for j in (k - 1, k + 1) if 0 <= j < len(runs)]
            if any(time_s[a + h - 1] - time_s[a + low] >= handling_s for low, h, _ in near):
                reasons["short_still"][a + lo:a + hi] = True
    moving |= reasons["short_still"]
    noise = {c.name: c.sigma for c in prepared}
    return MotionMask(moving, reasons, np.diff(segment) != 0, noise, s)


def _channel_tests(channel: _Channel, t: np.ndarray, values: np.ndarray, base_rows: int,
                   var_rows: int, min_run: int, s: MotionSettings, held: bool = False
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Level, variance and clipping tests of one channel over one segment, and the runs
    off the interpolated baseline alone (a step of the still level bends it)."""
    m = values.size
    baseline, left, right = _baseline(t, values, base_rows, held=True)
    deviation = values - baseline
    level = np.zeros(m, dtype=bool)
    stepped = np.zeros(m, dtype=bool)
    if channel.sigma > 0:  # off the baseline and off both anchors around it (a step is not)
        limit = s.threshold * channel.sigma
        # an accelerometer's still level never drifts: anchors that disagree are a step,
        # and between them only a sample near one of them is at rest
        off = np.abs(deviation) > limit
        if held:
            off |= np.abs(right - left) > limit
        level = _long_runs(off & (np.abs(values - left) > limit)
                           & (np.abs(values - right) > limit), min_run)
        stepped = _long_runs(np.abs(deviation) > limit, min_run)
    variance = np.zeros(m, dtype=bool)
    if channel.diff_sigma > 0 and m >= var_rows:
        # blocks of var_rows samples (the last takes the remainder); differences inside each
        blocks = m // var_rows
        d = np.diff(values)
        whole = d[: (blocks - 1) * var_rows].reshape(blocks - 1, var_rows) if blocks > 1 \
            else np.empty((0, var_rows))
        spreads = list(_mad(whole)) if whole.size else []
        spreads.append(float(_mad(d[(blocks - 1) * var_rows:][None, :])[0]))
        loud = MAD_TO_SIGMA * np.asarray(spreads) > s.variance_ratio * channel.diff_sigma
        for k in np.flatnonzero(loud):
            variance[k * var_rows: m if k == blocks - 1 else (k + 1) * var_rows] = True
    clipped = np.zeros(m, dtype=bool)
    for extreme in (float(np.max(channel.values)), float(np.min(channel.values))):
        at = values == extreme
        far = np.abs(extreme - baseline) > s.threshold * max(channel.sigma, channel.lsb)
        clipped |= _long_runs(at & far, int(s.clip_samples))
    return level, variance, clipped, stepped
