"""ASAM MDF4 (hrgtc.recording.formats.mdf) on asammdf's real samples, and round trips.

Truth: the raw records of the channel (``raw=True``, asammdf's lowest level) and the
1:1 conversion its conversion block states, the master channel, the measurement's start
in the header (CANape wrote 2018-11-22 15:26:35 +01:00); round trips through asammdf's
``MDF.append``.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import SlowChannelWarning
from hrgtc.recording import iter_chunks, read
from hrgtc.recording.formats import format_for, open_streams
from hrgtc.recording.formats.mdf import group_prefixes

asammdf = pytest.importorskip("asammdf")

CUT = "mdf/test_batch_cut_1.mf4"
TWO = "mdf/test_metadata.mf4"
SBYTE = "ASAM.M.SCALAR.SBYTE.IDENTICAL.DISCRETE"


def test_a_canape_group_reads_as_its_raw_records_times_its_conversion(data):
    rec = read(data / CUT, columns={"rate_dph": SBYTE}, validate=False)
    mdf = asammdf.MDF(data / CUT)
    try:
        raw = mdf.get(SBYTE, raw=True)
        conversion = mdf.groups[0].channels[1].conversion
        master = mdf.get_master(0)
    finally:
        mdf.close()
    assert raw.samples.dtype == np.int8 and len(rec) == len(raw.samples) == 32
    assert conversion.conversion_type == 0  # MDF4 cc_type 0: 1:1, physical = raw
    np.testing.assert_array_equal(rec["rate_dph"], raw.samples.astype(float))
    np.testing.assert_array_equal(rec["time_s"], master)
    assert rec.metadata.extra["time_origin"].startswith("2018-11-22T14:26:35.4397")  # UTC
    assert rec.metadata.extra["mdf_units"][SBYTE] == "hours"


def test_two_groups_are_named_by_their_acquisition_names_text_channels_are_not_numbers(data):
    streams = open_streams(data / TWO)
    try:
        assert [s.stream for s in streams] == ["100ms_sync", "Engine_1"]
        kinds = streams[1].kinds()
        assert kinds["Engine_1/ASAM.M.SCALAR.UBYTE.VTAB_RANGE_NO_DEFAULT_VALUE"] == "string"
        assert kinds["Engine_1/ASAM.M.SCALAR.UBYTE.TAB_INTP_DEFAULT_VALUE"] == "numeric"
    finally:
        for stream in streams:
            stream.close()
    rec = read(data / TWO, validate=False, metadata={"sample_rate_hz": 1.0},
               columns={"rate_dph": "Engine_1/ASAM.M.SCALAR.UBYTE.TAB_INTP_DEFAULT_VALUE"})
    np.testing.assert_array_equal(rec["time_s"], [0.0, 1.0])
    np.testing.assert_array_equal(rec["rate_dph"], [111.0, 111.0])
    assert group_prefixes(["a", "a", "b", ""]) == ["0/", "1/", "b/", "3/"]
    assert group_prefixes(["only"]) == [""]


def write_mdf(path, rate, temp):
    from asammdf import MDF, Signal

    with MDF(version="4.10") as mdf:
        mdf.append([Signal(rate[1], rate[0], name="GyroZ", unit="deg/h")], acq_name="fast")
        mdf.append([Signal(temp[1], temp[0], name="Temp", unit="degC")], acq_name="slow")
        mdf.save(path, overwrite=True)


def test_round_trip_of_two_rates_through_mdf_append(tmp_path):
    path = tmp_path / "bench.mf4"
    t_fast = np.arange(2000) * 0.01
    rate = 9.7 + np.sin(t_fast)
    t_slow = np.arange(21) * 1.0
    temp = 20.0 + 0.1 * t_slow
    write_mdf(path, (t_fast, rate), (t_slow, temp))
    with pytest.warns(SlowChannelWarning, match="slow/Temp"):
        rec = read(path, columns={"rate_dph": "fast/GyroZ", "temperature_c": "slow/Temp"},
                   thermometer="sensor", slow_channels="interpolate", validate=False)
    np.testing.assert_array_equal(rec["time_s"], t_fast)
    np.testing.assert_array_equal(rec["rate_dph"], rate)
    np.testing.assert_allclose(rec["temperature_c"], np.interp(t_fast, t_slow, temp),
                               rtol=1e-12)
    parts = list(iter_chunks(path, columns={"rate_dph": "fast/GyroZ"}, chunk_rows=700,
                             validate=False))
    assert [len(p) for p in parts] == [700, 700, 600]
    np.testing.assert_array_equal(np.concatenate([p["rate_dph"] for p in parts]), rate)


def test_hrgtc_info_on_the_canape_cut(data, run_info):
    code, found, output = run_info(data / CUT, "--spike-filter", "off", "--col",
                                   f"rate_dph={SBYTE}", "--col", f"temperature_c={SBYTE}",
                                   "--thermometer", "sensor")
    assert found is not None and found["format"] == "mdf" and found["rows"] == 32, output
    columns = {c["name"]: c for c in found["columns"]}
    assert (columns["rate_dph"]["min"], columns["rate_dph"]["max"]) == (-128.0, 118.0)
    assert code == 0
    assert found["sample_rate_hz"] == pytest.approx(10.0)  # the 100 ms raster


def test_the_file_is_known_by_its_identification_block_under_another_suffix(data, tmp_path):
    renamed = tmp_path / "run.dat"
    renamed.write_bytes((data / CUT).read_bytes())
    assert format_for(renamed).name == "mdf"
