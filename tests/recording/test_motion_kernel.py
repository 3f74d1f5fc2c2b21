"""The compiled at-rest detector gives the masks of its numpy definition, bit for bit.

``motion_reference.detect_motion_reference`` is the detector's numpy text as it was
before its loops were compiled (``hrgtc.recording._motion_kernel``); every fixture the
detector is tested on, the simulated handling and orientation recordings and the real
cold test, is run through both.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hrgtc.recording import _motion_kernel as kernel
from hrgtc.recording.motion import (
    MotionSettings,
    _difference_median,
    detect_motion,
    segments_of,
)
from hrgtc.simulate import constant
from hrgtc.simulate.handling import Handling
from hrgtc.simulate.logger import Logger, log_run
from hrgtc.simulate.mems import G_SENSITIVITY_DPH_PER_G
from motion_reference import detect_motion_reference
from motion_reference import segments_of as reference_segments
from recording.test_motion import PAN, handled


def same_masks(*args, **kwargs) -> None:
    """detect_motion and its numpy definition agree on every mask and figure."""
    new, old = detect_motion(*args, **kwargs), detect_motion_reference(*args, **kwargs)
    assert np.array_equal(new.moving, old.moving)
    for reason in old.reasons:
        assert np.array_equal(new.reasons[reason], old.reasons[reason]), reason
    assert np.array_equal(new.segment, old.segment)
    assert new.noise == old.noise  # the robust σ of each channel, exactly
    return new


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_handling_bursts_with_and_without_accelerometer(seed):
    t, rate, accel, _ = handled(seed)
    assert same_masks(t, {"rate_dph": rate}, accel={"accel_z": accel}).n_moving > 0
    same_masks(t, rate * 3600.0)


def test_the_fixtures_of_each_test():
    t, rate, _, _ = handled(bursts=0, offset_dps=0.0)
    table = np.where(t > 3600.0, 36.0, 0.0)
    same_masks(t, rate + table, input_rate=table)
    same_masks(t, rate + table)
    spiky = rate.copy()
    spiky[[100, 5000, 40000]] -= 5.7
    same_masks(t, spiky)
    shaken = rate.copy()
    shake = (t > 1000.0) & (t < 1030.0)
    shaken[shake] += 0.1 * np.random.default_rng(5).standard_normal(shake.sum())
    same_masks(t, shaken, settings=MotionSettings(threshold=1e3))
    clipped = rate.copy()
    clipped[2000:2003] = 300.0
    assert same_masks(t, clipped, settings=MotionSettings(min_motion_s=10.0)).reasons[
        "clipped"].any()
    t3, rate3, accel3, truth3 = handled(bursts=3)
    same_masks(t3, np.where(truth3, 4.0, rate3), accel={"accel_z": accel3})


def test_gaps_backward_steps_and_bursts():
    t, rate, _, _ = handled(bursts=0, hours=0.5)
    t = np.where(t >= 900.0, t + 300.0, t)
    rate[np.flatnonzero(t < 900.0)[-20:]] += 100.0
    same_masks(t, rate)
    t2 = t.copy()
    t2[5000] = t2[4990]  # a step back: a new segment
    same_masks(t2, rate)
    fs, rng = 50.0, np.random.default_rng(2)
    bursts = np.concatenate([300.0 * k + np.arange(0.0, 5.0, 1 / fs) for k in range(20)])
    level = np.repeat(np.linspace(0.0, 2.0, 20), int(5 * fs))
    same_masks(bursts, level + 0.01 * rng.standard_normal(bursts.size))


def test_quantised_and_saturating_channels():
    # a 16-bit MEMS stream: many equal values, ties at every median
    t, rate, accel, _ = handled(seed=4, fs=20.0, hours=1.0)
    lsb = 250.0 / 32768.0
    counts = np.clip(np.round(rate / lsb), -600, 600) * lsb
    assert same_masks(t, counts, accel={"accel_z": np.round(accel * 4096) / 4096}).n_moving
    same_masks(t, np.round(rate, 1))


@pytest.mark.parametrize("seed", range(6))
def test_random_recordings(seed):
    """Random sizes (around the compiled medians' cut-offs), rates, gaps and motion."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1_500, 40_000))
    fs = float(rng.choice([1.0, 10.0, 100.0, 200.0]))
    t = np.arange(n) / fs + rng.normal(0.0, 1e-4 / fs, n) * (seed % 2)
    for at in rng.integers(1, n - 1, size=int(rng.integers(0, 4))):
        t[at:] += float(rng.uniform(3.0, 50.0)) / fs
    rate = rng.normal(0.0, 0.05, n) + 0.01 * np.cumsum(rng.normal(0.0, 1.0, n)) / np.sqrt(n)
    for start in rng.integers(0, n - 50, size=int(rng.integers(0, 5))):
        rate[start:start + int(rng.integers(2, 50))] += float(rng.uniform(-5.0, 5.0))
    settings = MotionSettings(baseline_s=float(rng.uniform(5.0, 120.0)),
                              window_s=float(rng.uniform(0.1, 3.0)))
    same_masks(t, {"a": rate, "b": rate[::-1].copy()}, settings=settings)


def test_a_long_recording_takes_the_bracketed_medians():
    # more than 4 x 65,536 differences: the global medians are bracketed, not gathered
    t, rate, _, _ = handled(seed=7, fs=100.0, hours=1.0)
    t = np.where(t > 1800.0, t + 10.0, t)  # a gap: the steps inside segments differ
    assert same_masks(t, rate).n_moving > 0


def test_simulated_handling_and_orientation_recordings():
    hrg = log_run(constant(20.0, 1.0), "paper-unit",
                  Logger(sample_rate_hz=5.0, accelerometer=True,
                         handling=Handling(orientations=4, handling_s=30.0,
                                           max_rate_dps=200.0)), seed=0)
    t = hrg.truth["time_s"]
    rate = hrg.truth["rate_dph"] if "rate_dph" in hrg.truth else next(
        v for k, v in hrg.columns.items() if k.startswith("gyro"))
    accel = {a: hrg.columns[f"acc_{a} [g]"] for a in "xyz"}
    mask = same_masks(t, {"rate_dph": rate}, accel=accel)
    assert mask.moving[hrg.truth["motion"]].mean() > 0.9
    mems = log_run(constant(20.0, 1.0), "paper-unit",
                   Logger(sample_rate_hz=2.0, frequency=False,
                          handling=Handling(orientations=3,
                                            g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G)),
                   seed=1)
    rates = {k: v for k, v in mems.columns.items() if k.startswith("gyro")}
    same_masks(mems.truth["time_s"], rates)


@pytest.mark.skipif(not Path(PAN).exists(), reason="real cold test not in the checkout")
def test_the_real_cold_test():
    data = np.genfromtxt(PAN, delimiter=",", skip_header=1)
    rates = {axis: data[:, 4 + k] for k, axis in enumerate("xyz")}
    t = data[:, 0] / 1000.0
    assert same_masks(t, rates).segment.max() + 1 == 25
    assert np.array_equal(segments_of(t), reference_segments(t))


@pytest.mark.parametrize("kind", ["normal", "ties", "sorted", "mostly_one", "zeros"])
def test_block_median_is_numpys(kind):
    rng = np.random.default_rng(11)
    for n in (3, 2048, 2049, 4096, 12_000, 12_001, 30_000):
        values = {"normal": rng.standard_normal(n),
                  "ties": np.round(3 * rng.standard_normal(n)),
                  "sorted": np.sort(rng.standard_normal(n)),
                  "mostly_one": np.where(rng.random(n) < 0.6, 1.0, rng.standard_normal(n)),
                  "zeros": np.zeros(n)}[kind]
        assert kernel.median(values) == np.median(values)


@pytest.mark.parametrize("mode", [kernel.FORWARD, kernel.INSIDE, kernel.DEVIATION,
                                  kernel.INSIDE_FORWARD])
def test_difference_medians_are_numpys(mode):
    rng = np.random.default_rng(mode)
    n = 400_000
    time_s = np.arange(n) / 200.0  # steps of 0.005 s up to rounding: few distinct values
    time_s[n // 3:] += 7.0
    time_s[n // 2] = time_s[n // 2 - 1]
    walk = np.cumsum(rng.standard_normal(n))
    for x in (time_s, walk, np.round(walk)):
        breaks = np.diff(segments_of(time_s)) != 0
        d = np.diff(x)
        selected = {kernel.FORWARD: d[d > 0], kernel.INSIDE: d[~breaks],
                    kernel.DEVIATION: np.abs(d[~breaks] - 0.25),
                    kernel.INSIDE_FORWARD: d[~breaks & (d > 0)]}[mode]
        value, count = _difference_median(x, breaks, mode, 0.25)
        assert count == selected.size
        assert value == np.median(selected)


def test_steps_over_is_numpys():
    """The dropouts (steps longer than a limit) as ``np.flatnonzero(np.diff(t) > limit)``,
    with backward steps, repeated times and a NaN time."""
    rng = np.random.default_rng(11)
    time_s = np.cumsum(rng.exponential(0.01, 200_000))
    time_s[[50, 9_000, 150_000]] += [5.0, -3.0, 0.0]
    time_s[77] = time_s[76]
    time_s[120_000] = np.nan
    for limit in (0.0, 0.02, 0.05, 1.0, 10.0):
        expected = np.flatnonzero(np.diff(time_s) > limit)
        found = kernel.steps_over(time_s, limit)
        assert found.dtype == expected.dtype and np.array_equal(found, expected), limit
    for short in (np.zeros(0), np.ones(1), np.array([0.0, 7.0])):
        assert np.array_equal(kernel.steps_over(short, 1.0),
                              np.flatnonzero(np.diff(short) > 1.0))


@pytest.mark.parametrize("input_rate", ["table", 10.0])
def test_the_input_rate_subtracted_in_place(input_rate):
    """``overwrite=True`` subtracts the known input rate in the caller's array (which then
    holds the rate the level test reads) and finds the masks of the reference."""
    t, rate, _, _ = handled(bursts=3)
    table = np.where(t > 3600.0, 36.0, 0.0) if input_rate == "table" else input_rate
    mine = rate + table
    expected = same_masks(t, mine, input_rate=table)
    found = detect_motion(t, mine, input_rate=table, overwrite=True)
    assert found.n_moving == expected.n_moving > 0
    assert np.array_equal(found.moving, expected.moving)
    for reason in expected.reasons:
        assert np.array_equal(found.reasons[reason], expected.reasons[reason]), reason
    np.testing.assert_array_equal(mine, (rate + table) - table)  # bit for bit
