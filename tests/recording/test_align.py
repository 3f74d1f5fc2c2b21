"""Tests of hrgtc.recording.align: the streams of a file joined onto one time axis.

Truth: a 10 Hz gyro stream and a 1 Hz thermometer stream, aligned, give the same
recording (bit for bit) as the same data written as one 10 Hz table whose 1 Hz
column is empty between its values, read through the existing slow-channel path.
"""

from __future__ import annotations

import json
import warnings

import h5py
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.core.errors import RecordingError, SlowChannelWarning
from hrgtc.recording import Metadata, Recording, iter_chunks, read, write
from hrgtc.recording.align import AlignedSource, align
from hrgtc.recording.formats import TableSource

N = 1200  # 120 s at 10 Hz


def gyro_and_thermometer(gap: bool = False):
    """10 Hz gyro columns; a housing thermometer at 1 Hz starting at 0.3 s (optionally a stop)."""
    t = np.arange(N) / 10.0
    rng = np.random.default_rng(3)
    gyro = {"time_s": t, "freq_hz": 4425.0 - 0.002 * t,
            "rate_dph": 9.7 + rng.standard_normal(N)}
    logged = np.arange(3, N, 10)  # rows 3, 13, 23 ...: the thermometer's times
    if gap:
        logged = logged[(logged < 400) | (logged > 700)]  # it stopped for 30 s
    housing = 20.0 + 0.05 * t[logged] + 0.01 * rng.standard_normal(logged.size)
    return gyro, t[logged], housing, logged


def one_table(gyro, logged, housing):
    """The existing layout: one 10 Hz table, housing_c empty where it was not logged."""
    column = np.full(N, np.nan)
    column[logged] = housing
    return {**gyro, "housing_c": column}


def two_stream_h5(path, gyro, thermo_time, housing):
    with h5py.File(path, "w") as f:
        f.attrs["sample_rate_hz"] = 10.0
        f.attrs["unit"] = "SN 4"
        fast = f.create_group("gyro")
        for name, values in gyro.items():
            fast[name] = values
        slow = f.create_group("thermal")
        slow["time_s"] = thermo_time
        slow["housing_c"] = housing
    return path


@pytest.mark.parametrize("mode", ["hold", "interpolate"])
@pytest.mark.parametrize("gap", [False, True])
def test_two_streams_equal_the_slow_channel_path(tmp_path, mode, gap):
    gyro, thermo_time, housing, logged = gyro_and_thermometer(gap)
    table = write(Recording(one_table(gyro, logged, housing), Metadata(10.0, unit="SN 4")),
                  tmp_path / "one.parquet")
    streams = two_stream_h5(tmp_path / "two.h5", gyro, thermo_time, housing)
    words = {"slow_channels": mode, "hold_max_s": 2.5 if gap else None, "gaps": "ignore"}
    with pytest.warns(SlowChannelWarning) as single_warnings:
        expected = read(table, **words)
    with pytest.warns(SlowChannelWarning) as aligned_warnings:
        aligned = read(streams, **words)
    assert aligned.names == expected.names
    for name in expected.names:
        assert np.array_equal(aligned[name], expected[name]), name
    assert aligned.metadata.sample_rate_hz == 10.0 and aligned.metadata.unit == "SN 4"
    # rows before the first value (0.3 s) and, with the stop, those more than 2.5 s after
    # the last value before it (row 393) up to the next one (row 703)
    rows = np.arange(N)
    assert len(expected) == N - 3 - (np.count_nonzero((rows > 393 + 25) & (rows < 703))
                                     if gap else 0)
    # both report the channel alike: period, maximum age, cells filled, rows dropped
    first = str(single_warnings[0].message).split(": ", 1)[1]
    second = str(aligned_warnings[0].message).split(": ", 1)[1]
    assert first == second
    # streamed in chunks: the same rows
    with pytest.warns(SlowChannelWarning):
        chunks = list(iter_chunks(streams, chunk_rows=97, **words))
    assert np.array_equal(np.concatenate([c["housing_c"] for c in chunks]),
                          expected["housing_c"])


def test_the_values_are_the_last_one_or_the_line_between(tmp_path):
    t = np.arange(50) / 10.0
    slow_t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    slow_v = np.array([0.0, 10.0, 20.0, 30.0, 40.0])
    fast = TableSource("run", {"time_s": t, "rate_dph": np.zeros(50)})
    slow = TableSource("run", {"time_s": slow_t, "housing_c": slow_v})
    held = align([fast, slow], "hold").read(["time_s", "housing_c"], set())
    np.testing.assert_array_equal(held.column("housing_c").to_numpy(), 10.0 * np.floor(t))
    line = align([fast, slow], "interpolate").read(["time_s", "housing_c"], set())
    expected = np.where(t <= 4.0, 10.0 * t, 40.0)  # after the last value: held
    np.testing.assert_allclose(line.column("housing_c").to_numpy(), expected, atol=1e-12)


def test_a_single_stream_is_returned_as_it_is():
    only = TableSource("run", {"time_s": np.arange(3.0)})
    assert align([only]) is only
    assert align([only], "error") is only


