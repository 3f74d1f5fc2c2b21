"""The robust spike filter's loops (:mod:`hrgtc.recording.spikes`), in C.

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

The loops are the compiled module ``_spike_native`` (``_spike_native.c``, built by
``pip install -e .``); they were numba kernels, kept as the reference of
``tests/recording/test_spike_native.py``, which checks the two agree bit for bit. numba
is not imported: its import and start cost a command more than the filter itself
(docs/architecture.md, "The native kernels"). When the module is missing this raises
``ImportError`` saying how to build it, rather than falling back unnoticed.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hrgtc.core.native import native_module

_native = native_module("hrgtc.recording._spike_native", "spike filter")


class SpikeRule(NamedTuple):
    """The filter's constants, one argument of the kernels: the threshold
    ``max(k·σ_MAD, floor)`` over ``window_s`` windows of at least ``min_window`` (≥ 1)
    finite second differences (σ_MAD = ``mad_to_sigma`` × median / ``second_diff``),
    segments cut at a step beyond ``gap_periods`` median periods (times ``tolerance``)."""

    k: float
    floor: float
    window_s: float
    gap_periods: float
    tolerance: float
    min_window: int
    mad_to_sigma: float
    second_diff: float


#: What the kernel tests: single-sample spikes, or motion across a sample.
SPIKE = 0
ACROSS = 1


def _channel_test(t: np.ndarray, x: np.ndarray, rule: SpikeRule, mode: int) -> np.ndarray:
    """The test ``mode`` of one channel (``t``, ``x``: contiguous float64 of one length)."""
    out = np.zeros(x.size, dtype=np.bool_)
    _native.channel_test(t, x, out, tuple(rule), mode)
    return out


def spike_mask(t: np.ndarray, x: np.ndarray, rule: SpikeRule) -> np.ndarray:
    """:func:`hrgtc.recording.spikes.find_spikes` of one channel, given its LSB floor."""
    return _channel_test(t, x, rule, SPIKE)


def across_mask(t: np.ndarray, x: np.ndarray, rule: SpikeRule) -> np.ndarray:
    """:func:`hrgtc.recording.spikes.moving_across` of one channel, given its LSB floor."""
    return _channel_test(t, x, rule, ACROSS)
