"""``hrgtc compensate`` and ``hrgtc evaluate``: no silent wrong output (issue 11).

One test (or a parametrised set) per item of the issue's list of what went wrong:
implausible values, rate units at any sample rate, --gaps, trusted model files,
compensation applied twice, tracebacks, temporary files left behind. Truth: the
corruptions the tests made, and the exit code and message the README promises.
"""

from __future__ import annotations

import errno
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.model import save_model
from hrgtc.recording import Metadata, Recording, read, validate, write

from fuzzing import make_model, make_run

runner = CliRunner()


@pytest.fixture(scope="module")
def model():
    return make_model()


@pytest.fixture(scope="module")
def files(tmp_path_factory, model):
    folder = tmp_path_factory.mktemp("compensate")
    model_path = save_model(model, folder / "model.json")
    run = make_run(rows=3000)
    return folder, model_path, run


def invoke(*args):
    result = runner.invoke(app, [str(a) for a in args])
    return result.exit_code, result.stdout, result.stderr


def compensate(run_path, model_path, output, *extra):
    return invoke("compensate", run_path, "-m", model_path, "-o", output, "--json", *extra)


def with_values(run: Recording, **changes) -> Recording:
    columns = {k: np.array(run[k]) for k in run.names}
    for name, (rows, value) in changes.items():
        columns[name][rows] = value
    return Recording(columns, run.metadata)


def one_error_line(stderr: str) -> str:
    assert stderr.startswith("error:"), stderr
    assert "Traceback" not in stderr and "internal error" not in stderr, stderr
    return stderr


# -- implausible values pass -------------------------------------------------------------
@pytest.mark.parametrize("column, rows, value, match", [
    ("freq_hz", 1500, 1e300, r"column 'freq_hz', row 1500: 1e\+300 Hz is far outside the "
                             r"model's calibrated span"),
    ("freq_hz", 700, "x1000", r"column 'freq_hz', row 700: 4\.42\d+e\+06 Hz is far outside"),
    ("freq_hz", 10, 0.0, r"column 'freq_hz', row 10: 0 Hz is far outside"),
    ("rate_dph", 42, 1e300, r"column 'rate_dph', row 42: 1e\+300 °/h is beyond ±3\.6e\+06"),
    ("chamber_c", 5, 1e300, r"column 'chamber_c', row 5: 1e\+300 °C is outside -200 to 500"),
])
def test_implausible_values_are_errors_with_file_column_and_row(files, tmp_path, column, rows,
                                                                value, match):
    _folder, model_path, run = files
    if value == "x1000":
        value = run[column][rows] * 1000.0
    bad = write(with_values(run, **{column: (rows, value)}), tmp_path / "bad.parquet")
    code, _, stderr = compensate(bad, model_path, tmp_path / "out.parquet")
    assert code == 2
    assert "bad.parquet" in one_error_line(stderr)
    assert re.search(match, _squash(stderr)), stderr
    assert not (tmp_path / "out.parquet").exists()
    # info, without a model, checks the physical ranges (and the frequency against the run)
    code, _, stderr = invoke("info", bad)
    assert code == 2 and f"column '{column}', row" in _squash(stderr)


def _squash(text: str) -> str:
    return " ".join(text.split())


def test_out_of_band_single_sample_without_a_model(tmp_path, files):
    _, _, run = files
    doubled = with_values(run, freq_hz=(100, run.freq_hz[100] * 2.0))
    report = validate(doubled, raise_errors=False)
    assert [p.kind for p in report.problems] == ["implausible"]
    assert report.problems[0].row == 100 and "more than 5% away" in report.problems[0].message


