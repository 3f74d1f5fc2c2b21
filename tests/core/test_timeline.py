"""The time axis as segments: the one gap test, windows, power-on time, slicing, blocks."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.core.timeline import (
    Timeline,
    gap_limit_s,
    holdout_rows,
    is_gap,
    parse_time_bound,
    seconds_since_power_on,
    segment_bounds,
    slice_rows,
    time_blocks,
    windows,
)
from hrgtc.core.timeline_builder import TimelineBuilder


def burst_times(bursts=25, burst_s=5.0, period_s=300.0, rate_hz=50.0, start_s=15.352):
    """A burst logger's time axis like the PAN cold test: 250 samples every 300 s."""
    one = np.arange(round(burst_s * rate_hz)) / rate_hz
    return np.concatenate([start_s + k * period_s + one for k in range(bursts)])


def test_a_step_of_exactly_two_periods_is_one_missing_sample_not_a_gap():
    period = 0.005
    # 2 periods computed from rounded times lands a hair above 2 * period
    times = np.array([1000.0, 1000.0 + period, 1000.0 + 3 * period])
    assert np.diff(times)[1] != 2 * period  # the rounding the tolerance is there for
    assert not is_gap(np.diff(times), period).any()
    assert is_gap(np.array([2.01 * period]), period).all()
    assert gap_limit_s(period) == pytest.approx(2 * period, rel=1e-5)


def test_burst_axis_gives_its_segments_span_and_recorded_duration():
    time = burst_times()
    line = Timeline.from_time(time, 0.02)
    assert line.n_segments == 25
    assert line.samples_per_segment.tolist() == [250] * 25
    assert line.recorded_s == pytest.approx(125.0)
    assert line.span_s == pytest.approx(24 * 300.0 + 4.98)
    assert line.burst_length_s == pytest.approx(5.0)
    assert line.burst_period_s == pytest.approx(300.0)
    assert line.is_bursty
    assert "recorded 125 s in 25 segment(s)" in line.summary().text()


def test_the_builder_chunk_by_chunk_gives_the_whole_timeline():
    time = burst_times()
    whole = Timeline.from_time(time, 0.02)
    for size in (1, 7, 250, 251, 1000):
        builder = TimelineBuilder(0.02)
        for first in range(0, time.size, size):
            builder.partial_fit(time[first:first + size])
        built = builder.finish()
        np.testing.assert_array_equal(built.bounds, whole.bounds)
        np.testing.assert_array_equal(built.start_s, whole.start_s)
        np.testing.assert_array_equal(built.stop_s, whole.stop_s)


def test_warm_up_counts_from_power_on_once_unless_each_segment_restarts():
    time = burst_times()
    since = seconds_since_power_on(time)
    # a 50 s warm-up drops the first burst only (it lasts 5 s), not 2,500 samples
    assert np.count_nonzero(since < 50.0) == 250
    # shorter than the first burst's span: nothing but those first seconds
    assert np.count_nonzero(since < 3.0) == 150
    restart = seconds_since_power_on(time, segment_bounds(time, 0.02), True)
    assert np.count_nonzero(restart < 3.0) == 25 * 150


def test_windows_never_span_a_gap_and_partial_ones_follow_the_half_rule():
    time = burst_times()  # 5 s bursts, 10 s windows: each burst is one half window
    kept = windows(time, 10.0, period_s=0.02)
    assert kept.n_windows == 25 and kept.n_partial_kept == 25 and kept.rows_dropped == 0
    short = windows(time, 12.0, period_s=0.02)  # 250 of 600 rows: under half, dropped
    assert short.n_windows == 0 and short.n_partial_dropped == 25 and short.rows_dropped == 6250
    # each window's rows lie in one burst
    means = windows(time, 2.0, period_s=0.02)
    spans = [np.ptp(time[means.labels == k]) for k in range(means.n_windows)]
    assert max(spans) < 2.0
    np.testing.assert_allclose(means.means(time)[:3], [time[:100].mean(), time[100:200].mean(),
                                                       time[200:250].mean()])


def test_slicing_by_seconds_and_by_clock_time():
    time = burst_times()
    first, stop = slice_rows(time, 600.0, 3600.0)
    assert (time[first] - time[0]) >= 600.0 and (time[stop - 1] - time[0]) < 3600.0
    assert stop - first == 10 * 250
    origin = "2020-03-07T15:45:00"
    assert parse_time_bound("2020-03-07T16:45", origin) == 3600.0
    assert parse_time_bound("600", None) == 600.0
    with pytest.raises(InputError, match="no clock times"):
        parse_time_bound("2020-03-07T16:45", None)
    with pytest.raises(InputError, match="neither seconds"):
        parse_time_bound("noon", origin)
    with pytest.raises(InputError, match="after --start"):
        slice_rows(time, 10.0, 5.0)


def test_time_blocks_cut_at_burst_bounds_and_holdout_never_splits_a_burst():
    time = burst_times(bursts=24)
    blocks = time_blocks(time, 4)
    assert [b - a for a, b in blocks] == [6 * 250] * 4
    cut = holdout_rows(time, holdout_fraction=0.25)
    assert cut == 18 * 250
    assert holdout_rows(time, holdout_s=30.0) == 18 * 250  # 6 bursts of 5 s recorded
    continuous = np.arange(1000) * 0.1
    assert holdout_rows(continuous, holdout_fraction=0.3) == 700
    with pytest.raises(InputError, match="exactly one"):
        holdout_rows(continuous)


@pytest.mark.parametrize("sizes", [[1, 1, 98], [98, 1, 1], [1, 97, 1, 1], [2, 2, 2, 94]])
def test_time_blocks_of_very_unequal_segments_are_contiguous_and_nonempty(sizes):
    # window means of a real file with motion left out: a few long still periods and
    # short pieces between them (issue 27: the CATS tag's file crashed here, IndexError)
    starts = np.cumsum([0, *sizes[:-1]]) * 1000.0
    time = np.concatenate([s + np.arange(k, dtype=float)
                           for s, k in zip(starts, sizes, strict=True)])
    for count in (2, 3):
        blocks = time_blocks(time, count)
        assert len(blocks) == count
        assert blocks[0][0] == 0 and blocks[-1][1] == time.size
        assert all(a < b for a, b in blocks)
        pairs = itertools.pairwise(blocks)
        assert all(b == c for (_, b), (c, _) in pairs)
