"""NI TDMS (hrgtc.recording.formats.tdms) on npTDMS's real sample files, and round trips.

Truth: the values npTDMS's own tests publish for its sample files
(``test_example_files.py``: the first scaled values of ``raw1.tdms``, the first values of
LabVIEW's ``Digital_Input.tdms``), the DAQmx raw counts times the scale the file states
(read with ``scaled=False``, npTDMS's lowest level), the waveform properties of the file;
round trips through npTDMS's ``TdmsWriter``.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import RecordingError, SlowChannelWarning
from hrgtc.recording import iter_chunks, read
from hrgtc.recording.formats import format_for, open_streams

nptdms = pytest.importorskip("nptdms")

RAW = "tdms/raw1.tdms"
LABVIEW = "tdms/Digital_Input.tdms"
ALL = "07/09/2012 06:58:23 PM - Digital Input - All Data"
LEVEL1 = "07/09/2012 06:58:23 PM - Digital Input - Decimated Data_Level1"
LINE = "Dev1_port3_line7 - line 0"
# npTDMS's test_example_files.py::test_raw_format
FIRST_TEN = [-0.18402661, 0.14801477, -0.24506363, -0.29725028, -0.20020142, 0.18158513,
             0.02380444, 0.20661031, 0.20447401, 0.2517777]


def test_daqmx_raw_data_reads_scaled_on_its_waveform_time_axis(data):
    rec = read(data / RAW, columns={"rate_dph": "First  Channel", "freq_hz": "Second Chan"},
               validate=False)
    np.testing.assert_allclose(rec["rate_dph"][:10], FIRST_TEN, atol=5e-9)
    with nptdms.TdmsFile.open(data / RAW) as tdms:  # the lowest level: counts and the scale
        channel = tdms["Layer Data"]["First  Channel"]
        raw = next(iter(channel.read_data(scaled=False).values()))
        slope = channel.properties["NI_Scale[1]_Linear_Slope"]
        increment = channel.properties["wf_increment"]
    assert raw.dtype == np.int16
    np.testing.assert_allclose(rec["rate_dph"], raw * slope, rtol=1e-12)
    np.testing.assert_array_equal(rec["time_s"], np.arange(2000) * increment)
    assert rec.metadata.sample_rate_hz == pytest.approx(50_000.0)
    assert rec.metadata.extra["time_origin"] == "2016-12-15T22:35:21.000000"
    assert rec.metadata.extra["tdms_units"]["First  Channel"] == "Volts"
    assert "Seventh Cha" in rec.columns  # unmapped channels keep their names


def test_labview_groups_at_three_rates_are_streams_aligned_on_the_mapped_one(data):
    streams = open_streams(data / LABVIEW)
    assert [s.count_rows() for s in streams] == [20000, 400, 8]
    assert all(s.on_request for s in streams)
    for stream in streams:
        stream.close()
    with pytest.warns(SlowChannelWarning, match="Level1"):
        rec = read(data / LABVIEW, columns={"rate_dph": f"{ALL}/{LINE}",
                                            "freq_hz": f"{LEVEL1}/{LINE}"}, validate=False)
    assert len(rec) == 20000 and rec["time_s"][1] == pytest.approx(0.0005)
    with nptdms.TdmsFile.open(data / LABVIEW) as tdms:
        level1 = tdms[LEVEL1][LINE].read_data()
    # npTDMS's test_labview_file: the first ten values of the level-1 group
    np.testing.assert_array_equal(level1[:10], [0, 1, 0, 1, 0, 1, 0, 1, 0, 1])
    # hold: the last level-1 value at or before each row (both groups start together)
    held = level1[np.searchsorted(np.arange(400) * 0.025, rec["time_s"], side="right") - 1]
    np.testing.assert_array_equal(rec["freq_hz"], held)


def test_one_group_asked_for_is_read_alone_without_resampling(data):
    rec = read(data / LABVIEW, columns={"rate_dph": f"{LEVEL1}/{LINE}"}, validate=False,
               slow_channels="error")
    assert len(rec) == 400
    np.testing.assert_allclose(np.diff(rec["time_s"]), 0.025, rtol=1e-9)
    with pytest.raises(RecordingError, match="streams on their own time axes"):
        read(data / LABVIEW, columns={"rate_dph": f"{ALL}/{LINE}", "freq_hz": f"{LEVEL1}/{LINE}"},
             validate=False, slow_channels="error")


def test_hrgtc_info_on_the_daqmx_file(data, run_info):
    code, found, output = run_info(data / RAW, "--spike-filter", "off", "--col",
                                   "rate_dph=First  Channel", "--col",
                                   "temperature_c=Second Chan", "--thermometer", "sensor",
                                   "--rate-unit", "dps")
    assert code == 0, output
    assert found["format"] == "tdms" and found["rows"] == 2000
    assert found["sample_rate_hz"] == pytest.approx(50_000.0)
    columns = {c["name"]: c for c in found["columns"]}
    assert columns["time_s"]["max"] == pytest.approx(1999 * 2e-5)


def write_tdms(path, groups):
    """npTDMS's writer: groups of (name, start, increment, {channel: (values, properties)})."""
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    with TdmsWriter(path) as writer:
        objects = [RootObject({"name": "bench"})]
        for group, start, increment, channels in groups:
            objects.append(GroupObject(group))
            for name, (values, props) in channels.items():
                objects.append(ChannelObject(group, name, values, properties={
                    "wf_start_time": np.datetime64(start, "us"), "wf_increment": increment,
                    "wf_start_offset": 0.0, "wf_samples": len(values), **props}))
        writer.write_segment(objects)


