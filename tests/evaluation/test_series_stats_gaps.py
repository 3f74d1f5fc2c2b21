"""Bias stability and Allan deviation never reach across a gap (segments pushed apart)."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.evaluation.allan import allan_deviation
from hrgtc.evaluation.series_stats import SeriesStatistics


def _segments(seed=0, sizes=(1234, 777, 2048)):
    rng = np.random.default_rng(seed)
    # each segment sits at its own level: a difference across a gap would see the step
    return [rng.normal(0.0, 1.0, n) + 100.0 * k for k, n in enumerate(sizes)]


def _manual_oadev(parts, m):
    total = count = 0.0
    for x in parts:
        phase = np.concatenate([[0.0], np.cumsum(x)])
        if phase.size <= 2 * m:
            continue
        d = phase[2 * m:] - 2 * phase[m:-m] + phase[:-2 * m]
        total += float(np.sum(d * d))
        count += d.size
    return np.sqrt(total / (2.0 * count)) / m, int(count)


def test_tau_blocks_never_span_a_gap_and_allan_is_pooled_within_segments():
    parts = _segments()
    stats = SeriesStatistics(10.0, (1.0, 10.0), allan=True)
    for k, part in enumerate(parts):
        stats.partial_fit(part, [0] if k else [])
    assert stats.segments == 3 and stats.longest_segment_s == pytest.approx(204.8)
    # full τ-blocks of each segment, and its partial last block when it holds at least
    # half τ less one sample (4 of 10: the tails 4, 7 and 8 all count)
    means = np.concatenate([
        np.r_[p[: p.size // 10 * 10].reshape(-1, 10).mean(axis=1),
              [p[p.size // 10 * 10:].mean()] if p.size % 10 >= 4 else []] for p in parts])
    assert stats.bias_stability()[1.0] == pytest.approx(np.std(means, ddof=1), rel=1e-12)
    assert stats.partial_blocks()[1.0] == 3
    curve = stats.allan_deviation()
    for tau, dev, n in zip(curve.taus_s, curve.deviation, curve.counts, strict=True):
        m = round(tau * 10.0)
        expected, count = _manual_oadev(parts, m)
        assert dev == pytest.approx(expected, rel=1e-9) and n == count
    # no τ beyond the longest segment's reach, and the step of 100 between segments is
    # nowhere to be seen (white noise of σ 1: ADEV(τ0) ≈ 1)
    assert curve.taus_s.max() * 10.0 * 2 < 2048
    assert curve.deviation[0] == pytest.approx(1.0, rel=0.1)
    joined = allan_deviation(np.concatenate(parts), 10.0, taus="octave")
    assert joined.deviation[-1] > 5.0  # what reaching across the gaps would have reported


def test_breaks_inside_one_push_and_in_the_decimated_path():
    parts = _segments(1, sizes=(3000, 2500, 4000))
    one = SeriesStatistics(10.0, (1.0,), allan=True, full_samples=2048)
    one.partial_fit(np.concatenate(parts), [3000, 5500])
    fine = one.allan_deviation()
    for tau, dev, n in zip(fine.taus_s, fine.deviation, fine.counts, strict=True):
        expected, count = _manual_oadev(parts, round(tau * 10.0))
        assert dev == pytest.approx(expected, rel=1e-9) and n == count


def test_bursts_shorter_than_tau_give_the_spread_of_their_burst_means():
    """5 s bursts at 50 Hz every 300 s (the real cold test's logger): no 10 s block fits in
    a burst, so τ = 10 s comes from the burst means (half τ or more), one burst that lost a
    sample (a spike removed) included; a burst of a fifth of τ is left out."""
    rng = np.random.default_rng(3)
    bursts = [rng.normal(0.0, 1.0, 250) + 5.0 * np.sin(k) for k in range(12)]
    bursts[4] = bursts[4][:249]
    bursts.append(rng.normal(0.0, 1.0, 100) + 1000.0)  # 2 s: too short for τ = 10 s
    stats = SeriesStatistics(50.0, (10.0,), allan=False)
    for k, burst in enumerate(bursts):
        stats.partial_fit(burst, [0] if k else [])
    expected = np.std([b.mean() for b in bursts[:12]], ddof=1)
    assert stats.bias_stability()[10.0] == pytest.approx(expected, rel=1e-12)
    assert stats.partial_blocks()[10.0] == 12


def test_pooled_interval_uses_the_segments_edf_in_both_paths():
    from hrgtc.evaluation.allan import deviation_edf
    from hrgtc.evaluation.allan_segments import pooled_edf

    parts = _segments(4, sizes=(1500, 900, 2600))
    lengths = [p.size for p in parts]
    for full in (1 << 22, 2048):  # samples held, and the exact running sums past the cap
        stats = SeriesStatistics(10.0, (1.0,), allan=True, full_samples=full)
        for k, part in enumerate(parts):
            stats.partial_fit(part, [0] if k else [])
        curve = stats.allan_deviation(confidence=0.683)
        assert curve.segments == 3 and stats.segment_lengths() == lengths
        for tau, edf, low, dev, high in zip(curve.taus_s, curve.edf, curve.lower,
                                            curve.deviation, curve.upper, strict=True):
            m = round(tau * 10.0)
            assert edf == pytest.approx(pooled_edf("allan", lengths, m), rel=1e-12)
            assert low < dev < high
        # the edf of one record of the total length (what was used before) is larger at
        # long τ (the decimated path keeps only the short τ of its exact sums)
        m = round(curve.taus_s[-1] * 10.0)
        if full > 4096:
            assert deviation_edf("allan", sum(lengths) + 1, m) > 1.3 * curve.edf[-1]


def test_burst_means_beyond_a_segment_from_pushed_times():
    """White rate noise σ = 1 at 50 Hz in 5 s bursts every 60 s: the burst-mean Allan
    deviation at τ = 60 s is σ/√(τ·fs) within its 99 % interval, with r = 12 stated."""
    rng = np.random.default_rng(12)
    stats = SeriesStatistics(50.0, (10.0,), allan=True)
    for k in range(300):
        stats.partial_fit(rng.normal(size=250) + 3.0, [0] if k else [],
                   time_s=60.0 * k + np.arange(250) / 50.0)
    result = stats.burst_allan(confidence=0.99)
    assert result.dead_time_ratio == pytest.approx(12.0) and result.bursts == 300
    assert result.counts[0] == 299
    theory = 1.0 / np.sqrt(60.0 * 50.0)
    assert result.lower[0] < theory < result.upper[0]
    lines = result.lines()
    assert "r = 12" in lines[0] and "N = 299" in lines[1] and "random walk" in lines[1]
    assert stats.segment_starts() == [250 * k for k in range(1, 300)]
    one = SeriesStatistics(50.0, (10.0,), allan=True)
    one.partial_fit(rng.normal(size=500))
    with pytest.raises(InputError, match="one contiguous segment"):
        one.burst_allan(0.683)
