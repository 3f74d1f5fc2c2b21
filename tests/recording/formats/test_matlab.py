"""MATLAB .mat (hrgtc.recording.formats.matlab) on files MATLAB wrote, and round trips.

Truth: the values SciPy's ``test_mio.py`` states for its files written by MATLAB 7.4
(``testdouble = 0:pi/4:2*pi``; a 3×5 matrix with 1..5 in its first row and 1..3 in its
first column; a struct field ``[sqrt(2) exp(1) pi]``), the same row read from the v7.3
(HDF5) file where MATLAB stored it transposed; datenums from Python's proleptic Gregorian
ordinal (``date.toordinal() + 366`` is MATLAB's ``datenum``); round trips through
``scipy.io.savemat`` and h5py written in MATLAB's v7.3 layout.
"""

from __future__ import annotations

import math
from datetime import date

import h5py
import numpy as np
import pytest
from scipy.io import savemat

from hrgtc.core.errors import RecordingError, SlowChannelWarning
from hrgtc.recording import read
from hrgtc.recording.formats import format_for, open_streams

THETA = np.arange(0, 2 * np.pi + 1e-10, np.pi / 4)  # test_mio.py: theta


@pytest.mark.parametrize("name", ["testdouble_7.4_GLNX86.mat", "testhdf5_7.4_GLNX86.mat"])
def test_a_row_matlab_wrote_reads_as_scipy_states_it_v5_and_v73(data, name):
    rec = read(data / "matlab" / name, columns={"time_s": "testdouble"}, validate=False)
    np.testing.assert_allclose(rec["time_s"], THETA, rtol=0, atol=1e-15)


def test_the_v73_file_stores_the_row_transposed_and_is_read_back_as_a_row(data):
    path = data / "matlab" / "testhdf5_7.4_GLNX86.mat"
    with h5py.File(path, "r") as f:
        assert f["testdouble"].shape == (9, 1)  # MATLAB's 1×9, column-major
    assert format_for(path).name == "matlab"  # not hdf5: the MAT-file header decides


def test_a_v73_file_of_unknown_suffix_is_matlab_though_hdf5_knows_it_too(data, tmp_path):
    renamed = tmp_path / "run.dat"
    renamed.write_bytes((data / "matlab" / "testhdf5_7.4_GLNX86.mat").read_bytes())
    assert format_for(renamed).name == "matlab"
    renamed.write_bytes((data / "matlab" / "testdouble_7.4_GLNX86.mat").read_bytes())
    assert format_for(renamed).name == "matlab"


def test_a_matrix_becomes_numbered_columns(data):
    rec = read(data / "matlab" / "testmatrix_7.4_GLNX86.mat",
               columns={"time_s": "testmatrix_1"}, validate=False)
    np.testing.assert_array_equal(rec["time_s"], [1, 2, 3])
    for k in range(2, 6):
        np.testing.assert_array_equal(rec[f"testmatrix_{k}"], [k, 0, 0])


def test_a_struct_gives_its_numeric_fields_only(data):
    rec = read(data / "matlab" / "teststruct_7.4_GLNX86.mat",
               columns={"time_s": "doublefield"}, validate=False)
    np.testing.assert_allclose(rec["time_s"], [math.sqrt(2), math.e, math.pi], rtol=1e-15)
    assert set(rec.columns) == {"time_s"}  # the text and complex fields are no columns


def datenum(day: date, seconds: float) -> float:
    """MATLAB's datenum from Python's proleptic Gregorian ordinal (day 1 = 0001-01-01)."""
    return day.toordinal() + 366 + seconds / 86400.0


def test_datenum_times_become_seconds_with_their_date_kept(tmp_path):
    t = np.array([datenum(date(2020, 3, 7), 43200.0 + k) for k in range(100)])
    assert t[0] == 737857.5  # datenum(2020,3,7,12,0,0), MATLAB's documentation example
    rate = 9.7 + 0.01 * np.arange(100)
    savemat(tmp_path / "run.mat", {"log": {"t_datenum": t, "rate": rate, "temp": 20 + 0 * t}})
    rec = read(tmp_path / "run.mat", columns={"time_s": "t_datenum", "temperature_c": "temp"},
               thermometer="sensor", validate=False)
    np.testing.assert_allclose(rec["time_s"], np.arange(100.0), atol=2e-5)  # 1e-10 day ulps
    np.testing.assert_array_equal(rec["rate"], rate)  # unmapped: under its own name
    assert rec.metadata.extra["time_origin"].startswith("2020-03-07T12:00:00")
    savemat(tmp_path / "bad.mat", {"t_datenum": np.arange(5.0), "rate_dph": np.ones(5)})
    with pytest.raises(RecordingError, match=r"bad.mat: column 't_datenum' is named a datenum"):
        read(tmp_path / "bad.mat", validate=False)


