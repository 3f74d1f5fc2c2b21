"""Tests of hrgtc.recording.mapping on messy IMU files (PX4 / ArduPilot style logs).

Each case writes a small CSV the way such a logger would and checks the values
read against hand arithmetic: rad/s × (180/π) × 3600 = °/h (206264.806...),
µs / 10^6 = s, raw count × scale + offset = °C; the sensor thermometer's
frequency column is the temperature column itself.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hrgtc.core.errors import InputError, RecordingError
from hrgtc.recording import ReadOptions, axis_names, axis_view, parse_columns, read

RATE_HZ = 100.0
N = 400


def imu_csv(tmp_path, name="imu.csv", time_scale=1.0, rate_scale=1.0, temp=None, extra=None,
            table=None):
    """A three-axis log without frequency columns: t, gx, gy, gz, temp (and extras).

    ``table``: input rates added to gx (a rate-table run of the x axis).
    """
    rng = np.random.default_rng(3)
    columns = {"t": np.arange(N) / RATE_HZ * time_scale}
    for i, axis in enumerate("xyz"):
        columns[f"g{axis}"] = (1e-5 * (i + 1) + 1e-6 * rng.standard_normal(N)) * rate_scale
    columns["temp"] = temp if temp is not None else 30.0 + 0.01 * np.arange(N)
    columns.update(extra or {})
    if table is not None:
        columns["gx"] = columns["gx"] + table
    path = tmp_path / name
    names = list(columns)
    rows = np.column_stack([columns[k] for k in names])
    with open(path, "w") as out:
        out.write(",".join(names) + "\n")
        for row in rows:
            out.write(",".join(repr(float(v)) for v in row) + "\n")
    return path, columns


IMU_COLS = ["time_s=t", "rate_dph_x=gx", "rate_dph_y=gy", "rate_dph_z=gz", "temperature_c=temp"]


def test_parse_columns_accepts_per_axis_names():
    assert parse_columns(["freq_hz_x=f1,rate_dph_b2=w"]) == {"freq_hz_x": "f1",
                                                               "rate_dph_b2": "w"}
    with pytest.raises(InputError, match=r"'chamber_c_x' is not a recording column"):
        parse_columns(["chamber_c_x=c"])
    with pytest.raises(InputError, match="not a recording column"):
        parse_columns(["rate_dph_=w"])


def test_rad_per_s_microseconds_sensor_thermometer(tmp_path):
    path, raw = imu_csv(tmp_path, time_scale=1e6)
    options = ReadOptions(columns=parse_columns(IMU_COLS), units={"time": "us", "rate": "rad/s"},
                          thermometer="sensor")
    rec = options.read(path)
    assert axis_names(rec.names) == ("x", "y", "z")
    np.testing.assert_allclose(rec["time_s"], np.arange(N) / RATE_HZ, rtol=0, atol=1e-12)
    assert rec.metadata.sample_rate_hz == pytest.approx(RATE_HZ)
    factor = 180.0 / math.pi * 3600.0
    assert factor == pytest.approx(206264.80624709636, rel=1e-15)
    for axis in "xyz":
        np.testing.assert_allclose(rec[f"rate_dph_{axis}"], raw[f"g{axis}"] * factor, rtol=1e-15)
        # the shared temperature is every axis's thermometer, the same array (no copy)
        assert rec[f"freq_hz_{axis}"] is rec["temperature_c"]
    np.testing.assert_array_equal(rec["temperature_c"], raw["temp"])
    assert rec.metadata.extra["thermometer"] == "sensor"
    view = axis_view(rec, "y")
    np.testing.assert_array_equal(view.freq_hz, raw["temp"])


def test_rate_unit_converts_input_rate_columns_too(tmp_path):
    inputs = np.repeat([0.0, 10.0, -10.0, 0.0], N // 4)  # deg/s on the table
    path, raw = imu_csv(tmp_path, rate_scale=180.0 / math.pi, table=inputs,
                        extra={"table": inputs, "f": np.full(N, 4425.0)})
    cols = [*IMU_COLS, "input_rate_dph_x=table", "freq_hz_x=f", "freq_hz_y=f", "freq_hz_z=f"]
    rec = read(path, columns=cols, units={"rate": "dps"})
    np.testing.assert_array_equal(rec["input_rate_dph_x"], inputs * 3600.0)
    np.testing.assert_array_equal(rec["rate_dph_x"], raw["gx"] * 3600.0)
    view = axis_view(rec, "x")  # bias = rate - input rate, sample by sample
    np.testing.assert_allclose(view.measured_bias_dph, (raw["gx"] - inputs) * 3600.0,
                               rtol=0, atol=1e-9)
    assert abs(view.measured_bias_dph.mean() - 1e-5 * 180.0 / math.pi * 3600) < 0.1


def test_temperature_from_a_raw_count(tmp_path):
    counts = np.round(np.linspace(1200.0, 1800.0, N))  # e.g. a 1/16 °C per LSB sensor
    path, _ = imu_csv(tmp_path, temp=counts)
    cols = parse_columns(IMU_COLS)
    with pytest.raises(RecordingError, match=r"column 'temperature_c', row \d+: .*--temp-scale"):
        read(path, columns=cols, units={"rate": "radps"}, thermometer="sensor")
    rec = read(path, columns=cols, units={"rate": "radps"}, thermometer="sensor",
               temp_scale=0.0625, temp_offset_c=-40.0)
    np.testing.assert_array_equal(rec["temperature_c"], counts * 0.0625 - 40.0)
    assert rec["temperature_c"][0] == 35.0 and rec["temperature_c"][-1] == 72.5
    with pytest.raises(InputError, match="temp_scale must be a finite number"):
        read(path, columns=cols, units={"rate": "radps"}, temp_scale=0.0)


@pytest.mark.parametrize("spikes", ["error", "drop"])
def test_a_count_map_that_gives_impossible_temperatures_says_what_it_gave(tmp_path, spikes):
    """Issue 27: a scale and offset written for the unsigned count of a sensor whose count
    is unwrapped (65236 -> -300) gave -357 °C, and with --spikes drop a bare "the
    recording has no rows" (every row judged impossible before anything said why). The
    map's result is named, with the option that fixes it, before any check judges it."""
    unsigned = np.round(np.linspace(65236.0, 65000.0, N))  # -300 ... -536 signed
    path, _ = imu_csv(tmp_path, temp=unsigned)
    cols = parse_columns(IMU_COLS)
    scale, offset = 0.00586994, 24.2787 - 0.00586994 * 65536.0  # for the unsigned count
    with pytest.warns(UserWarning, match="signed 16-bit"), pytest.raises(RecordingError) as caught:
        read(path, columns=cols, units={"rate": "radps"}, thermometer="sensor",
             temp_scale=scale, temp_offset_c=offset, spikes=spikes)
    message = str(caught.value)
    assert message.startswith(f"{path}: column 'temp' (temperature_c): the count map ")
    assert "row 0: 65236 -> -362.2 °C" in message, message
    assert "read as it is, the map gives 21.83 °C" in message
    assert message.endswith("pass --temp-unwrap off")
    rec = read(path, columns=cols, units={"rate": "radps"}, thermometer="sensor",
               temp_scale=scale, temp_offset_c=offset, spikes=spikes, temp_unwrap="off")
    assert rec["temperature_c"][0] == pytest.approx(65236.0 * scale + offset)
    # the other way round: a map for the signed count, the count read as it is
    with pytest.raises(RecordingError, match=r"gives 676.2 °C .* the map gives 20.82 °C: "
                                             r"pass --temp-unwrap 16$"):
        read(path, columns=cols, units={"rate": "radps"}, thermometer="sensor",
             temp_scale=0.01, temp_offset_c=25.0, temp_unwrap="off", spikes=spikes)


