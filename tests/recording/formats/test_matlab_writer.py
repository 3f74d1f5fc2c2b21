"""Writing MATLAB v5 files (``hrgtc simulate --format mat``): a simulated run written in
chunks reads back bit for bit, with hrgtc and with ``scipy.io.loadmat`` alone.

Truth: the simulator's own arrays (``simulate_run``, the same seed); scipy's reading of
the file (its variables, their MATLAB class and shape), which is not hrgtc's reader.
"""

from __future__ import annotations

import json
import re
import sys

import numpy as np
import pytest

from hrgtc import simulate
from hrgtc.core.errors import RecordingError
from hrgtc.recording import Metadata, RecordingWriter, read
from hrgtc.recording.formats import matlab

scipy_io = pytest.importorskip("scipy.io")

RATE_HZ = 10.0
PROFILE = simulate.cooldown(20.0, 10.0, 0.2)  # 7200 rows


@pytest.fixture(scope="module")
def run(tmp_path_factory, simulated_file):
    """(path, the simulator's recording): written in chunks of 1000 rows."""
    return simulated_file(tmp_path_factory.mktemp("mat"), "cool.mat", PROFILE, 5, RATE_HZ)


def test_hrgtc_reads_back_the_simulators_arrays_and_metadata(run, check_read_back):
    check_read_back(*run, PROFILE, 5)


def test_scipy_loads_column_vectors_and_the_metadata_struct(run):
    path, truth = run
    n = len(truth)
    assert scipy_io.whosmat(str(path)) == [("hrgtc_metadata", (1, 1), "struct")] + [
        (name, (n, 1), "double") for name in truth.names]
    found = scipy_io.loadmat(str(path), simplify_cells=True)
    assert found["__header__"].startswith(b"MATLAB 5.0 MAT-file")
    for name in truth.names:
        assert found[name].dtype == np.float64
        assert np.array_equal(found[name], truth[name]), name
    struct = found["hrgtc_metadata"]
    expected = truth.metadata
    assert struct["sample_rate_hz"] == RATE_HZ and struct["unit"] == expected.unit
    assert struct["profile"] == expected.profile
    assert struct["input_rate_dph"] == expected.input_rate_dph
    assert json.loads(struct["extra_json"]) == expected.extra


def test_metadata_set_at_the_end_and_text_of_any_script(tmp_path):
    path = tmp_path / "late.mat"
    first = Metadata(sample_rate_hz=5.0, unit="SN 12 «α»")
    last = Metadata(sample_rate_hz=5.0, unit="SN 12 «α»", profile="",
                    extra={"restarts_s": [12.5], "note": None})
    with RecordingWriter(path, first, ["time_s", "freq_hz", "rate_dph"]) as out:
        out.write({"time_s": np.arange(3) / 5.0, "freq_hz": np.full(3, 4425.0),
                   "rate_dph": np.ones(3)})
        out.set_metadata(last)
    assert read(path).metadata == last


def test_a_column_that_is_not_a_matlab_name_is_refused(tmp_path):
    with pytest.raises(RecordingError, match=rf"^{re.escape(str(tmp_path / 'x.mat'))}: column\(s\) "
                       r"\['2nd_rate'\] cannot be MATLAB variable names"):
        RecordingWriter(tmp_path / "x.mat", Metadata(sample_rate_hz=1.0), ["time_s", "2nd_rate"])
    assert list(tmp_path.iterdir()) == []


def test_more_than_a_v5_variable_holds_is_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(matlab, "V5_VARIABLE_BYTES", 8 * 100)
    with pytest.raises(RecordingError, match=r"at most 2\^31 bytes.*write \.h5 or \.parquet"):
        with RecordingWriter(tmp_path / "x.mat", Metadata(sample_rate_hz=1.0),
                             ["rate_dph"]) as out:
            out.write({"rate_dph": np.ones(60)})
            out.write({"rate_dph": np.ones(60)})
    assert list(tmp_path.iterdir()) == []


def test_writing_without_scipy_names_the_extra(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "scipy.io", None)  # import raises ImportError
    target = re.escape(str(tmp_path / "x.mat"))
    with pytest.raises(RecordingError, match=rf"^{target}: writing MATLAB files "
                       r"needs the Python package "
                       r"'scipy.io'.*pip install 'hrgtc\[matlab\]'"):
        RecordingWriter(tmp_path / "x.mat", Metadata(sample_rate_hz=1.0), ["rate_dph"])
