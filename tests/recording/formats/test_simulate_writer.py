"""``hrgtc simulate --format tdms|mat|mf4``: the registry's writers, the output names from
``output_suffixes()``, read-only formats refused naming those that write, and a campaign
written as TDMS calibrating to the model the same campaign in Parquet gives.

Truth: the registry's own list of writers; the model ``hrgtc calibrate`` fits on the
Parquet files (hrgtc's own format), compared with that fitted on the TDMS files.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.cli.options import OutputFormat
from hrgtc.recording import read
from hrgtc.recording.formats.registry import output_suffixes

runner = CliRunner()


def simulate(*args: str) -> list[dict[str, Any]]:
    result = runner.invoke(app, ["simulate", *args, "--json"])
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_the_written_out_output_formats_are_the_registrys_writers():
    assert [f.value for f in OutputFormat] == list(output_suffixes())
    assert {k: output_suffixes()[k] for k in ("tdms", "mat", "mf4")} == {
        "tdms": ".tdms", "mat": ".mat", "mf4": ".mf4"}


@pytest.mark.parametrize("fmt", ["tdms", "mat", "mf4"])
def test_simulate_writes_each_format_and_it_reads_back_as_parquet_does(tmp_path, fmt):
    args = ["--profile", "constant", "--temperature", "5", "--hours", "0.1", "--rate-hz", "5",
            "--seed", "9"]
    (written,) = simulate(*args, "--format", fmt, "-o", str(tmp_path / fmt))
    (reference,) = simulate(*args, "-o", str(tmp_path / "parquet"))
    assert written["path"] == str(tmp_path / fmt / f"constant_5C{output_suffixes()[fmt]}")
    back, truth = read(written["path"]), read(reference["path"])
    assert back.names == truth.names and back.metadata == truth.metadata
    for name in truth.names:
        assert np.array_equal(back[name], truth[name]), name


@pytest.mark.parametrize(("given", "named"), [("ulog", "ulog"), ("dataflash", "dataflash")])
def test_a_format_without_a_writer_is_refused_naming_those_that_write(tmp_path, given, named):
    result = runner.invoke(app, ["simulate", "--format", given, "-o", str(tmp_path)])
    assert result.exit_code == 2
    text = " ".join(result.output.split()).replace("│", "")
    text = " ".join(text.split())
    assert f"hrgtc has no writer for {named} files" in text
    assert "the formats that write are parquet, csv, h5, tdms, mat, mf4" in text
    assert list(tmp_path.iterdir()) == []


def test_simulate_help_imports_no_format_library():
    code = ("import sys\nfrom typer.testing import CliRunner\nfrom hrgtc.cli import app\n"
            "assert CliRunner().invoke(app, ['simulate', '--help']).exit_code == 0\n"
            "print(sorted(m for m in ('nptdms', 'asammdf', 'scipy', 'h5py') "
            "if m in sys.modules))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, timeout=120)
    assert out.stdout.strip() == "[]"


def _without_provenance(model: Any, folder: Path) -> Any:
    """The model without what differs by file: creation time, hashes, the inputs' names."""
    if isinstance(model, dict):
        return {re.sub(r"\.(tdms|parquet)$", "", str(k).replace(str(folder), "")):
                _without_provenance(v, folder) for k, v in model.items()
                if k not in ("created_utc", "sha256", "parameters_sha256")}
    if isinstance(model, list):
        return [_without_provenance(v, folder) for v in model]
    if isinstance(model, str):
        return re.sub(r"\.(tdms|parquet)$", "", model.replace(str(folder), ""))
    return model


def test_a_campaign_written_as_tdms_calibrates_to_the_parquet_campaigns_model(tmp_path):
    models = {}
    for fmt in ("parquet", "tdms"):
        folder = tmp_path / fmt
        soaks = simulate("--profile", "soak", "--setpoints=-20,0,20,40", "--hours", "5",
                         "--rate-hz", "1", "--seed", "4", "--format", fmt, "-o", str(folder))
        (cool,) = simulate("--profile", "cooldown", "--start", "20", "--end", "-20", "--hours",
                           "5", "--rate-hz", "1", "--seed", "5", "--format", fmt,
                           "-o", str(folder))
        model = folder / "model.json"
        result = runner.invoke(app, ["calibrate", "--soak", *(s["path"] for s in soaks),
                                     "--drift", cool["path"], "-o", str(model)])
        assert result.exit_code == 0, result.output
        models[fmt] = _without_provenance(json.loads(model.read_text()), folder)
    assert models["tdms"] == models["parquet"]
    assert models["tdms"]["drift"] == models["parquet"]["drift"]  # the fit itself, not only text
