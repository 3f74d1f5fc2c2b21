"""The robust spike filter's numpy definition, as it was before its loops were compiled.

:func:`find_spikes_reference` and :func:`moving_across_reference` are the plain numpy
text of :func:`hrgtc.recording.spikes.find_spikes` and
:func:`hrgtc.recording.spikes.moving_across` (a numpy temporary per step, a 2-D median per
window length); ``tests/recording/test_spike_kernel.py`` checks that the compiled filter
(``hrgtc.recording._spike_kernel``) gives the same masks, bit for bit.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterator

import numpy as np

from hrgtc.recording.gaps import GAP_PERIODS, GAP_TOLERANCE
from hrgtc.recording.resolution import resolution
from hrgtc.recording.spikes import (
    _MAD_TO_SIGMA,
    _SECOND_DIFF,
    MIN_WINDOW_SAMPLES,
    RESOLUTION_ROWS,
    SPIKE_K,
    SPIKE_LSB,
    SPIKE_WINDOW_S,
)


def _segments(time_s: np.ndarray) -> list[tuple[int, int]]:
    """``[start, stop)`` of the contiguous segments: split where a step > 2 median periods."""
    n = len(time_s)
    if n < 2:
        return [(0, n)] if n else []
    steps = np.diff(time_s)
    positive = steps[np.isfinite(steps) & (steps > 0)]
    if not positive.size:
        return [(0, n)]
    limit = GAP_PERIODS * float(np.median(positive)) * (1.0 + GAP_TOLERANCE)
    cuts = np.flatnonzero(~(steps <= limit)) + 1
    bounds = [0, *cuts.tolist(), n]
    return [(a, b) for a, b in itertools.pairwise(bounds) if b > a]


def _sigma(second: np.ndarray) -> float:
    """σ of the samples from the MAD of their second differences (0 for a constant).

    The MAD about 0: second differences carry no level and no linear trend.
    """
    return _MAD_TO_SIGMA * float(np.median(np.abs(second))) / _SECOND_DIFF


def _window_sigmas(second: np.ndarray, bounds: np.ndarray) -> np.ndarray:
    """σ_MAD of each window ``bounds[i]:bounds[i+1]`` of the second differences.

    Windows of equal length are done together (one median per row of a 2-D view);
    a window with fewer than :data:`MIN_WINDOW_SAMPLES` finite values takes its
    segment's σ.
    """
    sizes = np.diff(bounds)
    sigmas = np.full(sizes.size, np.nan)
    finite = np.isfinite(second)
    if finite.all():
        for size in np.unique(sizes):
            which = np.flatnonzero(sizes == size)
            if size < MIN_WINDOW_SAMPLES:
                continue
            rows = np.abs(second[bounds[which][:, None] + np.arange(size)])
            sigmas[which] = _MAD_TO_SIGMA * np.median(rows, axis=1) / _SECOND_DIFF
    else:
        for i, (a, b) in enumerate(itertools.pairwise(bounds.tolist())):
            part = second[a:b][finite[a:b]]
            if part.size >= MIN_WINDOW_SAMPLES:
                sigmas[i] = _sigma(part)
    short = np.isnan(sigmas)
    if short.any():
        whole = second[finite]
        sigmas[short] = _sigma(whole) if whole.size else 0.0
    return sigmas


def _segment_limits(t: np.ndarray, x: np.ndarray, k: float, lsb_multiple: float,
                    window_s: float, lsb: float | None) -> Iterator[tuple[int, int, np.ndarray,
                                                                           np.ndarray, np.ndarray]]:
    """Per contiguous segment of at least 3 samples: ``(start, stop, values, second
    differences, threshold max(k·σ_MAD, m·LSB) of each sample)`` (see :func:`find_spikes`)."""
    if lsb is None:
        lsb = resolution(x[:RESOLUTION_ROWS])
    floor = lsb_multiple * float(lsb or 0.0)
    for start, stop in _segments(t):
        if stop - start < 3:
            continue
        xs = x[start:stop]
        second = np.empty_like(xs)
        second[1:-1] = xs[1:-1] - 0.5 * (xs[:-2] + xs[2:])
        second[0], second[-1] = second[1], second[-2]
        ts = t[start:stop]
        with np.errstate(invalid="ignore"):
            origin = float(np.nanmin(ts)) if np.isfinite(ts).any() else 0.0
            block = np.floor((ts - origin) / window_s)
        edges = np.flatnonzero(np.diff(block)) + 1
        bounds = np.array([0, *edges.tolist(), len(xs)])
        sigmas = _window_sigmas(second, bounds)
        yield start, stop, xs, second, np.repeat(np.maximum(k * sigmas, floor), np.diff(bounds))


def moving_across_reference(time_s: np.ndarray, values: np.ndarray, *, k: float = SPIKE_K,
                  lsb_multiple: float = SPIKE_LSB, window_s: float = SPIKE_WINDOW_S,
                  lsb: float | None = None) -> np.ndarray:
    """Samples across which a channel moves: a boolean mask, True where the samples on
    either side of it disagree, ``|x[i+1] − x[i−1]|`` or ``|x[i+2] − x[i−2]|`` beyond the
    threshold of :func:`find_spikes` (never across a gap; the sample itself is not used).

    An accelerometer that moves across a sample says the unit was being turned there: a
    single-sample rate excursion at that sample is a fast rotation caught by one sample
    (a handling pulse shorter than the sample period), not a spike. A glitch that hits
    every column of one row leaves the accelerometer's neighbours in agreement.
    """
    x = np.asarray(values, dtype=np.float64)
    t = np.asarray(time_s, dtype=np.float64)
    moving = np.zeros(x.size, dtype=bool)
    for start, stop, xs, _, limit in _segment_limits(t, x, k, lsb_multiple, window_s, lsb):
        across = np.zeros(xs.size)
        with np.errstate(invalid="ignore"):
            across[1:-1] = np.abs(xs[2:] - xs[:-2])
            if xs.size >= 5:
                across[2:-2] = np.maximum(across[2:-2], np.abs(xs[4:] - xs[:-4]))
            moving[start:stop] = across > limit
    return moving


def find_spikes_reference(time_s: np.ndarray, values: np.ndarray, *, k: float = SPIKE_K,
                lsb_multiple: float = SPIKE_LSB, window_s: float = SPIKE_WINDOW_S,
                lsb: float | None = None) -> np.ndarray:
    """Single-sample spikes of a channel: a boolean mask, True at each spike.

    Parameters
    ----------
    time_s
        Time of each sample. [s]
    values
        The channel (any unit; NaN never a spike here: the validation names those).
    k
        Threshold in robust standard deviations σ_MAD of the window.
    lsb_multiple
        Threshold floor in steps of the channel's resolution (``m``).
    window_s
        Length of the windows σ_MAD is estimated on (cut at gaps). [s]
    lsb
        The channel's resolution; None: :func:`hrgtc.recording.resolution.resolution`
        of its first :data:`RESOLUTION_ROWS` values.

    Returns
    -------
    numpy.ndarray
        True where ``|x[i] − x[i±1]|`` and ``|x[i] − (x[i−1] + x[i+1]) / 2|`` all exceed
        ``max(k·σ_MAD, m·LSB)`` while ``|x[i+1] − x[i−1]|`` does not (the neighbours agree:
        one sample off a steady stream, not a stream in motion); at a segment's edge,
        against the next two samples.
    """
    x = np.asarray(values, dtype=np.float64)
    t = np.asarray(time_s, dtype=np.float64)
    spikes = np.zeros(x.size, dtype=bool)
    for start, stop, xs, second, limit in _segment_limits(t, x, k, lsb_multiple, window_s, lsb):
        with np.errstate(invalid="ignore"):
            left = np.abs(np.diff(xs, prepend=np.nan))
            right = np.abs(np.diff(xs, append=np.nan))
            # ... and its two neighbours agree with each other: a single sample off a
            # steady stream, not a stream that moves (handling, a rotation), whose every
            # sample is far from its neighbours
            across = np.full(xs.size, np.inf)
            across[1:-1] = np.abs(xs[2:] - xs[:-2])
            inner = ((left > limit) & (right > limit) & (np.abs(second) > limit)
                     & (across <= limit))
            # the edges: away from both of the next two samples, which agree
            inner[0] = (right[0] > limit[0]) & (abs(xs[0] - xs[2]) > limit[0]) & (
                right[1] <= limit[0])
            inner[-1] = (left[-1] > limit[-1]) & (abs(xs[-1] - xs[-3]) > limit[-1]) & (
                left[-2] <= limit[-1])
        spikes[start:stop] = inner
    return spikes