def test_a_matrix_with_a_names_variable_and_a_scalar_rate(tmp_path):
    table = np.column_stack([np.arange(50) / 10.0, 4425.0 + np.arange(50), np.ones(50)])
    savemat(tmp_path / "m.mat", {"data": table, "data_names": ["time_s", "freq_hz", "rate_dph"],
                                 "fs": 10.0})
    rec = read(tmp_path / "m.mat", validate=False)
    np.testing.assert_array_equal(rec["freq_hz"], table[:, 1])
    assert rec.metadata.sample_rate_hz == 10.0 and "sample_rate_inferred" not in rec.metadata.extra


def savemat73(path, variables):
    """A v7.3 MAT-file as MATLAB writes one: HDF5 after a 512-byte header, arrays transposed."""
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, value in variables.items():
            if isinstance(value, list):  # a 1×k cell of char vectors
                refs = []
                for k, text in enumerate(value):
                    ds = f.create_dataset(f"#refs#/{name}{k}",
                                          data=np.array([[ord(c)] for c in text], np.uint16))
                    ds.attrs["MATLAB_class"] = np.bytes_("char")
                    refs.append(ds.ref)
                cell = f.create_dataset(name, data=np.array(refs, dtype=h5py.ref_dtype)[:, None])
                cell.attrs["MATLAB_class"] = np.bytes_("cell")
            else:
                array = np.asarray(value, dtype=np.float64)
                array = array[:, None] if array.ndim == 1 else array  # a column vector
                f.create_dataset(name, data=array.T).attrs["MATLAB_class"] = np.bytes_("double")
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: hrgtc test HDF5 schema 1.00 ."
    with open(path, "r+b") as f:
        f.write(header.ljust(116, b" ") + bytes(8) + b"\x00\x02" + b"IM")


def test_round_trip_of_a_v73_matrix_with_names_transposed_back(tmp_path):
    table = np.column_stack([np.arange(40) / 4.0, 9.7 + np.arange(40), 20.0 + np.arange(40)])
    savemat73(tmp_path / "v73.mat", {"m": table, "names": ["t", "omega", "temp"]})
    with h5py.File(tmp_path / "v73.mat", "r") as f:
        assert f["m"].shape == (3, 40)  # stored k×N
    rec = read(tmp_path / "v73.mat", columns={"time_s": "t", "rate_dph": "omega",
                                              "temperature_c": "temp"},
               thermometer="sensor", validate=False)
    for k, name in enumerate(["time_s", "rate_dph", "temperature_c"]):
        np.testing.assert_array_equal(rec[name], table[:, k])


def test_structs_at_two_rates_are_streams_on_request_aligned(tmp_path):
    t_fast, t_slow = np.arange(600) / 10.0, np.arange(61.0)
    savemat(tmp_path / "two.mat", {"gyro": {"t": t_fast, "rate": np.sin(t_fast)},
                                   "chamber": {"time": t_slow, "temp": 20 + t_slow / 60}})
    names = {s.stream for s in open_streams(tmp_path / "two.mat")}
    assert names == {"gyro", "chamber"}
    with pytest.warns(SlowChannelWarning, match="chamber.temp"):
        rec = read(tmp_path / "two.mat", columns={"rate_dph": "gyro.rate",
                                                  "temperature_c": "chamber.temp"},
                   thermometer="sensor", slow_channels="interpolate", validate=False)
    np.testing.assert_array_equal(rec["time_s"], t_fast)
    np.testing.assert_allclose(rec["temperature_c"], 20 + t_fast / 60, rtol=1e-12)


def test_a_file_of_tables_without_their_own_times_is_refused_naming_them(tmp_path):
    savemat(tmp_path / "x.mat", {"a": np.arange(10.0), "b": np.arange(20.0)})
    with pytest.raises(RecordingError, match=r"x\.mat: .*2 tables.*no time axis"):
        read(tmp_path / "x.mat")