def test_sample_rate_changing_within_the_file(tmp_path):
    # 5 Hz metadata, the last third at 10 Hz: only the start was checked before
    n = 3000
    time_s = np.concatenate([np.arange(2000) / 5.0, 400.0 + np.arange(1, 1001) / 10.0])
    rng = np.random.default_rng(0)
    run = Recording({"time_s": time_s, "freq_hz": 4428.5 + rng.normal(0, 0.002, n),
                     "rate_dph": 10.0 + rng.normal(0, 2.0, n)}, Metadata(sample_rate_hz=5.0))
    path = write(run, tmp_path / "mixed.csv")
    code, _, stderr = invoke("info", path)
    assert code == 2
    assert re.search(r"row 2000: the time step changes to (9\.9\d*|10) Hz but the metadata "
                     r"\(and the start of the file\) say 5 Hz; the sample rate changes.*split it "
                     r"at row 2000", _squash(stderr)), stderr


def test_csv_whose_last_field_was_cut_mid_number(tmp_path, files):
    _, model_path, run = files
    path = write(run, tmp_path / "run.csv")
    text = path.read_text().rstrip("\n")
    path.write_text(text[:-9])  # the logger died while writing the last number
    code, _, stderr = compensate(path, model_path, tmp_path / "out.parquet")
    assert code == 2
    assert "row 2999, the last line, ends without a line end" in _squash(stderr)
    path.write_text(text)  # a complete last line without a line end is fine
    assert compensate(path, model_path, tmp_path / "out.parquet")[0] == 0


# -- rate in °/s at 200 Hz, time in ms ---------------------------------------------------
@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    folder = tmp_path_factory.mktemp("units")
    runs = {}
    for rate in (1.0, 10.0, 200.0):
        written = simulate_files([profiles.soak(20.0, 400.0 / 3600.0 * max(1.0, 10.0 / rate))],
                                 folder / f"{rate:g}", "parquet", sample_rate_hz=rate, seed=4)
        runs[rate] = read(written[0].path)
    return runs


@pytest.mark.parametrize("rate_hz", [1.0, 10.0, 200.0])
@pytest.mark.parametrize("table_dph", [0.0, 360_000.0])  # at rest, and a 100 °/s rate table
def test_rate_units_are_judged_at_any_sample_rate(simulated, rate_hz, table_dph):
    run = simulated[rate_hz]
    meta = Metadata(sample_rate_hz=rate_hz, input_rate_dph=run.metadata.input_rate_dph
                    + table_dph)
    in_dph = Recording({**{k: run[k] for k in run.names},
                        "rate_dph": run.rate_dph + table_dph}, meta)
    assert validate(in_dph, raise_errors=False).ok  # °/h, even on a rate table
    for factor, unit in ((3600.0, "dps"), (3600.0 * 180.0 / math.pi, "radps")):
        scaled = in_dph.with_columns(rate_dph=in_dph.rate_dph / factor)
        report = validate(scaled, raise_errors=False)
        kinds = [p.kind for p in report.problems]
        assert kinds == ["rate_unit"], (factor, report.message)
        assert f"--rate-unit {unit}" in report.problems[0].message


def test_time_in_ms_without_metadata_names_the_option(tmp_path):
    n = 2000
    rng = np.random.default_rng(1)
    path = tmp_path / "ms.csv"
    rows = "\n".join(f"{5 * k},{4428.5 + rng.normal(0, 0.002)},{10 + rng.normal(0, 2)}"
                     for k in range(n))
    path.write_text("t,f,w\n" + rows + "\n")
    args = ["--col", "time_s=t,freq_hz=f,rate_dph=w"]
    code, _, stderr = invoke("info", path, *args)
    assert code == 2 and "pass --time-unit ms (that is 200 Hz)" in _squash(stderr)
    assert invoke("info", path, *args, "--time-unit", "ms")[0] == 0
    assert invoke("info", path, *args, "--rate-hz", "0.2")[0] == 0  # a slow logger, confirmed