def test_per_axis_temperatures_are_each_axis_thermometer(tmp_path):
    extra = {"tx": np.full(N, 20.0), "ty": np.full(N, 21.0), "tz": np.full(N, 22.0)}
    path, _ = imu_csv(tmp_path, extra=extra)
    cols = [*IMU_COLS[:4], "temperature_c_x=tx", "temperature_c_y=ty", "temperature_c_z=tz"]
    rec = read(path, columns=cols, units={"rate": "radps"}, thermometer="sensor")
    for axis, value in zip("xyz", (20.0, 21.0, 22.0), strict=True):
        assert np.all(rec[f"freq_hz_{axis}"] == value)
        assert np.all(axis_view(rec, axis).freq_hz == value)


def test_sensor_thermometer_without_temperature_column_is_an_error(tmp_path):
    path, _ = imu_csv(tmp_path)
    with pytest.raises(RecordingError, match=r"--thermometer sensor needs .*'temperature_c_x'"):
        read(path, columns=IMU_COLS[:4], units={"rate": "radps"}, thermometer="sensor")
    with pytest.raises(InputError, match="thermometer must be one of"):
        read(path, columns=IMU_COLS, thermometer="mems")


def test_without_the_sensor_option_a_frequency_column_is_required(tmp_path):
    path, _ = imu_csv(tmp_path)
    with pytest.raises(RecordingError, match=r"'freq_hz_x', 'freq_hz_y', 'freq_hz_z' missing"):
        read(path, columns=IMU_COLS, units={"rate": "radps"})


def test_bursts_in_a_multi_axis_file(tmp_path):
    path, _ = imu_csv(tmp_path)
    lines = path.read_text().splitlines()
    # a burst logger: 100 rows, a 20 s pause (longer than a dropout), the rest
    t = np.arange(N) / RATE_HZ + np.where(np.arange(N) >= 100, 20.0, 0.0)
    fixed = [lines[0]] + [",".join([repr(float(t[i])), *line.split(",")[1:]])
                          for i, line in enumerate(lines[1:])]
    path.write_text("\n".join(fixed) + "\n")
    options = dict(columns=IMU_COLS, units={"rate": "radps"}, thermometer="sensor",
                   metadata={"sample_rate_hz": RATE_HZ})
    with pytest.raises(RecordingError, match=r"column 'time_s', row 100: 1 gap"):
        read(path, **options)
    rec = read(path, gaps="split", **options)
    assert len(rec) == N and axis_names(rec.names) == ("x", "y", "z")
    chunks = list(ReadOptions(gaps="split", chunk_rows=64, columns=parse_columns(IMU_COLS),
                              units={"rate": "radps"}, thermometer="sensor",
                              metadata={"sample_rate_hz": RATE_HZ}).chunks(path))
    assert sum(len(c) for c in chunks) == N


def test_a_mapped_axis_column_without_its_rate_is_kept_as_it_is(tmp_path):
    path, raw = imu_csv(tmp_path, extra={"f": np.full(N, 4425.0)})
    rec = read(path, columns=["time_s=t", "freq_hz=f", "rate_dph=gx", "temperature_c_q=temp"],
               units={"rate": "dps"}, validate=False)
    assert axis_names(rec.names) == ()
    np.testing.assert_array_equal(rec["temperature_c_q"], raw["temp"])
