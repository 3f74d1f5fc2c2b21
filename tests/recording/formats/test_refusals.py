"""Cut, corrupt and empty files of every new format, a missing library, lazy imports.

Truth: each real sample cut in half, its first bytes kept and the rest overwritten, or
emptied: ``hrgtc info`` exits 2 with one message naming the file and what to do, never a
traceback or the library's own output; a flight log cut short (the DataFlash sample is
one, cut at 64 KiB) is read up to its last whole record, as PX4's and ArduPilot's tools
read it. A library that is not installed is named with the extra that installs it;
``hrgtc --help`` and reading a CSV import none of the libraries.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from hrgtc.core.errors import RecordingError
from hrgtc.recording import read

SAMPLES = {
    "tdms": "tdms/raw1.tdms",
    "matlab-v5": "matlab/testdouble_7.4_GLNX86.mat",
    "matlab-v73": "matlab/testhdf5_7.4_GLNX86.mat",
    "ulog": "ulog/sample_log_small.ulg",
    "dataflash": "dataflash/test.BIN",
    "mdf": "mdf/test_batch_cut_1.mf4",
}
#: The formats whose cut files are refused (flight logs are read up to the cut).
REFUSE_CUT = ("tdms", "matlab-v5", "matlab-v73", "mdf")
LIBRARIES = ("nptdms", "pyulog", "pymavlink", "asammdf")


def broken(data, tmp_path, key: str, how: str):
    original = (data / SAMPLES[key]).read_bytes()
    path = tmp_path / f"{how}-{(data / SAMPLES[key]).name}"
    if how == "cut":
        path.write_bytes(original[: len(original) // 2])
    elif how == "corrupt":  # the signature kept, the rest noise
        noise = np.random.default_rng(3).integers(0, 256, len(original) - 64, dtype=np.uint8)
        path.write_bytes(original[:64] + noise.tobytes())
    else:
        path.write_bytes(b"")
    return path


def assert_refused(path, run_info):
    code, _, output = run_info(path)
    assert code == 2, output
    assert f"error: {path}" in output.replace("\n", " ")
    for noise in ("Traceback", "Exception ignored", "WARNING]", "bad header", "Skipped"):
        assert noise not in output, output


@pytest.mark.parametrize("key", sorted(SAMPLES))
@pytest.mark.parametrize("how", ["corrupt", "empty"])
def test_corrupt_and_empty_files_are_refused_in_one_message(data, tmp_path, run_info, key,
                                                            how):
    assert_refused(broken(data, tmp_path, key, how), run_info)


@pytest.mark.parametrize("key", REFUSE_CUT)
def test_cut_files_of_bench_formats_are_refused_naming_the_fix(data, tmp_path, run_info, key):
    path = broken(data, tmp_path, key, "cut")
    assert_refused(path, run_info)
    with pytest.raises(RecordingError, match=r"truncated or corrupt.*(again|save)"):
        read(path, validate=False)


@pytest.mark.parametrize(("key", "columns"), [
    ("ulog", {"rate_dph": "sensor_combined.gyro_rad[2]"}),
    ("dataflash", {"rate_dph": "ATT.Roll"}),
])
def test_a_flight_log_cut_short_is_read_up_to_its_last_whole_record(data, tmp_path, key,
                                                                    columns):
    whole = read(data / SAMPLES[key], columns=columns, validate=False,
                 metadata={"sample_rate_hz": 1.0})
    cut = read(broken(data, tmp_path, key, "cut"), columns=columns, validate=False,
               metadata={"sample_rate_hz": 1.0})
    assert 0 < len(cut) < len(whole)
    np.testing.assert_array_equal(cut["rate_dph"], whole["rate_dph"][: len(cut)])


@pytest.mark.parametrize(("module", "extra", "key"), [
    ("nptdms", "tdms", "tdms"), ("pyulog", "px4", "ulog"),
    ("pymavlink.DFReader", "ardupilot", "dataflash"), ("asammdf", "mdf", "mdf")])
def test_a_missing_library_is_named_with_its_extra(data, monkeypatch, module, extra, key):
    monkeypatch.setitem(sys.modules, module, None)  # import raises ImportError
    with pytest.raises(RecordingError, match=rf"needs the Python package '{module}'.*"
                       rf"pip install 'hrgtc\[{extra}\]'"):
        read(data / SAMPLES[key])


def test_help_and_reading_a_csv_import_none_of_the_libraries(tmp_path):
    csv = tmp_path / "run.csv"
    csv.write_text("time_s,freq_hz,rate_dph\n" + "".join(
        f"{k / 10},4425.{k},9.7\n" for k in range(50)))
    code = (
        "import sys\n"
        "from typer.testing import CliRunner\n"
        "from hrgtc.cli import app\n"
        "assert CliRunner().invoke(app, ['--help']).exit_code == 0\n"
        "from hrgtc.recording import read\n"
        f"read({str(csv)!r})\n"
        f"print(sorted(m for m in {LIBRARIES!r} if m in sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120)
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize(("key", "example", "listed"), [
    ("ulog", "sensor_gyro_0.x", "sensor_gyro_1 (6 rows: "),
    ("dataflash", "IMU.GyrX", "IMU2 (45 rows: IMU2.GyrX"),
])
def test_a_log_read_without_a_mapping_lists_its_streams_and_an_example(data, run_info, key,
                                                                       example, listed):
    code, _, output = run_info(data / SAMPLES[key])
    text = " ".join(output.split())
    assert code == 2 and f"e.g. --col rate_dph={example}" in text and listed in text, output