# -- --gaps on compensate and evaluate -----------------------------------------------------
def test_gaps_option_on_every_command_that_reads(files, tmp_path, model):
    from hrgtc.compensate import Compensator

    _, model_path, run = files
    time_s = np.array(run.time_s)
    time_s[1500:] += 60.0  # a minute without samples
    gapped = write(Recording({**{k: run[k] for k in run.names}, "time_s": time_s},
                             run.metadata), tmp_path / "gap.parquet")
    code, _, stderr = compensate(gapped, model_path, tmp_path / "a.parquet")
    assert code == 2 and "--gaps split" in _squash(stderr) and "--gaps bridge" in _squash(stderr)
    code, stdout, _ = compensate(gapped, model_path, tmp_path / "a.parquet", "--gaps", "split")
    assert code == 0 and json.loads(stdout)["rows"] == len(run)
    out = read(tmp_path / "a.parquet", gaps="ignore")
    # split: the df/dt filter restarts after the gap, as for two runs
    second = Compensator(model).transform(read(gapped, gaps="ignore").slice(1500, len(run)))
    np.testing.assert_allclose(out.slice(1500, len(run))["bias_model_dph"],
                               second["bias_model_dph"], rtol=0, atol=1e-9)
    assert compensate(gapped, model_path, tmp_path / "b.parquet", "--gaps", "ignore")[0] == 0
    code, stdout, _ = invoke("evaluate", gapped, "-m", model_path, "--json", "--gaps", "split")
    assert code == 0 and json.loads(stdout)["n_samples"] == len(run)
    for command in ("info", "compensate", "evaluate", "calibrate", "report"):
        assert "--gaps" in invoke(command, "--help")[1]


# -- model files are trusted -------------------------------------------------------------------
@pytest.mark.parametrize("command", ["compensate", "evaluate"])
def test_a_nan_coefficient_is_a_model_file_error_not_nan_output(files, tmp_path, command):
    _folder, model_path, run = files
    data = json.loads(model_path.read_text())
    data["drift"]["scaled_coefficients"][0] = math.nan
    data["schema_version"] = 1
    del data["parameters_sha256"]
    broken = tmp_path / "nan.json"
    broken.write_text(json.dumps(data, allow_nan=True))
    run_path = write(run, tmp_path / "run.parquet")
    args = ["-o", tmp_path / "out.parquet"] if command == "compensate" else []
    code, _, stderr = invoke(command, run_path, "-m", broken, *args)
    assert code == 2
    assert "nan.json: model file is invalid at drift.scaled_coefficients[0]: 'NaN'" in \
        _squash(stderr)
    assert "run.parquet" not in stderr  # the model is blamed, not the recording


# -- compensation applied twice -------------------------------------------------------------
def test_compensated_output_is_marked_and_refused(files, tmp_path, model):
    _, model_path, run = files
    source = write(run, tmp_path / "run.parquet")
    out = tmp_path / "out.parquet"
    assert compensate(source, model_path, out)[0] == 0
    meta = json.loads(pq.read_schema(out).metadata[b"hrgtc"])
    mark = meta["extra"]["compensated_by"]
    assert mark["model_sha256"] == model.sha256 and mark["model_unit"] == "FZ-1"
    sha = model.sha256[:12]
    for args in ([], ["--col", "rate_dph=rate_comp_dph"]):  # renamed columns too
        code, _, stderr = compensate(out, model_path, tmp_path / "again.parquet", *args)
        assert code == 2
        assert f"out.parquet is already compensated, by model {sha} (unit FZ-1" in \
            _squash(stderr)
        code, _, stderr = invoke("evaluate", out, "-m", model_path, *args)
        assert code == 2 and f"by model {sha}" in stderr
    # metadata lost (another tool's CSV export): the column names still tell
    table = pq.read_table(out)
    plain = tmp_path / "plain.csv"
    plain.write_text(",".join(table.column_names) + "\n" + "\n".join(
        ",".join(repr(v) for v in row) for row in zip(*[c.to_pylist() for c in table.columns],
                                                       strict=True)) + "\n")
    code, _, stderr = compensate(plain, model_path, tmp_path / "again.parquet", "--rate-hz",
                                 "10")
    assert code == 2 and "it has the columns rate_comp_dph, bias_model_dph" in _squash(stderr)


