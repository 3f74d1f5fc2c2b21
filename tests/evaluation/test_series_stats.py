"""Tests of hrgtc.evaluation.series_stats: streamed statistics equal the in-memory ones."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from hrgtc.evaluation.allan import allan_deviation
from hrgtc.evaluation.metrics import bias_stability_table
from hrgtc.evaluation.noise import noise_terms
from hrgtc.evaluation.series_stats import SeriesStatistics


def _series(n, seed=3, fs=10.0):
    rng = np.random.default_rng(seed)
    white = rng.normal(0.0, 2.0, n)
    walk = np.cumsum(rng.normal(0.0, 0.002, n))
    drift = 30.0 + 5.0 * np.sin(np.arange(n) / (fs * 3000.0))  # a slow thermal drift [°/h]
    return white + walk + drift


def _feed(values, stats, seed=0):
    rng = np.random.default_rng(seed)
    start = 0
    while start < values.size:
        stop = min(values.size, start + int(rng.integers(1, 40_000)))
        stats.partial_fit(values[start:stop])
        start = stop
    return stats


def test_below_the_cap_the_results_are_those_of_the_whole_series():
    fs, taus = 10.0, (1.0, 10.0, 100.0)
    values = _series(200_003, fs=fs)
    stats = _feed(values, SeriesStatistics(fs, taus))
    expected = bias_stability_table(values, fs, taus)
    for tau in taus:  # the same block means; their variance merged chunk by chunk
        assert stats.bias_stability()[tau] == pytest.approx(expected[tau], rel=1e-13, abs=0)
    streamed, whole = stats.allan_deviation(), allan_deviation(values, fs, taus="octave")
    np.testing.assert_array_equal(streamed.taus_s, whole.taus_s)
    np.testing.assert_array_equal(streamed.deviation, whole.deviation)
    np.testing.assert_array_equal(streamed.counts, whole.counts)


def test_beyond_the_cap_short_taus_are_exact_and_long_ones_agree_within_their_confidence():
    fs, taus = 10.0, (1.0, 10.0, 100.0)
    values = _series(600_011, seed=5, fs=fs)
    stats = _feed(values, SeriesStatistics(fs, taus, full_samples=1 << 16), seed=1)
    assert stats._full is None and stats._decimated.rows == 32  # kept means <= 2^15
    table = stats.bias_stability()
    expected = bias_stability_table(values, fs, taus)
    for tau in taus:
        assert table[tau] == pytest.approx(expected[tau], rel=1e-12, abs=0)
    streamed, whole = stats.allan_deviation(), allan_deviation(values, fs, taus="octave")
    np.testing.assert_allclose(streamed.taus_s, whole.taus_s, rtol=0, atol=0)
    exact = streamed.taus_s * fs < 32
    assert exact.sum() == 5  # m = 1, 2, 4, 8, 16 from the running sums
    np.testing.assert_allclose(streamed.deviation[exact], whole.deviation[exact], rtol=1e-10)
    # m >= 32 from 32-sample means: same estimator over starts at multiples of 32
    usable = whole.blocks >= 10
    np.testing.assert_allclose(streamed.deviation[usable], whole.deviation[usable], rtol=0.03)
    a, b = noise_terms(streamed), noise_terms(whole)
    assert a.arw_deg_per_rt_h == pytest.approx(b.arw_deg_per_rt_h, rel=0.02)


def test_memory_is_bounded_by_the_cap_not_the_length():
    # 4 M samples (32 MB as one array) pass through in ~1 MB chunks; the statistics keep
    # at most 2^16 samples (0.5 MB) for the Allan deviation plus the τ-block means
    fs = 200.0
    rng = np.random.default_rng(0)
    stats = SeriesStatistics(fs, (1.0, 10.0, 100.0), full_samples=1 << 16)
    tracemalloc.start()
    try:
        for _ in range(32):
            stats.partial_fit(rng.normal(0.0, 2.0, 1 << 17))
        stats.allan_deviation()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert stats.n == 1 << 22
    assert peak < 12e6, peak  # the chunk and its temporaries, not the 32 MB series
