"""Outputs never replace inputs, writes that fail name their file, training refuses
compensated files (issue 21, Deliver 6 and the reading-side items).

Each command that writes is given ``-o`` naming one of its inputs, spelled the same,
through a symbolic link, a hard link and a relative path, with ``--force``: the
command must refuse (exit 2, one line naming the output) and leave the input's bytes
unchanged. On the main branch before this work ``compensate --force`` replaced the raw
recording by its compensation.
"""

from __future__ import annotations

import errno
import os

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.model import save_model
from hrgtc.recording import formats, write

from fuzzing import make_model, make_run

runner = CliRunner()


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("outputs")
    model_path = save_model(make_model(), folder / "model.json")
    run_path = write(make_run(rows=1200), folder / "run.parquet")
    return folder, model_path, run_path


def invoke(*args):
    result = runner.invoke(app, [str(a) for a in args])
    return result.exit_code, result.stdout, result.stderr.strip()


def refused(code: int, stderr: str, name: str) -> bool:
    return (code == 2 and stderr.startswith("error:") and "is an input of this command" in stderr
            and "even with --force" in stderr and name in stderr and "Traceback" not in stderr)


def _spellings(tmp_path, target):
    """The same file as ``target`` named four ways: itself, a symlink, a hard link, relative."""
    symlink = tmp_path / "link.parquet"
    symlink.symlink_to(target)
    hard = tmp_path / "hard.parquet"
    os.link(target, hard)
    relative = os.path.relpath(target, tmp_path)
    return [str(target), str(symlink), str(hard), relative]


def test_compensate_refuses_an_output_that_is_its_input_even_with_force(files, tmp_path,
                                                                       monkeypatch):
    _, model_path, run_path = files
    before = run_path.read_bytes()
    monkeypatch.chdir(tmp_path)
    for output in _spellings(tmp_path, run_path):
        code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o", output,
                                 "--force")
        assert refused(code, stderr, output), (output, stderr)
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o", model_path.with_suffix(
        ".csv"), "--force")
    assert code == 0, stderr  # another file is fine
    assert run_path.read_bytes() == before


def test_compensate_refuses_the_model_file_as_output(files, tmp_path):
    _, model_path, run_path = files
    link = tmp_path / "m.parquet"  # an output suffix, the model's bytes behind it
    link.symlink_to(model_path)
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o", link, "--force")
    assert refused(code, stderr, "m.parquet")


def test_evaluate_calibrate_report_and_export_refuse_their_inputs(files, tmp_path):
    _, model_path, run_path = files
    model_before, run_before = model_path.read_bytes(), run_path.read_bytes()
    code, _, stderr = invoke("evaluate", run_path, "-m", model_path, "--allan-csv", model_path,
                             "--force")
    assert refused(code, stderr, "model.json")
    code, _, stderr = invoke("calibrate", "--soak", run_path, "--drift", run_path, "-o",
                             run_path, "--force")
    assert refused(code, stderr, "run.parquet")
    code, _, stderr = invoke("report", run_path, "-m", model_path, "-o", model_path, "--force")
    assert refused(code, stderr, "model.json")
    params = tmp_path / "hrgtc_params.txt"  # the model under the name export-c writes
    params.write_bytes(model_before)
    code, _, stderr = invoke("export-c", params, "-o", tmp_path, "--format", "params", "--force")
    assert refused(code, stderr, "hrgtc_params.txt")
    assert params.read_bytes() == model_before
    assert (model_path.read_bytes(), run_path.read_bytes()) == (model_before, run_before)


def test_a_full_disk_names_the_output_not_a_temporary_file(files, tmp_path, monkeypatch):
    _, model_path, run_path = files

    def full(self, columns):  # as pyarrow reports it: an errno, no file name
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(formats.ParquetSink, "write", full)
    output = tmp_path / "out.parquet"
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o", output)
    assert code == 2 and stderr.startswith(f"error: {output}: the disk is full"), stderr
    assert list(tmp_path.iterdir()) == []  # no temporary file left behind

    def full_named(self, columns):  # as h5py reports it: the temporary file's name
        raise OSError(errno.ENOSPC, "No space left on device", str(self.path))

    monkeypatch.setattr(formats.ParquetSink, "write", full_named)
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o", output)
    assert stderr.startswith(f"error: {output}: the disk is full"), stderr
    assert ".tmp" not in stderr


def test_calibrate_refuses_a_compensated_file_as_training_input(files, tmp_path):
    _, model_path, run_path = files
    compensated = tmp_path / "comp.parquet"
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o", compensated)
    assert code == 0, stderr
    for option in ("--drift", "--soak"):
        args = ["--soak", run_path, "--drift", run_path]
        args[args.index(option) + 1] = compensated
        code, _, stderr = invoke("calibrate", *args, "-o", tmp_path / "m.json")
        assert code == 2 and "comp.parquet is already compensated" in stderr, stderr
        assert "calibrate on the original (raw) recording" in stderr
    # the columns alone (metadata dropped, e.g. by a spreadsheet) are enough to tell
    stripped = tmp_path / "stripped.csv"
    text = compensated.with_suffix(".csv")
    invoke("compensate", run_path, "-m", model_path, "-o", text)
    stripped.write_text("\n".join(line for line in text.read_text().split("\n")
                                  if not line.startswith("#")))
    code, _, stderr = invoke("calibrate", "--thermometer", "sensor", "--drift", stripped,
                             "-o", tmp_path / "m.json")
    assert code == 2 and "stripped.csv is already compensated" in stderr, stderr
    assert not (tmp_path / "m.json").exists()


def test_fleet_commands_refuse_an_output_in_the_models_they_read(files, tmp_path):
    _, model_path, _ = files
    models = tmp_path / "models"
    models.mkdir()
    unit = models / "u1.json"
    unit.write_bytes(model_path.read_bytes())
    table = models / "fleet.parquet"
    table.write_bytes(b"PAR1 stands in for the fleet table")
    for args in (["fleet", "prior", models, "-o", unit, "--force"],
                 ["fleet", "report", models, "-o", table, "--force"],
                 ["fleet", "evaluate", tmp_path, "--models", models, "-o", table, "--force"]):
        code, _, stderr = invoke(*args)
        assert refused(code, stderr, unit.name if unit in args else table.name), (args, stderr)
    assert unit.read_bytes() == model_path.read_bytes()