# -- tracebacks instead of errors ------------------------------------------------------------
def test_unwritable_directory_fails_before_the_work(files, tmp_path):
    """A real read-only directory; as root (CI), the command runs as 'nobody' (setpriv)."""
    _, model_path, run = files
    shared = Path(tempfile.mkdtemp(prefix="hrgtc-unwritable-"))
    try:
        shared.chmod(0o755)
        source = write(run, shared / "r.parquet")
        model = shared / "unit.json"
        model.write_bytes(Path(model_path).read_bytes())
        for path in (source, model):
            path.chmod(0o644)
        locked = shared / "locked"
        locked.mkdir()
        locked.chmod(0o555)
        if os.geteuid() == 0:
            command = ["setpriv", "--reuid=65534", "--regid=65534", "--clear-groups",
                       sys.executable, "-m", "hrgtc.cli", "compensate", str(source),
                       "--model", str(model), "-o", str(locked / "out.parquet")]
            done = subprocess.run(command, capture_output=True, text=True, timeout=300,
                                  env={**os.environ, "HOME": str(shared),
                                       "NUMBA_CACHE_DIR": str(shared / "numba")})
            code, stderr = done.returncode, done.stderr
        else:
            code, _, stderr = compensate(source, model, locked / "out.parquet")
        assert code == 2 and "is not writable" in _squash(stderr), stderr
        assert not list(locked.iterdir())
    finally:
        shutil.rmtree(shared, ignore_errors=True)


def test_permission_and_full_disk_are_one_line_errors(files, tmp_path, monkeypatch):
    from hrgtc.core import files as files_module
    from hrgtc.recording import formats

    _, model_path, run = files
    source = write(run, tmp_path / "r.parquet")
    real_access = os.access
    monkeypatch.setattr(files_module.os, "access",
                        lambda path, mode, **k: not mode & os.W_OK and real_access(path, mode))
    code, _, stderr = compensate(source, model_path, tmp_path / "o.parquet")
    assert code == 2 and "is not writable" in one_error_line(stderr)
    monkeypatch.undo()

    class Usage:
        free = 1000

    monkeypatch.setattr(files_module.shutil, "disk_usage", lambda path: Usage)
    code, _, stderr = compensate(source, model_path, tmp_path / "o.parquet")
    assert code == 2 and "MB free" in one_error_line(stderr)  # before any work
    monkeypatch.undo()

    def full(self, columns):
        raise OSError(errno.ENOSPC, "No space left on device", str(self.path))

    for sink in (formats.ParquetSink, formats.Hdf5Sink):
        monkeypatch.setattr(sink, "write", full)
    for suffix in (".parquet", ".h5"):
        code, _, stderr = compensate(source, model_path, tmp_path / f"o{suffix}")
        assert code == 2 and "the disk is full" in one_error_line(stderr)
        assert sorted(p.name for p in tmp_path.iterdir()) == ["r.parquet"]  # nothing left


