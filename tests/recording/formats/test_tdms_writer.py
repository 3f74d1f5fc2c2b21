"""Writing TDMS files (``hrgtc simulate --format tdms``): a simulated run written in
segments reads back bit for bit, with hrgtc and with npTDMS alone.

Truth: the simulator's own arrays (``simulate_run``, the same seed); npTDMS's reading of
the file (its channels, properties and ``time_track()``), which is not hrgtc's reader.
"""

from __future__ import annotations

import json
import re
import sys

import numpy as np
import pytest

from hrgtc import simulate
from hrgtc.core.errors import RecordingError, SlowChannelWarning
from hrgtc.recording import Metadata, RecordingWriter, read

nptdms = pytest.importorskip("nptdms")

RATE_HZ = 10.0
PROFILE = simulate.soak(-10.0, 0.2)  # 7200 rows


@pytest.fixture(scope="module")
def run(tmp_path_factory, simulated_file):
    """(path, the simulator's recording): written in chunks of 1000 rows (8 segments)."""
    return simulated_file(tmp_path_factory.mktemp("tdms"), "soak.tdms", PROFILE, 3, RATE_HZ)


def test_hrgtc_reads_back_the_simulators_arrays_and_metadata(run, check_read_back):
    back = check_read_back(*run, PROFILE, 3)
    assert back.metadata.profile == "soak -10 C, 0.2 h from 20 C"


def test_nptdms_reads_the_same_channels_with_labviews_waveform_properties(run):
    path, truth = run
    with nptdms.TdmsFile.open(str(path)) as tdms:
        (group,) = tdms.groups()
        assert group.name == "recording"
        assert [c.name for c in group.channels()] == list(truth.names)
        for channel in group.channels():
            values = channel[:]
            assert values.dtype == np.float64
            assert np.array_equal(values, truth[channel.name]), channel.name
        rate = group["rate_dph"]
        props = rate.properties
        assert props["wf_increment"] == 1.0 / RATE_HZ
        assert props["wf_start_offset"] == 0.0
        # a relative time axis: LabVIEW's zero time (1904-01-01)
        assert np.datetime64(props["wf_start_time"], "us") == np.datetime64("1904-01-01", "us")
        assert props["unit_string"] == "deg/h"
        assert group["freq_hz"].properties["unit_string"] == "Hz"
        # npTDMS's waveform time (offset + i * increment) is the simulator's i / fs to 2 ulp
        np.testing.assert_array_max_ulp(rate.time_track(), truth["time_s"], maxulp=2)
        assert json.loads(tdms.properties["hrgtc"]) == truth.metadata.to_dict()


def test_without_a_time_column_the_time_is_the_waveform_timing(tmp_path):
    """hrgtc's waveform-timing path: no ``time_s`` channel, a clock origin in the metadata."""
    n, rate_hz = 500, 50.0
    values = np.random.default_rng(1).standard_normal(n)
    freq = 4425.0 + values / 100.0
    metadata = Metadata(sample_rate_hz=rate_hz, unit="SN 1",
                        extra={"time_origin": "2024-05-01T10:00:00.000000"})
    path = tmp_path / "wave.tdms"
    with RecordingWriter(path, metadata, ["freq_hz", "rate_dph"]) as out:
        out.write({"freq_hz": freq[:200], "rate_dph": values[:200]})
        out.write({"freq_hz": freq[200:], "rate_dph": values[200:]})
    with nptdms.TdmsFile.open(str(path)) as tdms:
        channel = tdms["recording"]["rate_dph"]
        expected_time = channel.time_track()  # npTDMS: wf_start_offset + i * wf_increment
        start = np.datetime64(channel.properties["wf_start_time"], "us")
    assert start == np.datetime64("2024-05-01T10:00:00", "us")
    back = read(path)
    assert back.names == ("time_s", "freq_hz", "rate_dph")
    assert np.array_equal(back["time_s"], expected_time)
    assert np.array_equal(back["rate_dph"], values) and np.array_equal(back["freq_hz"], freq)
    assert back.metadata.sample_rate_hz == rate_hz
    assert back.metadata == metadata


def test_metadata_set_at_the_end_replaces_the_first(tmp_path):
    path = tmp_path / "late.tdms"
    first = Metadata(sample_rate_hz=5.0, unit="A")
    last = Metadata(sample_rate_hz=5.0, unit="A", extra={"restarts_s": [12.5]})
    with RecordingWriter(path, first, ["time_s", "freq_hz", "rate_dph"]) as out:
        out.write({"time_s": np.arange(10) / 5.0, "freq_hz": np.full(10, 4425.0),
                   "rate_dph": np.ones(10)})
        out.set_metadata(last)
    assert read(path).metadata == last


def test_writing_without_nptdms_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "nptdms", None)  # import raises ImportError
    target = re.escape(str(tmp_path / "x.tdms"))
    with pytest.raises(RecordingError, match=rf"^{target}: writing TDMS files "
                       r"needs the Python package "
                       r"'nptdms'.*pip install 'hrgtc\[tdms\]'"):
        RecordingWriter(tmp_path / "x.tdms", Metadata(sample_rate_hz=1.0), ["rate_dph"])
    assert list(tmp_path.iterdir()) == []  # no temporary file left behind


def test_in_a_file_of_several_groups_time_s_is_each_groups_waveform_timing(tmp_path):
    """Only a file of one group is read on a ``time_s`` channel; groups of a file of several
    keep their waveform timing (a channel ``time_s`` stays one of their columns)."""
    path = tmp_path / "two.tdms"
    fast = {"wf_increment": 0.1, "wf_start_offset": 0.0}
    slow = {"wf_increment": 1.0, "wf_start_offset": 0.0}
    with nptdms.TdmsWriter(str(path)) as out:
        out.write_segment([
            nptdms.ChannelObject("fast", "rate", np.arange(50.0), properties=fast),
            nptdms.ChannelObject("fast", "time_s", 100.0 + np.arange(50.0), properties=fast),
            nptdms.ChannelObject("slow", "temp", 20.0 + np.arange(5.0), properties=slow)])
    with pytest.warns(SlowChannelWarning, match="'slow/temp' is logged every 1 s"):
        back = read(path, columns={"freq_hz": "fast/rate", "rate_dph": "fast/time_s",
                                   "temperature_c": "slow/temp"}, thermometer="sensor")
    assert np.array_equal(back["time_s"], np.arange(50) * 0.1)
    assert np.array_equal(back["rate_dph"], 100.0 + np.arange(50.0))


@pytest.mark.parametrize(("stored", "said"), [("{not json", "is not valid JSON"),
                                              ("[1, 2]", "is not a JSON object")])
def test_a_damaged_metadata_property_is_named_with_what_is_wrong(tmp_path, stored, said):
    """The file property ``hrgtc`` that is not a JSON object is refused naming the file,
    the property and the fault."""
    path = tmp_path / "damaged.tdms"
    channel = nptdms.ChannelObject("recording", "time_s", np.arange(5.0))
    with nptdms.TdmsWriter(str(path)) as writer:
        writer.write_segment([nptdms.RootObject(properties={"hrgtc": stored}), channel])
    with pytest.raises(RecordingError, match=re.escape(
            f"{path}: the file property 'hrgtc' (hrgtc's metadata) {said}")):
        read(path)
