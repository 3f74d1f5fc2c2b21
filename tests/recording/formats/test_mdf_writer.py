"""Writing MDF4 files (``hrgtc simulate --format mf4``): a simulated run written in chunks
reads back bit for bit, with hrgtc and with asammdf alone.

Truth: the simulator's own arrays (``simulate_run``, the same seed); asammdf's reading of
the file (its channels, master, units and header comment), which is not hrgtc's reader.
"""

from __future__ import annotations

import json
import re
import sys
import xml.etree.ElementTree as ElementTree

import numpy as np
import pytest

from hrgtc import simulate
from hrgtc.core.errors import RecordingError
from hrgtc.recording import Metadata, RecordingWriter, read

asammdf = pytest.importorskip("asammdf")

RATE_HZ = 10.0
PROFILE = simulate.warmup(-10.0, 0.0, 0.2)  # 7200 rows


@pytest.fixture(scope="module")
def run(tmp_path_factory, simulated_file):
    """(path, the simulator's recording): written in chunks of 1000 rows."""
    return simulated_file(tmp_path_factory.mktemp("mdf"), "warm.mf4", PROFILE, 7, RATE_HZ)


def test_hrgtc_reads_back_the_simulators_arrays_and_metadata(run, check_read_back):
    check_read_back(*run, PROFILE, 7)


def test_asammdf_reads_the_same_channels_on_the_time_master(run):
    path, truth = run
    with asammdf.MDF(str(path)) as mdf:
        assert mdf.version == "4.10"
        (group,) = mdf.groups
        assert group.channel_group.acq_name == "recording"
        names = [c.name for c in group.channels]
        assert names == ["time", *truth.names[1:]]
        for name in truth.names[1:]:
            signal = mdf.get(name)
            assert signal.samples.dtype == np.float64
            assert np.array_equal(signal.samples, truth[name]), name
            assert np.array_equal(signal.timestamps, truth["time_s"]), name
        assert mdf.get("rate_dph").unit == "deg/h" and mdf.get("housing_c").unit == "degC"
        comment = ElementTree.fromstring(mdf.header.comment)
    assert comment.findtext("TX") == truth.metadata.profile
    stored = comment.find("common_properties/e[@name='hrgtc']").text
    assert json.loads(stored) == truth.metadata.to_dict()


def test_metadata_set_at_the_end_and_a_clock_origin(tmp_path):
    path = tmp_path / "late.mf4"
    first = Metadata(sample_rate_hz=5.0, unit="A <&> B")
    last = Metadata(sample_rate_hz=5.0, unit="A <&> B", profile="soak <10 C> & more",
                    extra={"time_origin": "2024-05-01T10:00:00.000000", "restarts_s": [1.5]})
    with RecordingWriter(path, first, ["time_s", "freq_hz", "rate_dph"]) as out:
        out.write({"time_s": np.arange(10) / 5.0, "freq_hz": np.full(10, 4425.0),
                   "rate_dph": np.ones(10)})
        out.set_metadata(last)
    assert read(path).metadata == last
    with asammdf.MDF(str(path)) as mdf:
        assert mdf.header.start_time.isoformat().startswith("2024-05-01T10:00:00")


def test_writing_without_asammdf_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "asammdf", None)  # import raises ImportError
    target = re.escape(str(tmp_path / "x.mf4"))
    with pytest.raises(RecordingError, match=rf"^{target}: writing MDF files "
                       r"needs the Python package "
                       r"'asammdf'.*pip install 'hrgtc\[mdf\]'"):
        RecordingWriter(tmp_path / "x.mf4", Metadata(sample_rate_hz=1.0), ["rate_dph"])
    assert list(tmp_path.iterdir()) == []
