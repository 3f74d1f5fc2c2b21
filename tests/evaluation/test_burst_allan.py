"""Allan deviation beyond a burst from burst means: dead-time ratio, white-noise correction,
and the bias it leaves for flicker and random-walk rate noise (Barnes' B2, SP 1065 5.15)."""

from __future__ import annotations

import math

import allantools
import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.evaluation.burst_allan import burst_mean_allan, dead_time_bias


@pytest.mark.parametrize("r", [1.0, 1.5, 2.5, 12.0, 60.0])
def test_dead_time_bias_at_one_burst_is_barnes_b2(r):
    """B2(r, μ) of Barnes (NBS TN 375; SP 1065 Section 5.15) is relative to σ²_y(τ_b);
    ours is relative to σ²_y(T) = σ²_y(τ_b)·r^μ. Closed forms: white FM B2 = 1, random
    walk FM (3r − 1)/2, flicker FM [(r+1)² ln(r+1) + (r−1)² ln(r−1) − 2r² ln r]/(4 ln 2),
    white PM 2/3 (r > 1)."""
    def xlogx2(v):
        return 0.0 if v == 0 else v * v * math.log(v)

    assert dead_time_bias(1, r, -1) == pytest.approx(r, rel=1e-12)
    assert dead_time_bias(1, r, 1) * r == pytest.approx((3 * r - 1) / 2, rel=1e-9)
    flicker = (xlogx2(r + 1) + xlogx2(r - 1) - 2 * xlogx2(r)) / (4 * math.log(2))
    assert dead_time_bias(1, r, 0) == pytest.approx(flicker, rel=1e-9)
    assert dead_time_bias(1, r, -2) / r ** 2 == pytest.approx(2 / 3 if r > 1 else 1.0)


def test_dead_time_bias_white_is_r_at_every_m_and_vanishes_without_dead_time():
    for m in (1, 2, 8, 64):
        assert dead_time_bias(m, 12.0, -1) == pytest.approx(12.0, rel=1e-12)
        for mu in (-1, 0, 1):
            assert dead_time_bias(m, 1.0, mu) == pytest.approx(1.0, rel=1e-9)
            # every rate noise: 1 <= bias <= r, so the corrected value is a lower bound
            assert 1.0 - 1e-9 <= dead_time_bias(m, 12.0, mu) <= 12.0 + 1e-9
    with pytest.raises(InputError, match="r >= 1"):
        dead_time_bias(1, 0.5, 0)


def _bursts(values, fs, burst_samples, period_samples):
    """Cut bursts out of a continuous record: means, durations and start times."""
    starts = np.arange(0, values.size - burst_samples + 1, period_samples)
    means = np.array([values[s:s + burst_samples].mean() for s in starts])
    return means, np.full(starts.size, burst_samples / fs), starts / fs


def test_white_noise_burst_means_match_theory_within_their_interval():
    """White rate noise σ = 1 at 50 Hz in 5 s bursts every 60 s (r = 12): the corrected
    burst-mean Allan deviation at τ = M·60 s is σ/√(τ·fs) (SP 1065 white FM) within its
    99 % interval (the coverage of the interval is tested below), the uncorrected one √r
    larger."""
    rng = np.random.default_rng(4)
    fs, burst, count = 50.0, 250, 600  # 5 s bursts every 60 s
    samples = rng.normal(size=(count, burst))  # only the bursts are recorded
    means = samples.mean(axis=1)
    result = burst_mean_allan(means, np.full(count, burst / fs), np.arange(count) * 60.0,
                              confidence=0.99)
    assert result.dead_time_ratio == pytest.approx(12.0) and result.runs == 1
    assert result.period_s == pytest.approx(60.0) and result.burst_s == pytest.approx(5.0)
    theory = 1.0 / np.sqrt(result.taus_s * fs)
    short = result.taus_s <= 16 * 60.0  # τ with at least ~70 terms
    assert short.sum() >= 5
    assert np.all(result.lower[short] < theory[short])
    assert np.all(theory[short] < result.upper[short])
    assert result.raw_deviation == pytest.approx(result.deviation * math.sqrt(12.0))
    assert result.counts[0] == count - 1
    assert np.all(result.bias_flicker < 1.0) and np.all(result.bias_random_walk < 1.0)
    assert result.bias_random_walk[0] == pytest.approx(math.sqrt((3 * 12 - 1) / 2 / 144))


def test_white_noise_interval_covers_the_truth_at_its_level():
    """Coverage of the 68 % interval at τ = T over 400 burst recordings: 0.68 ± 0.07."""
    rng = np.random.default_rng(8)
    hits = 0
    for _ in range(400):
        means = rng.normal(size=60) / math.sqrt(250.0)
        result = burst_mean_allan(means, np.full(60, 5.0), np.arange(60) * 60.0)
        hits += result.lower[0] < 1.0 / math.sqrt(60.0 * 50.0) < result.upper[0]
    assert hits / 400 == pytest.approx(0.683, abs=0.07)


def test_random_walk_burst_means_carry_the_stated_bias():
    """Random-walk rate noise cut into 5-sample bursts every 60 s at 1 Hz: averaged over 150
    recordings, corrected² / (oadev² of the continuous record at the same τ) equals the
    stated bias_random_walk² (B/r of the structure function) within 15 %."""
    rng = np.random.default_rng(21)
    ratios, stated = [], None
    for _ in range(150):
        values = np.cumsum(rng.normal(size=12000))
        means, durations, starts = _bursts(values, 1.0, 5, 60)
        result = burst_mean_allan(means, durations, starts)
        taus = result.taus_s[:3]
        _, truth, _, _ = allantools.oadev(values, rate=1.0, data_type="freq", taus=taus)
        ratios.append(result.deviation[:3] ** 2 / truth ** 2)
        stated = result.bias_random_walk[:3] ** 2
    assert np.mean(ratios, axis=0) == pytest.approx(stated, rel=0.15)
    assert stated[0] < 0.2  # the white-noise correction understates random walk 2.9× at T


def test_missing_bursts_split_runs_and_irregular_starts_are_not_estimable():
    rng = np.random.default_rng(1)
    starts = np.arange(40) * 300.0
    starts[20:] += 300.0  # one burst missing: no difference across it
    means = rng.normal(size=40)
    result = burst_mean_allan(means, np.full(40, 5.0), starts)
    assert result.runs == 2 and result.counts[0] == 38
    with pytest.raises(InputError, match="regular period"):
        burst_mean_allan(means[:5], np.full(5, 5.0), np.array([0.0, 10, 300, 310, 900]))
    with pytest.raises(InputError, match="no dead time"):
        burst_mean_allan(means, np.full(40, 300.0), np.arange(40) * 300.0)
