"""The compiled spike filter gives the masks of its numpy definition, bit for bit.

``spikes_reference`` holds :func:`~hrgtc.recording.spikes.find_spikes` and
:func:`~hrgtc.recording.spikes.moving_across` as they were before their loops were
compiled (``hrgtc.recording._spike_kernel``). Both are run on random records built to
reach every branch (gaps, NaN and infinite times and values, time going backwards,
quantised and constant streams, windows shorter than the minimum, segments of 1 to 5
samples) and on the real PAN cold test.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.recording.spikes import find_spikes, moving_across
from recording.test_spike_filter import PAN
from spikes_reference import find_spikes_reference, moving_across_reference


def same(time_s, values, **kwargs) -> None:
    """Both tests agree with their numpy definitions on one record."""
    assert np.array_equal(find_spikes(time_s, values, **kwargs),
                          find_spikes_reference(time_s, values, **kwargs))
    assert np.array_equal(moving_across(time_s, values, **kwargs),
                          moving_across_reference(time_s, values, **kwargs))


def record(seed: int, n: int, rate_hz: float, defects: int) -> tuple[np.ndarray, np.ndarray]:
    """A noisy, drifting stream with spikes, steps, gaps and ``defects`` odd samples."""
    rng = np.random.default_rng(seed)
    time_s = np.arange(n) / rate_hz + 1000.0
    values = 0.001 * time_s + rng.standard_normal(n)
    if n > 10:
        values[rng.integers(0, n, n // 50 + 1)] += rng.choice([-30.0, 25.0, 8.5], n // 50 + 1)
        cut = rng.integers(1, n - 1, 3)
        time_s[cut[0]:] += 7.3 / rate_hz  # a gap
        time_s[cut[1]:] -= 0.5 / rate_hz  # a step back
        values[cut[2]:] += 40.0  # a step of the level
    for _ in range(defects if n else 0):
        i = int(rng.integers(0, n))
        kind = int(rng.integers(0, 6))
        if kind == 0:
            values[i] = np.nan
        elif kind == 1:
            values[i] = np.inf
        elif kind == 2:
            time_s[i] = np.nan
        elif kind == 3:
            time_s[i] = -np.inf
        elif kind == 4:
            time_s[i] = np.inf
        else:
            time_s[i] = time_s[i - 1] if i else time_s[i]  # a repeated time
    return time_s, values


@pytest.mark.parametrize("seed", range(12))
@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 5, 17, 40, 3001, 20_011])
def test_random_records_give_the_reference_masks(seed, n):
    time_s, values = record(seed, n, 50.0, defects=seed % 4)
    same(time_s, values)
    same(time_s, values, window_s=0.2, k=3.0)  # 10-sample windows: the segment's σ
    same(time_s, np.round(values * 2.0) / 2.0, lsb=0.5)  # quantised, a given LSB
    same(time_s, np.round(values * 2.0) / 2.0)  # quantised, the LSB found


def test_constant_and_two_level_streams():
    time_s = np.arange(5000) / 10.0
    same(time_s, np.zeros(5000))
    same(time_s, np.where(np.arange(5000) % 7 == 0, 1.0, 0.0))
    same(time_s, np.where(np.arange(5000) % 2 == 0, -0.0, 0.0))
    same(np.zeros(5000), np.arange(5000.0))  # no positive step: one segment


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=0,
                max_size=80),
       st.lists(st.floats(min_value=-1e3, max_value=1e3) | st.just(np.nan), min_size=0,
                max_size=80),
       st.sampled_from([0.05, 1.0, 30.0]))
def test_any_values_and_times(values, times, window_s):
    n = min(len(values), len(times))
    same(np.array(times[:n]), np.array(values[:n]), window_s=window_s)


def test_the_real_cold_test():
    raw = np.genfromtxt(PAN, delimiter=",", skip_header=1)
    for column in range(1, raw.shape[1]):  # every channel, also the count and the time
        same(raw[:, 0] / 1000.0, raw[:, column])
        same(raw[:, 0] / 1000.0, raw[:, column], window_s=1.0)
