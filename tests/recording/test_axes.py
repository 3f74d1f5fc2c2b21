"""Tests of hrgtc.recording.axes: multi-axis recordings and the view of one axis.

Truth: a multi-axis file is built from single-axis recordings, so every axis
view read back must equal its single-axis recording bit for bit (with the
other axes' frequencies and temperatures beside it); the views share memory
with the multi-axis recording (no copies).
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import RecordingError
from hrgtc.recording import (
    COLUMNS,
    Metadata,
    Recording,
    axis_names,
    axis_view,
    iter_chunks,
    read,
    validate,
    write,
)
from hrgtc.recording.axes import AXIS_COLUMNS, base_name, split_axis

RATE_HZ = 50.0
AXES = ("x", "y", "z")


def single_axis(axis_index: int, n: int = 300) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(axis_index)
    return {
        "freq_hz": 4425.0 + 3.0 * axis_index + 0.01 * rng.standard_normal(n),
        "rate_dph": 5.0 * axis_index + rng.standard_normal(n),
        "temperature_c": 20.0 + axis_index + 0.1 * rng.standard_normal(n),
        "bias_dph": 2.0 + 0.01 * rng.standard_normal(n),
    }


def multi_axis(n: int = 300) -> Recording:
    columns = {"time_s": np.arange(n) / RATE_HZ, "chamber_c": np.full(n, 25.0)}
    for i, axis in enumerate(AXES):
        columns.update({f"{k}_{axis}": v for k, v in single_axis(i, n).items()})
    meta = Metadata(RATE_HZ, unit="imu", input_rate_dph=1.0,
                    extra={"axis_input_rate_dph": {"x": 9.67, "y": -3.5, "z": 0.0}})
    return Recording(columns, meta)


def test_new_contract_columns():
    for name, unit in (("input_rate_dph", "deg/h"), ("temperature_c", "degC"),
                       ("scale_ppm", "ppm")):
        assert COLUMNS[name][0] == unit and not COLUMNS[name][1]
    assert set(AXIS_COLUMNS) <= set(COLUMNS)


def test_axis_names_in_file_order_and_single_axis():
    assert axis_names(["time_s", "rate_dph_z", "freq_hz_z", "rate_dph_a1", "input_rate_dph_q"]) \
        == ("z", "a1")
    assert axis_names(["time_s", "freq_hz", "rate_dph", "housing_c"]) == ()
    assert axis_names(["rate_dph_", "rate_dph_1x", "rate_dph_x_y"]) == ()


def test_split_axis_prefers_the_longest_contract_name():
    assert split_axis("input_rate_dph_x") == ("input_rate_dph", "x")
    assert split_axis("rate_dph_x") == ("rate_dph", "x")
    assert split_axis("chamber_c") == ("chamber_c", None)
    assert base_name("temperature_c_b", ("a", "b")) == "temperature_c"
    assert base_name("temperature_c_b", ("x",)) == "temperature_c_b"


def test_axis_view_renames_keeps_shared_and_cross_axis_without_copies():
    rec = multi_axis()
    view = axis_view(rec, "y")
    assert set(view.names) == {"time_s", "chamber_c", "freq_hz", "rate_dph", "temperature_c",
                               "bias_dph", "freq_hz_x", "freq_hz_z", "temperature_c_x",
                               "temperature_c_z"}
    assert np.shares_memory(view["rate_dph"], rec["rate_dph_y"])
    assert np.shares_memory(view["time_s"], rec["time_s"])
    assert np.shares_memory(view["freq_hz_x"], rec["freq_hz_x"])
    assert view.metadata.input_rate_dph == -3.5
    assert view.metadata.extra["axis"] == "y"
    np.testing.assert_array_equal(view.measured_bias_dph, rec["rate_dph_y"] + 3.5)


def test_axis_view_without_per_axis_input_rate_uses_the_metadata():
    rec = multi_axis()
    meta = Metadata(RATE_HZ, input_rate_dph=7.0)
    view = axis_view(Recording(rec.columns, meta), "x")
    assert view.metadata.input_rate_dph == 7.0


def test_axis_view_of_single_axis_recording_is_a_clear_error():
    n = 10
    rec = Recording({"time_s": np.arange(n) / RATE_HZ, "freq_hz": np.full(n, 4425.0),
                     "rate_dph": np.zeros(n)}, Metadata(RATE_HZ), source="run.csv")
    with pytest.raises(RecordingError, match=r"run.csv: axis 'x' asked of a single-axis"):
        axis_view(rec, "x")
    with pytest.raises(RecordingError, match=r"no axis 'w'.*\['x', 'y', 'z'\]"):
        axis_view(multi_axis(), "w")


def test_measured_bias_uses_the_input_rate_column():
    n = 6
    inputs = np.array([0.0, 0.0, 36000.0, 36000.0, -36000.0, -36000.0])
    rate = inputs + 3.0
    rec = Recording({"time_s": np.arange(n) / RATE_HZ, "freq_hz": np.full(n, 4425.0),
                     "rate_dph": rate, "input_rate_dph": inputs},
                    Metadata(RATE_HZ, input_rate_dph=99.0))
    np.testing.assert_array_equal(rec.measured_bias_dph, np.full(n, 3.0))


@pytest.mark.parametrize("suffix", [".parquet", ".csv", ".h5"])
def test_multi_axis_round_trip_views_equal_single_axis_files(tmp_path, suffix):
    rec = multi_axis()
    path = write(rec, tmp_path / f"imu{suffix}")
    back = read(path)
    assert axis_names(back.names) == AXES
    for i, axis in enumerate(AXES):
        single = Recording({"time_s": rec["time_s"], "chamber_c": rec["chamber_c"],
                            **single_axis(i)}, rec.metadata)
        single_back = read(write(single, tmp_path / f"{axis}{suffix}"))
        view = axis_view(back, axis)
        for name in single_back.names:
            np.testing.assert_array_equal(view[name], single_back[name])
        assert view.metadata.input_rate_dph == rec.metadata.extra["axis_input_rate_dph"][axis]


def test_multi_axis_streamed_in_chunks_equals_whole(tmp_path):
    path = write(multi_axis(), tmp_path / "imu.parquet")
    whole = read(path)
    chunks = list(iter_chunks(path, chunk_rows=70))
    assert len(chunks) == 5
    for name in whole.names:
        np.testing.assert_array_equal(np.concatenate([c[name] for c in chunks]), whole[name])


def test_validation_requires_each_axis_frequency():
    rec = multi_axis()
    columns = {k: v for k, v in rec.columns.items() if k != "freq_hz_z"}
    with pytest.raises(RecordingError, match=r"'freq_hz_z' missing.*--col freq_hz_z="):
        validate(Recording(columns, rec.metadata))


def test_validation_checks_each_axis_plausibility_and_units():
    rec = multi_axis()
    bad = rec["freq_hz_y"].copy()
    bad[123] = 4425.0 * 1.2
    with pytest.raises(RecordingError, match=r"column 'freq_hz_y', row 123: 5310 Hz"):
        validate(rec.with_columns(freq_hz_y=bad))
    with pytest.raises(RecordingError, match=r"freq_hz_z looks like kHz"):
        validate(rec.with_columns(freq_hz_z=rec["freq_hz_z"] / 1000.0))
    with pytest.raises(RecordingError, match=r"rate_dph_x looks like °/s or rad/s"):
        validate(rec.with_columns(rate_dph_x=rec["rate_dph_x"] / 3600.0))


def test_rate_table_steps_are_checked_on_rate_minus_input():
    n = 3000
    rng = np.random.default_rng(5)
    inputs = np.repeat([0.0, 36000.0, -36000.0, 360000.0, 0.0, 1.08e6], n // 6)
    rate = inputs * (1 + 300e-6) + 4.0 + 0.5 * rng.standard_normal(n)
    columns = {"time_s": np.arange(n) / RATE_HZ, "freq_hz": np.full(n, 4425.0),
               "rate_dph": rate, "input_rate_dph": inputs}
    assert validate(Recording(columns, Metadata(RATE_HZ))).ok
    in_dps = {**columns, "rate_dph": rate / 3600.0, "input_rate_dph": inputs / 3600.0}
    with pytest.raises(RecordingError, match="rate_dph looks like °/s"):
        validate(Recording(in_dps, Metadata(RATE_HZ)))


def test_users_per_axis_names_and_units_mapped(tmp_path):
    """A foreign Parquet file: its own names, frequencies in kHz, rates in °/s."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rec = multi_axis()
    theirs = {"t": rec["time_s"], "tc": rec["chamber_c"]}
    cols = ["time_s=t", "chamber_c=tc"]
    for axis in AXES:
        theirs[f"f{axis}"] = rec[f"freq_hz_{axis}"] / 1000.0
        theirs[f"w{axis}"] = rec[f"rate_dph_{axis}"] / 3600.0
        cols += [f"freq_hz_{axis}=f{axis}", f"rate_dph_{axis}=w{axis}"]
    path = tmp_path / "theirs.parquet"
    pq.write_table(pa.table(theirs), path)
    back = read(path, columns=cols, units={"freq": "kHz", "rate": "dps"},
                metadata={"sample_rate_hz": RATE_HZ})
    assert axis_names(back.names) == AXES
    for axis in AXES:
        np.testing.assert_allclose(back[f"freq_hz_{axis}"], rec[f"freq_hz_{axis}"], rtol=1e-15)
        np.testing.assert_allclose(back[f"rate_dph_{axis}"], rec[f"rate_dph_{axis}"], rtol=1e-15)


def test_per_axis_units_in_the_parquet_schema(tmp_path):
    import pyarrow.parquet as pq

    path = write(multi_axis(), tmp_path / "imu.parquet")
    schema = pq.read_schema(path)
    assert schema.field("rate_dph_y").metadata[b"unit"] == b"deg/h"
    assert schema.field("temperature_c_z").metadata[b"unit"] == b"degC"


def test_a_suffixed_name_without_its_rate_column_is_no_axis(tmp_path):
    """``resonator_c_est`` of a compensated single-axis output is not axis 'est'."""
    n = 50
    rec = Recording({"time_s": np.arange(n) / RATE_HZ, "freq_hz": np.full(n, 4425.0),
                     "rate_dph": np.ones(n), "rate_comp_dph": np.ones(n),
                     "resonator_c_est": np.full(n, 900.0)}, Metadata(RATE_HZ))
    back = read(write(rec, tmp_path / "out.parquet"))
    assert back.names == rec.names and axis_names(back.names) == ()
    assert base_name("resonator_c_est", axis_names(back.names)) == "resonator_c_est"