def test_corrupt_snappy_page_and_invalid_utf8(files, tmp_path):
    _, model_path, run = files
    table = pa.table({k: run[k] for k in run.names})
    snappy = tmp_path / "snappy.parquet"
    pq.write_table(table, snappy, compression="snappy")
    raw = bytearray(snappy.read_bytes())
    raw[len(raw) // 3] ^= 0xFF  # inside a data page
    snappy.write_bytes(bytes(raw))
    code, _, stderr = compensate(snappy, model_path, tmp_path / "o.parquet", "--rate-hz", "10")
    assert code == 2 and "snappy.parquet" in one_error_line(stderr)
    path = write(run, tmp_path / "r.csv")
    data = path.read_bytes()
    at = data.index(b"\n", len(data) // 2) + 3
    path.write_bytes(data[:at] + b"\xff" + data[at:])
    code, _, stderr = compensate(path, model_path, tmp_path / "o.parquet")
    assert code == 2 and "not valid UTF-8" in one_error_line(stderr) and "r.csv: row" in stderr


def test_a_flipped_bit_in_our_parquet_is_a_checksum_error(files, tmp_path):
    _, _, run = files
    path = write(run, tmp_path / "r.parquet")
    assert pq.ParquetFile(path).metadata.num_rows == len(run)
    raw = bytearray(path.read_bytes())
    offset = pq.ParquetFile(path).metadata.row_group(0).column(2).data_page_offset
    raw[offset + 200] ^= 0x01  # one bit of a rate_dph value: still a valid float
    path.write_bytes(bytes(raw))
    code, _, stderr = invoke("info", path)
    assert code == 2 and "corrupt" in stderr and "r.parquet" in stderr


# -- interrupted writes leave temporary files ----------------------------------------------
SLOW_WRITER = textwrap.dedent("""
    import sys, time
    import numpy as np
    from hrgtc.recording import Metadata, RecordingWriter
    with RecordingWriter(sys.argv[1], Metadata(sample_rate_hz=10.0), ["time_s"]) as w:
        w.write({"time_s": np.arange(10.0)})
        print("writing", flush=True)
        time.sleep(60)
""")


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_temporary_files_are_removed_on_sigterm_and_sigint(tmp_path, signum):
    target = tmp_path / "out.parquet"
    child = subprocess.Popen([sys.executable, "-c", SLOW_WRITER, str(target)],
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "writing"
        assert next(p.name for p in tmp_path.iterdir()).startswith(f".out.parquet.{child.pid}.")
        child.send_signal(signum)
        child.wait(timeout=30)
    finally:
        if child.poll() is None:
            child.kill()
    assert list(tmp_path.iterdir()) == []


def test_stale_temporary_files_of_dead_runs_are_removed_and_others_reported(files, tmp_path):
    from hrgtc.core.files import StaleTemporaryWarning

    _, model_path, run = files
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".out.parquet.{dead.pid}.abc123.tmp"
    stale.write_bytes(b"x" * 1000)
    alive = tmp_path / f".out.parquet.{os.getppid()}.def456.tmp"  # a running process
    alive.write_bytes(b"y")
    old_style = tmp_path / ".out.parquet.q1w2e3.tmp"  # no PID: older hrgtc
    old_style.write_bytes(b"z")
    source = write(run, tmp_path / "r.parquet")
    with pytest.warns(StaleTemporaryWarning, match=r"1 temporary file\(s\) .* remain"):
        code = compensate(source, model_path, tmp_path / "out.parquet")[0]
    assert code == 0
    assert not stale.exists() and alive.exists() and old_style.exists()


@pytest.mark.parametrize("command", ["compensate", "evaluate", "calibrate"])
def test_time_in_ms_gets_the_time_unit_hint_not_thousands_of_gaps(tmp_path, command):
    """Time logged in ms under 10 Hz metadata: every step is 1000 periods. Every command
    says '--time-unit ms', as info does, not '8999 gaps ... pass --gaps bridge' (the reader
    raised the gaps of its first chunk before the whole-file heuristics had run)."""
    from hrgtc.recording import Recording, write

    from fuzzing import make_model, make_run

    run = make_run(9000)
    columns = {k: run[k] for k in run.names}
    columns["time_s"] = columns["time_s"] * 1000.0
    path = write(Recording(columns, run.metadata), tmp_path / "ms.csv")
    model = save_model(make_model(), tmp_path / "m.json")
    args = {"compensate": [str(path), "--model", str(model), "-o", str(tmp_path / "o.csv")],
            "evaluate": [str(path), "--model", str(model)],
            "calibrate": ["--drift", str(path), "-o", str(tmp_path / "c.json")]}[command]
    result = CliRunner().invoke(app, [command, *args])
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "--time-unit ms" in text and "gap(s)" not in text, text


def test_compensate_refuses_to_drop_spikes(files, tmp_path):
    """The library's refusal (compensate_file), through the command: exit 2, the fix."""
    _, model_path, run = files
    run_path = write(run, tmp_path / "run.parquet")
    code, _, stderr = compensate(run_path, model_path, tmp_path / "out.parquet",
                                 "--spike-filter", "drop")
    assert code == 2
    assert "never drops a row: use --spike-filter flag" in " ".join(one_error_line(stderr).split())
    assert not (tmp_path / "out.parquet").exists()
