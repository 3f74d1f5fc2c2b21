"""``hrgtc fleet ...`` and ``hrgtc calibrate --prior`` in-process: JSON output, exit codes."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

SMALL = ["--sample-rate-hz", "1", "--soak-hours", "2.5", "--ramp-hours", "2",
         "--setpoints=-20,0,10,20,40"]


@pytest.fixture(scope="module")
def fleet(tmp_path_factory):
    root = tmp_path_factory.mktemp("cli-fleet")
    result = CliRunner().invoke(app, ["fleet", "simulate", "--units", "7", "--seed", "3",
                                      *SMALL, "-o", str(root / "fleet"), "--workers", "0",
                                      "--json"])
    assert result.exit_code == 0, result.output
    assert (root / "fleet" / "s3-u0006" / "truth.json").is_file()
    return root


def test_fleet_commands_end_to_end(fleet):
    runner = CliRunner()
    root = fleet
    (root / "fleet" / "s3-u0006" / "drift" / "cooldown_20C_to_-20C.parquet").write_text("x")
    result = runner.invoke(app, ["fleet", "calibrate", str(root / "fleet"), "-o",
                                 str(root / "models"), "--workers", "0", "--json"])
    assert result.exit_code == 1, result.output  # one unit failed, the others completed
    data = json.loads(result.stdout)
    assert data["counts"] == {"ok": 6, "skipped": 0, "failed": 1}
    (failed,) = [u for u in data["units"] if u["status"] == "failed"]
    assert failed["unit"] == "s3-u0006" and failed["error"]["file"].endswith(".parquet")

    result = runner.invoke(app, ["fleet", "calibrate", str(root / "fleet"), "-o",
                                 str(root / "models"), "--workers", "0", "--resume", "--json"])
    assert json.loads(result.stdout)["counts"] == {"ok": 0, "skipped": 6, "failed": 1}

    result = runner.invoke(app, ["fleet", "evaluate", str(root / "fleet"), "--models",
                                 str(root / "models"), "--unit-name", "x", "--workers", "0",
                                 "--no-allan", "--json"])
    assert json.loads(result.stdout)["counts"]["ok"] == 6

    result = runner.invoke(app, ["fleet", "report", str(root / "models"), "-o",
                                 str(root / "fleet.html")])
    assert result.exit_code == 0, result.output
    assert "s3-u0006" in (root / "fleet.html").read_text()

    result = runner.invoke(app, ["fleet", "prior", str(root / "models"), "-o",
                                 str(root / "prior.json"), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["n_units"] == 6

    unit = root / "fleet" / "s3-u0001"
    result = runner.invoke(app, ["calibrate", "--prior", str(root / "prior.json"),
                                 "--soak", str(unit / "soaks" / "soak_-20C.parquet"),
                                 "--soak", str(unit / "soaks" / "soak_40C.parquet"),
                                 "--drift", str(unit / "drift" / "cooldown_20C_to_-20C.parquet"),
                                 "-o", str(root / "u1.json"), "--json"])
    assert result.exit_code == 0, result.output
    prior = json.loads(result.stdout)["prior"]
    assert prior["prior_units"] == 6 and prior["max_temperature_std_c"] < 0.1

    # a unit of another kind (unit-b: a smaller shell at ~5.7 kHz) is refused
    other = root / "unit-b"
    for args in (["--profile", "soak", "--setpoints=-20,40", "--hours", "2.5",
                  "-o", str(other / "soaks")],
                 ["--profile", "cooldown", "--start", "20", "--end", "-20", "--hours", "2",
                  "-o", str(other / "cool.parquet")]):
        result = runner.invoke(app, ["simulate", *args, "--sample-rate-hz", "1",
                                     "--unit", "unit-b"])
        assert result.exit_code == 0, result.output
    result = runner.invoke(app, ["calibrate", "--prior", str(root / "prior.json"), "--soak",
                                 str(other / "soaks" / "soak_-20C.parquet"), "--soak",
                                 str(other / "soaks" / "soak_40C.parquet"), "--drift",
                                 str(other / "cool.parquet"), "-o", str(other / "m.json")])
    assert result.exit_code == 2
    assert "differ in kind" in result.output