def test_round_trip_scaling_and_two_rates_through_tdmswriter(tmp_path):
    path = tmp_path / "bench.tdms"
    counts = np.arange(-500, 500, dtype=np.int16) * 7
    scale = {"NI_Scaling_Status": "unscaled", "NI_Number_Of_Scales": 1,
             "NI_Scale[0]_Scale_Type": "Linear", "NI_Scale[0]_Linear_Slope": 0.25,
             "NI_Scale[0]_Linear_Y_Intercept": 3.0, "unit_string": "deg/h"}
    temp = 20.0 + 0.01 * np.arange(11)
    write_tdms(path, [("gyro", "2024-05-01T10:00:00", 0.01, {"rate": (counts, scale)}),
                      ("chamber", "2024-05-01T10:00:00.5", 1.0, {"temp": (temp, {})})])
    with pytest.warns(SlowChannelWarning):
        rec = read(path, columns={"rate_dph": "gyro/rate", "temperature_c": "chamber/temp"},
                   thermometer="sensor", validate=False, slow_channels="interpolate")
    # rows before the first temperature (0.5 s later) are a gap of that channel: dropped
    kept = np.arange(1000)[np.arange(1000) * 0.01 >= 0.5 - 1e-12]
    np.testing.assert_allclose(rec["rate_dph"], counts[kept] * 0.25 + 3.0, rtol=1e-15)
    np.testing.assert_allclose(rec["time_s"], kept * 0.01, rtol=1e-12)
    np.testing.assert_allclose(rec["temperature_c"],
                               np.interp(rec["time_s"], 0.5 + np.arange(11), temp), rtol=1e-12)
    assert rec.metadata.extra["time_origin"] == "2024-05-01T10:00:00.000000"


def test_batches_give_what_one_read_gives(data):
    whole = read(data / RAW, columns={"rate_dph": "First  Channel"}, validate=False)
    parts = list(iter_chunks(data / RAW, columns={"rate_dph": "First  Channel"}, chunk_rows=300,
                             validate=False))
    assert [len(p) for p in parts][:2] == [300, 300]
    np.testing.assert_array_equal(np.concatenate([p["rate_dph"] for p in parts]),
                                  whole["rate_dph"])


def test_the_file_is_known_by_its_lead_in_under_another_suffix(data, tmp_path):
    renamed = tmp_path / "run.dat"
    renamed.write_bytes((data / RAW).read_bytes())
    assert format_for(renamed).name == "tdms"
