"""PX4 ULog (hrgtc.recording.formats.ulog) against pyulog's ulog2csv export of a real log.

Truth: ``tests/data/formats/ulog/ulog2csv/``, written by pyulog's ``ulog2csv`` from
pyulog's own sample log (its README says how): a different code path (text written from
the parsed topics) than hrgtc's reader, which takes the topic arrays; timestamps in µs,
gyro rates in rad/s.
"""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

from hrgtc.core.errors import RecordingError, SlowChannelWarning
from hrgtc.recording import read
from hrgtc.recording.formats import format_for, open_streams
from hrgtc.recording.formats.ulog import stream_names

LOG = "ulog/sample_log_small.ulg"
RAD_S_TO_DPH = 3600.0 * 180.0 / math.pi


def export(data, name: str) -> dict[str, np.ndarray]:
    with open(data / "ulog" / "ulog2csv" / f"sample_log_small_{name}.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def test_each_topic_instance_is_a_stream_named_as_the_brief_says(data):
    names = {s.stream for s in open_streams(data / LOG)}
    assert {"sensor_gyro_0", "sensor_gyro_1", "sensor_gyro_2", "sensor_combined"} <= names
    assert "sensor_gyro" not in names and "sensor_combined_0" not in names
    assert stream_names([("a", 0), ("a", 1), ("b", 0), ("c", 1)]) == ["a_0", "a_1", "b", "c_1"]


@pytest.mark.parametrize("instance", [0, 1, 2])
def test_a_gyro_instance_reads_as_ulog2csv_exported_it(data, instance):
    stream = f"sensor_gyro_{instance}"
    rec = read(data / LOG, columns={"rate_dph": f"{stream}.z",
                                    "temperature_c": f"{stream}.temperature"},
               units={"rate": "radps"}, thermometer="sensor", validate=False)
    truth = export(data, stream)
    np.testing.assert_array_equal(rec["time_s"], truth["timestamp"] * 1e-6)
    # ulog2csv prints float32 values with 8 significant digits
    np.testing.assert_allclose(rec["rate_dph"], truth["z"] * RAD_S_TO_DPH, rtol=1e-7)
    np.testing.assert_allclose(rec["temperature_c"], truth["temperature"], rtol=1e-7)
    assert len(rec) == 6  # ulog2csv: "6 data points"


def test_sensor_combined_has_ulog2csvs_count_first_and_last_rows(data):
    rec = read(data / LOG, columns={"rate_dph": "sensor_combined.gyro_rad[2]",
                                    "freq_hz": "sensor_combined.gyro_rad[0]"},
               units={"rate": "radps"}, validate=False)
    truth = export(data, "sensor_combined_0.head_tail")
    assert len(rec) == 1298  # ulog2csv: "1298 data points"
    for rows, truth_rows in ((slice(0, 5), slice(0, 5)), (slice(-5, None), slice(5, 10))):
        np.testing.assert_array_equal(rec["time_s"][rows], truth["timestamp"][truth_rows] * 1e-6)
        np.testing.assert_allclose(rec["rate_dph"][rows],
                                   truth["gyro_rad[2]"][truth_rows] * RAD_S_TO_DPH, rtol=1e-7)
        np.testing.assert_allclose(rec["freq_hz"][rows], truth["gyro_rad[0]"][truth_rows],
                                   rtol=1e-7)


def test_topics_at_other_rates_are_aligned_onto_the_mapped_fast_topic_and_said(data):
    # sensor_combined (~200 Hz) takes the 1 Hz temperature of sensor_gyro_0: held, reported
    with pytest.warns(SlowChannelWarning, match="sensor_gyro_0.temperature"):
        rec = read(data / LOG, columns={"rate_dph": "sensor_combined.gyro_rad[2]",
                                        "temperature_c": "sensor_gyro_0.temperature"},
                   units={"rate": "radps"}, thermometer="sensor", validate=False,
                   hold_max_s=1.5)
    gyro = export(data, "sensor_gyro_0")
    t, temp = gyro["timestamp"] * 1e-6, gyro["temperature"]
    assert np.all(np.diff(rec["time_s"]) > 0)
    held = temp[np.searchsorted(t, rec["time_s"], side="right") - 1]  # hold: the last value
    np.testing.assert_allclose(rec["temperature_c"], held, rtol=1e-7)
    assert rec["time_s"][0] >= t[0]  # rows before the first temperature are dropped


def test_slow_channels_error_refuses_two_topics_but_not_one(data):
    with pytest.raises(RecordingError, match=r"2 streams .*\(sensor_"):
        read(data / LOG, columns={"rate_dph": "sensor_combined.gyro_rad[2]",
                                  "temperature_c": "sensor_gyro_0.temperature"},
             thermometer="sensor", slow_channels="error", validate=False)
    rec = read(data / LOG, columns={"rate_dph": "sensor_gyro_0.z",
                                    "temperature_c": "sensor_gyro_0.temperature"},
               thermometer="sensor", slow_channels="error", validate=False)
    assert len(rec) == 6


def test_hrgtc_info_says_what_the_export_says(data, run_info):
    code, found, output = run_info(data / LOG, "--col", "rate_dph=sensor_gyro_1.x",
                                   "--col", "temperature_c=sensor_gyro_1.temperature",
                                   "--rate-unit", "radps", "--thermometer", "sensor")
    truth = export(data, "sensor_gyro_1")
    assert code == 0, output
    assert found["format"] == "ulog" and found["rows"] == 6
    columns = {c["name"]: c for c in found["columns"]}
    assert columns["time_s"]["min"] == pytest.approx(truth["timestamp"][0] * 1e-6, abs=1e-9)
    assert columns["temperature_c"]["max"] == pytest.approx(truth["temperature"].max(),
                                                            rel=1e-7)
    assert columns["rate_dph"]["min"] == pytest.approx(truth["x"].min() * RAD_S_TO_DPH, rel=1e-7)


def test_the_log_is_known_by_its_magic_under_another_suffix(data, tmp_path):
    renamed = tmp_path / "flight.log"
    renamed.write_bytes((data / LOG).read_bytes()[:4096])
    assert format_for(renamed).name == "ulog"


def test_the_sampling_time_in_us_is_a_column_the_time_options_take(data):
    rec = read(data / LOG, columns={"time_s": "sensor_gyro_2.timestamp_sample",
                                    "rate_dph": "sensor_gyro_2.y"},
               units={"time": "us", "rate": "radps"}, validate=False,
               metadata={"sample_rate_hz": 1.0})
    truth = export(data, "sensor_gyro_2")
    np.testing.assert_array_equal(rec["time_s"], truth["timestamp_sample"] / 1e6)
    np.testing.assert_allclose(rec["rate_dph"], truth["y"] * RAD_S_TO_DPH, rtol=1e-7)