def test_error_mode_and_a_column_in_two_streams_are_refused():
    fast = TableSource("run.h5", {"time_s": np.arange(10.0), "rate_dph": np.zeros(10)},
                       stream="gyro")
    slow = TableSource("run.h5", {"time_s": np.arange(2.0), "rate_dph": np.zeros(2)},
                       stream="thermal")
    with pytest.raises(RecordingError, match=r"run\.h5: column 'rate_dph' is in the streams "
                       r"gyro and thermal"):
        AlignedSource([fast, slow])
    other = TableSource("run.h5", {"time_s": np.arange(2.0), "housing_c": np.zeros(2)},
                        stream="thermal")
    with pytest.raises(RecordingError, match=r"2 streams on their own time axes \(gyro, "
                       r"thermal\) and --slow-channels is 'error'; pass --slow-channels hold"):
        align([fast, other], "error")


def test_a_stream_time_axis_in_microseconds(tmp_path):
    t = np.arange(100) / 10.0
    fast = TableSource("run", {"time_s": t, "rate_dph": np.zeros(100)})
    slow = TableSource("run", {"t_us": np.arange(10) * 1e6, "housing_c": np.arange(10.0)},
                       time_column="t_us", time_unit_s=1e-6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SlowChannelWarning)
        table = align([fast, slow]).read(["time_s", "housing_c"], set())
    np.testing.assert_array_equal(table.column("housing_c").to_numpy(), np.floor(t))


def test_hrgtc_info_aligns_the_streams_of_an_hdf5_file(tmp_path):
    from typer.testing import CliRunner

    from hrgtc.cli import app

    gyro, thermo_time, housing, _ = gyro_and_thermometer()
    path = two_stream_h5(tmp_path / "two.h5", gyro, thermo_time, housing)
    runner = CliRunner()
    with pytest.warns(SlowChannelWarning):
        result = runner.invoke(app, ["info", str(path), "--json"])
    assert result.exit_code == 0, result.output
    info = json.loads(result.output)
    assert info["format"] == "hdf5" and info["rows"] == N - 3  # before the first value: dropped
    housing_c = next(c for c in info["columns"] if c["name"] == "housing_c")
    assert housing_c["min"] == float(housing.min()) and housing_c["max"] == float(housing.max())
    refused = runner.invoke(app, ["info", str(path), "--slow-channels", "error"])
    assert "2 streams on their own time axes (gyro, thermal)" in refused.output


def brute_force(time_s, sample_time, sample_values, mode, max_age_s):
    """Row by row, in plain Python: the value each row gets, or None for a row dropped."""
    out = []
    for t in time_s:
        before = [i for i, s in enumerate(sample_time) if s <= t]
        if not before or t - sample_time[before[-1]] > max_age_s:
            out.append(None)
            continue
        i = before[-1]
        value = sample_values[i]
        if mode == "interpolate" and i + 1 < len(sample_time) and sample_time[i + 1] > \
                sample_time[i]:
            share = (t - sample_time[i]) / (sample_time[i + 1] - sample_time[i])
            value = value + share * (sample_values[i + 1] - value)
        out.append(value)
    return out


@settings(max_examples=40, deadline=None)
@given(slow_times=st.lists(st.floats(0.0, 12.0), min_size=1, max_size=15, unique=True),
       mode=st.sampled_from(["hold", "interpolate"]), max_age_s=st.floats(0.05, 5.0),
       rows=st.integers(1, 40))
def test_aligned_rows_equal_a_row_by_row_computation(slow_times, mode, max_age_s, rows):
    time_s = np.arange(100) / 8.0  # 8 Hz, 12.4 s
    sample_time = np.sort(np.asarray(slow_times))
    sample_values = np.cos(sample_time) * 10.0
    fast = TableSource("run", {"time_s": time_s, "rate_dph": np.arange(100.0)})
    slow = TableSource("run", {"time_s": sample_time[::-1].copy(),  # unsorted on disk
                               "housing_c": sample_values[::-1].copy()})
    aligned = align([fast, slow], mode, max_age_s)
    tables = list(aligned.iter_tables(["time_s", "rate_dph", "housing_c"], set(), rows))
    got = np.concatenate([t.column("housing_c").to_numpy() for t in tables])
    kept = np.concatenate([t.column("rate_dph").to_numpy() for t in tables]).astype(int)
    expected = brute_force(time_s, sample_time, sample_values, mode, max_age_s)
    assert kept.tolist() == [i for i, v in enumerate(expected) if v is not None]
    np.testing.assert_allclose(got, [v for v in expected if v is not None], rtol=0, atol=1e-9)
    state = aligned.slow.channels["housing_c"]
    assert state.dropped == expected.count(None)


def test_a_channel_of_one_value_needs_a_maximum_age():
    fast = TableSource("run.h5", {"time_s": np.arange(10.0), "rate_dph": np.zeros(10)})
    slow = TableSource("run.h5", {"time_s": np.array([2.0]), "housing_c": np.array([20.0])},
                       stream="thermal")
    with pytest.raises(RecordingError, match=r"run\.h5: column 'housing_c' of the stream "
                       r"'thermal' has 1 value\(s\) .* give --hold-max-s SECONDS"):
        align([fast, slow]).read(["time_s", "housing_c"], set())
    table = align([fast, slow], max_age_s=100.0).read(["time_s", "housing_c"], set())
    assert table.column("housing_c").to_pylist() == [20.0] * 8  # rows 0 and 1: before it
