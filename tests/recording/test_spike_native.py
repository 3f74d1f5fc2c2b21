"""The spike filter's C loops (``_spike_native.c``) give the masks of the numba kernels
they replaced (``recording/_spike_numba_reference.py``), bit for bit, and their module
does not import numba.

The records reach every branch: segments of 0 to 7 samples, windows at and beyond the
size where the median is bracketed by a sample (256 values) and where the steps' median
is (2048 steps), NaN and infinite values and times, ties (quantised and constant
streams, zeros of both signs), huge offsets, windows with fewer than ``min_window``
finite second differences, a NaN or zero floor.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from hrgtc.recording import _spike_kernel as native
from hrgtc.recording import spikes
from recording import _spike_numba_reference as reference

# (k, floor, window_s, min_window): the command's settings, short windows, a zero and a
# NaN floor, a minimum window of one difference
RULES = [(5.0, 1e-3, 60.0, spikes.MIN_WINDOW_SAMPLES),
         (3.0, 0.0, 0.2, spikes.MIN_WINDOW_SAMPLES),
         (4.0, np.nan, 30.0, 1), (0.0, 0.5, 7.0, 400)]


def rules(k: float, floor: float, window_s: float, min_window: int):
    values = (k, floor, window_s, float(spikes.GAP_PERIODS), 1.0 + spikes.GAP_TOLERANCE,
              min_window, spikes._MAD_TO_SIGMA, spikes._SECOND_DIFF)
    return native.SpikeRule(*values), reference.SpikeRule(*values)


def same(t: np.ndarray, x: np.ndarray) -> None:
    """Both tests of the C kernel equal the numba kernel's under every rule."""
    t = np.ascontiguousarray(t, dtype=np.float64)
    x = np.ascontiguousarray(x, dtype=np.float64)
    for settings in RULES:
        mine, theirs = rules(*settings)
        for c, numba in ((native.spike_mask, reference.spike_mask),
                         (native.across_mask, reference.across_mask)):
            got, want = c(t, x, mine), numba(t, x, theirs)
            assert got.dtype == want.dtype == np.bool_
            np.testing.assert_array_equal(got.view(np.uint8), want.view(np.uint8))


def noisy(rng: np.random.Generator, n: int, rate_hz: float = 20.0):
    t = np.arange(n) / rate_hz + rng.uniform(0.0, 1e4)
    x = np.cumsum(rng.standard_normal(n)) * 0.01 + rng.standard_normal(n)
    if n > 4:
        at = rng.integers(0, n, n // 40 + 1)
        x[at] += rng.choice([-25.0, 30.0, 6.0], at.size)
    return t, x


@pytest.mark.parametrize("n", [0, 1, 2, 3, 4, 5, 6, 7, 255, 256, 257, 1201, 2049, 9000])
@pytest.mark.parametrize("seed", range(3))
def test_noisy_records_of_every_length(n, seed):
    rng = np.random.default_rng(1000 * n + seed)
    t, x = noisy(rng, n)
    same(t, x)
    same(t, np.round(x * 4.0) / 4.0)  # quantised: ties in every median


@pytest.mark.parametrize("seed", range(8))
def test_defects_gaps_and_steps_back(seed):
    rng = np.random.default_rng(seed)
    n = 6000
    t, x = noisy(rng, n, rate_hz=rng.choice([1.0, 50.0, 200.0]))
    for _ in range(12):
        i = int(rng.integers(1, n))
        kind = int(rng.integers(0, 8))
        if kind == 0:
            x[i] = np.nan
        elif kind == 1:
            x[i] = rng.choice([np.inf, -np.inf])
        elif kind == 2:
            t[i] = np.nan
        elif kind == 3:
            t[i] = rng.choice([np.inf, -np.inf])
        elif kind == 4:
            t[i:] += rng.uniform(0.1, 100.0)  # a gap
        elif kind == 5:
            t[i:] -= rng.uniform(0.0, 2.0)  # a step back
        elif kind == 6:
            t[i] = t[i - 1]  # a repeated time
        else:
            x[i:i + 3] = np.nan  # a short run of NaN: windows under min_window
    same(t, x)


def test_ties_zeros_and_constant_streams():
    n = 5000
    t = np.arange(n) / 10.0
    same(t, np.zeros(n))
    same(t, np.where(np.arange(n) % 2 == 0, -0.0, 0.0))  # zeros of both signs
    same(t, np.where(np.arange(n) % 7 == 0, 1.0, 0.0))
    same(t, np.where(np.arange(n) % 3 == 0, 2.0, -2.0))
    same(np.zeros(n), np.arange(n, dtype=np.float64))  # no positive step: one segment
    same(np.full(n, np.nan), np.arange(n, dtype=np.float64))  # no finite time
    same(np.repeat(np.arange(n // 10, dtype=np.float64), 10), np.sin(np.arange(n)))


def test_huge_offsets_and_values():
    rng = np.random.default_rng(7)
    t, x = noisy(rng, 20_000, rate_hz=100.0)
    same(t + 1.7e9, x + 1e12)  # a Unix clock, a frequency in Hz far from zero
    same(t * 1e-9, x * 1e-300)  # tiny steps, subnormal-near values
    same(t, np.where(rng.random(t.size) < 0.01, 1e308, x))  # differences overflow to inf


def test_long_segments_bracket_the_steps_median():
    """More than 2048 steps with jittered periods: the steps' median taken by the bracket."""
    rng = np.random.default_rng(11)
    n = 50_000
    t = np.cumsum(rng.uniform(0.05, 0.15, n))
    t[rng.integers(1, n, 20)] += 5.0
    same(t, rng.standard_normal(n))


@pytest.mark.parametrize("n", [64 * 300 + 1, 64 * 301 + 1])
def test_steps_that_mislead_the_bracket(n):
    """Every step the bracket's sample looks at is short, most are long: the bracket
    misses the middle ranks and the steps are gathered whole; and a window whose sampled
    second differences are all zero."""
    stride = (n - 1) // 64
    steps = np.full(n - 1, 1.0)
    steps[::stride] = 0.001
    t = np.concatenate([[0.0], np.cumsum(steps)])
    rng = np.random.default_rng(n)
    same(t, rng.standard_normal(n))
    x = np.zeros(n)
    x[1::2] = rng.standard_normal(x[1::2].size)  # ties at zero and noise, interleaved
    same(np.arange(n) / 100.0, x)


def test_the_module_does_not_import_numba():
    code = ("import sys; import hrgtc.recording._spike_kernel; "
            "import hrgtc.recording.spikes; print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_wrong_arrays_are_refused_not_read():
    mine, _ = rules(*RULES[0])
    t = np.arange(10.0)
    with pytest.raises(TypeError, match="values"):
        native.spike_mask(t, np.arange(10, dtype=np.float32), mine)
    with pytest.raises(TypeError, match="time_s"):
        native.spike_mask(np.arange(20.0)[::2], np.arange(10.0), mine)
    with pytest.raises(ValueError, match="one length"):
        native.spike_mask(t, np.arange(9.0), mine)
    with pytest.raises(ValueError, match="min_window"):
        native.spike_mask(t, np.arange(10.0), mine._replace(min_window=0))
