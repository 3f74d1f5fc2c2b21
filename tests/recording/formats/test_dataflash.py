"""ArduPilot DataFlash (hrgtc.recording.formats.dataflash) against the dump pymavlink ships.

Truth: ``tests/data/formats/dataflash/test.BIN.py3.dumped.IMU``, the ``IMU`` and ``IMU2``
lines of the ``mavlogdump.py`` output committed in pymavlink's repository beside its
``test.BIN`` (2019): ``TimeUS`` in µs, ``GyrX/GyrY/GyrZ`` in rad/s, ``T`` in °C.
"""

from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from hrgtc.core.errors import HrgtcWarning, SlowChannelWarning
from hrgtc.recording import read
from hrgtc.recording.formats import format_for, open_streams
from hrgtc.recording.formats.dataflash import stream_name

LOG = "dataflash/test.BIN"
RAD_S_TO_DPH = 3600.0 * 180.0 / math.pi


def dump(data, message: str) -> dict[str, np.ndarray]:
    rows = []
    for line in (data / "dataflash" / "test.BIN.py3.dumped.IMU").read_text().splitlines():
        found = re.search(r": (\w+) \{(.*)\}$", line)
        if found and found.group(1) == message:
            rows.append(dict(pair.split(" : ") for pair in found.group(2).split(", ")))
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def test_message_types_are_streams_and_instances_are_named_as_ardupilot_does(data):
    names = {s.stream for s in open_streams(data / LOG)}
    assert {"IMU", "IMU2", "ATT", "BARO"} <= names and "FMT" not in names
    fmt = SimpleNamespace(instance_field="I")
    assert stream_name(SimpleNamespace(get_type=lambda: "IMU", fmt=fmt, I=1)) == "IMU[1]"
    plain = SimpleNamespace(get_type=lambda: "IMU", fmt=SimpleNamespace(instance_field=None))
    assert stream_name(plain) == "IMU"


@pytest.mark.parametrize("message", ["IMU", "IMU2"])
def test_the_imus_read_as_mavlogdump_dumped_them(data, message):
    rec = read(data / LOG, columns={"rate_dph": f"{message}.GyrZ", "freq_hz": f"{message}.GyrX",
                                    "temperature_c": f"{message}.T"},
               units={"rate": "radps"}, validate=False)
    truth = dump(data, message)
    assert len(rec) == len(truth["TimeUS"]) == 45
    np.testing.assert_array_equal(rec["time_s"], truth["TimeUS"] * 1e-6)
    np.testing.assert_allclose(rec["rate_dph"], truth["GyrZ"] * RAD_S_TO_DPH, rtol=1e-15)
    np.testing.assert_array_equal(rec["freq_hz"], truth["GyrX"])  # unmapped unit: as logged
    np.testing.assert_array_equal(rec["temperature_c"], truth["T"])


def test_imu2_temperature_on_imu_time_axis_is_aligned_and_said(data):
    with pytest.warns(SlowChannelWarning):
        rec = read(data / LOG, columns={"rate_dph": "IMU.GyrZ", "temperature_c": "IMU2.T"},
                   units={"rate": "radps"}, thermometer="sensor", validate=False,
                   slow_channels="interpolate", hold_max_s=0.2)
    imu2 = dump(data, "IMU2")
    expected = np.interp(rec["time_s"], imu2["TimeUS"] * 1e-6, imu2["T"])
    np.testing.assert_allclose(rec["temperature_c"], expected, rtol=1e-12)


def test_hrgtc_info_says_what_the_dump_says(data, run_info):
    code, found, output = run_info(data / LOG, "--spike-filter", "off", "--col",
                                   "rate_dph=IMU.GyrZ", "--col", "temperature_c=IMU.T",
                                   "--rate-unit", "radps", "--thermometer", "sensor")
    truth = dump(data, "IMU")
    assert code == 0, output
    assert found["format"] == "dataflash" and found["rows"] == 45
    columns = {c["name"]: c for c in found["columns"]}
    assert columns["time_s"]["max"] == pytest.approx(truth["TimeUS"][-1] * 1e-6, abs=1e-12)
    assert columns["temperature_c"]["min"] == pytest.approx(truth["T"].min(), rel=1e-15)
    assert found["metadata"]["extra"]["firmware"] == "ArduPlane V3.8.2-dev (8178ab40)"
    # the sample is a log cut at 64 KiB: read to its last whole message, the rest counted
    assert found["metadata"]["extra"]["dataflash_trailing_bytes"] == 21


def test_the_log_is_known_by_its_first_message_under_another_suffix(data, tmp_path):
    renamed = tmp_path / "00000042.dat"
    renamed.write_bytes((data / LOG).read_bytes())
    assert format_for(renamed).name == "dataflash"


def test_a_log_cut_inside_a_message_is_read_to_its_last_whole_one_and_said(data):
    with pytest.warns(HrgtcWarning, match=r"test\.BIN: the log ends inside a message \(21 byte"):
        streams = open_streams(data / LOG)
    assert "IMU" in {s.stream for s in streams}
