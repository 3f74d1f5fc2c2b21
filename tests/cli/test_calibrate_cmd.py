"""``hrgtc calibrate``: an output that cannot be written fails before the fit (issue 11)."""

from __future__ import annotations

import os
import time

from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.recording import write

from fuzzing import make_run

runner = CliRunner()


def test_unwritable_output_fails_at_once_not_after_the_fit(tmp_path, monkeypatch):
    from hrgtc.core import files

    run = write(make_run(), tmp_path / "run.parquet")
    args = ["calibrate", "--soak", str(run), "--drift", str(run)]
    start = time.perf_counter()
    result = runner.invoke(app, [*args, "-o", str(tmp_path / "missing" / "unit.json")])
    assert result.exit_code == 2
    assert "directory" in result.stderr and "does not exist; create it first" in result.stderr
    real_access = os.access
    monkeypatch.setattr(files.os, "access",
                        lambda path, mode, **k: not mode & os.W_OK and real_access(path, mode))
    result = runner.invoke(app, [*args, "-o", str(tmp_path / "unit.json")])
    assert result.exit_code == 2 and "is not writable" in result.stderr
    assert time.perf_counter() - start < 5.0  # no soak was read, no model fitted
