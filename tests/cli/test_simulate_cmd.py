"""``hrgtc simulate``: in-process runs with Typer's CliRunner, checked through --json.

Truth: the files on disk (read back with hrgtc.recording), the row counts
``hours * 3600 * rate``, the chamber programs the options ask for, and the
library called directly with the same seed.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc import simulate
from hrgtc.cli import app
from hrgtc.recording import read
from hrgtc.simulate import standard_profiles

runner = CliRunner()


def run(*args: str) -> tuple[int, list | None, str]:
    result = runner.invoke(app, ["simulate", *args, "--json"])
    data = json.loads(result.stdout) if result.exit_code == 0 else None
    return result.exit_code, data, result.stderr


def test_soaks_one_file_per_set_point_and_no_overwrite_without_force(tmp_path):
    out = tmp_path / "soaks"
    args = ["--profile", "soak", "--setpoints=-20,-10", "--hours", "0.05", "--rate-hz", "10"]
    code, data, _ = run(*args, "--seed", "1", "-o", str(out))
    assert code == 0
    assert [d["path"] for d in data] == [
        str(out / "soak_-20C.parquet"),
        str(out / "soak_-10C.parquet"),
    ]
    assert [d["rows"] for d in data] == [1800, 1800]  # 0.05 h * 3600 s/h * 10 Hz
    rec = read(data[0]["path"])
    assert rec.metadata.unit == "paper-unit" and rec.metadata.sample_rate_hz == 10.0
    assert rec.metadata.extra["setpoint_c"] == -20.0
    # From room temperature, slewing at 2 °C/min: 179.9 s after the start, 20 - 179.9 / 30.
    assert rec["chamber_c"][0] == 20.0
    assert rec["chamber_c"][-1] == pytest.approx(20.0 - 179.9 / 30.0, rel=1e-12)
    library = simulate.simulate_run(
        simulate.soak(-20.0, 0.05), sample_rate_hz=10.0,
        seed=np.random.SeedSequence(1, spawn_key=(0,))
    )
    assert np.array_equal(rec.rate_dph, library.rate_dph)

    before = out.joinpath("soak_-10C.parquet").read_bytes()
    code, _, err = run(*args, "--seed", "2", "-o", str(out))
    assert code == 2
    assert "exist" in err and "--force" in err
    assert out.joinpath("soak_-10C.parquet").read_bytes() == before
    code, _, _ = run(*args, "--seed", "2", "-o", str(out), "--force")
    assert code == 0
    assert out.joinpath("soak_-10C.parquet").read_bytes() != before


def test_single_file_holds_all_set_points(tmp_path):
    code, data, _ = run(
        "--profile", "soak", "--setpoints=-20,40", "--hours", "0.5", "--single-file",
        "--rate-hz", "1", "-o", str(tmp_path / "all.csv"),
    )
    assert code == 0 and len(data) == 1 and data[0]["rows"] == 3600
    rec = read(data[0]["path"])
    # Chamber: 20 -> -20 at 2 °C/min (1200 s), hold to 1800 s, then -20 -> 40 (1800 s).
    assert rec["chamber_c"][1200] == -20.0 and rec["chamber_c"][1800] == -20.0
    assert rec["chamber_c"][-1] == pytest.approx(40.0 - 1.0 / 30.0, rel=1e-12)


@pytest.mark.parametrize(
    ("args", "name", "first", "last"),
    [
        (
            ["--profile", "cooldown", "--start", "20", "--end", "-20"],
            "cooldown_20C_to_-20C",
            20,
            -20,
        ),
        (["--profile", "warmup"], "warmup_-20C_to_20C", -20, 20),
        (["--profile", "constant", "--temperature", "5"], "constant_5C", 5, 5),
        (["--profile", "ramp", "--start", "0", "--end", "10", "--ramp-rate", "0.5"],
         "ramp_0C_to_10C", 0, 10),
    ],
)
def test_run_profiles(tmp_path, args, name, first, last):
    hours = [] if "ramp" in args else ["--hours", "1"]
    code, data, _ = run(*args, *hours, "--rate-hz", "1", "--format", "h5", "-o", str(tmp_path))
    assert code == 0
    assert data[0]["path"] == str(tmp_path / f"{name}.h5")
    rec = read(data[0]["path"])
    assert rec["chamber_c"][0] == first and rec["chamber_c"][-1] == pytest.approx(last, abs=0.01)


def test_profile_file_and_unit_b(tmp_path):
    path = tmp_path / "cycle.yaml"
    path.write_text(
        "start_c: 20\nsegments:\n"
        "  - {setpoint_c: 0, ramp_c_per_min: 2}\n"
        "  - {setpoint_c: 0, hold_h: 0.2}\n"
    )
    code, data, _ = run(
        "--profile", str(path), "--unit", "unit-b", "--rate-hz", "2", "-o", str(tmp_path)
    )
    assert code == 0
    assert data[0]["path"] == str(tmp_path / "cycle.parquet")
    assert data[0]["rows"] == ((600 + 720) * 2)  # 10 min ramp + 0.2 h hold at 2 Hz
    rec = read(data[0]["path"])
    assert rec.metadata.unit == "unit-b"
    assert 5000.0 < rec.freq_hz.mean() < 7000.0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--unit", "unit-z"],
         "'unit-z' is not one of 'paper-unit', 'unit-b', 'unit-play', 'imu-3', 'mems-3'"),
        (["--profile", "sock"], "unknown profile 'sock'"),
        (["--profile", "soak", "--temperature", "3"], "do not apply to profile 'soak'"),
        (["--profile", "cooldown", "--start", "-20", "--end", "20"], "needs end_c < start_c"),
        (["--profile", "missing.yaml"], "profile file missing.yaml not found"),
    ],
)
def test_errors_exit_2_with_a_message(tmp_path, args, message):
    code, _, err = run(*args, "--hours", "0.01", "--rate-hz", "1", "-o", str(tmp_path))
    assert code == 2
    assert message in " ".join(err.split())
    assert not list(tmp_path.iterdir())


def test_bad_setpoints_list(tmp_path):
    code, _, err = run("--setpoints=-20,warm", "-o", str(tmp_path))
    assert code == 2 and "'-20,warm' is not a comma-separated list of float values" in err


def test_ratetable_single_axis_reads_back_with_its_input_rate(tmp_path):
    code, data, _ = run(
        "--profile", "ratetable", "--setpoints=10,30", "--hours", "0.05", "--rates", "0,-50",
        "--rate-hold-s", "20", "--rate-hz", "2", "-o", str(tmp_path),
    )
    assert code == 0
    assert data[0]["path"] == str(tmp_path / "ratetable_10C_to_30C.parquet")
    assert data[0]["rows"] == 2 * (180 + 2 * 20) * 2  # two plateaus of 180 s + 2 x 20 s, 2 Hz
    rec = read(data[0]["path"])
    assert rec.metadata.input_rate_dph == 10.0
    assert set(np.unique(rec["input_rate_dph"])) == {10.0, 10.0 - 50 * 3600}
    assert rec.metadata.extra["chamber_program"]["segments"][2]["table_rate_dps"] == -50.0


def test_ratetable_on_imu3_writes_per_axis_columns(tmp_path):
    code, data, _ = run(
        "--profile", "ratetable", "--unit", "imu-3", "--setpoints=20", "--hours", "0.02",
        "--rates", "100", "--rate-hold-s", "10", "--rate-hz", "1", "--format", "csv",
        "-o", str(tmp_path),
    )
    assert code == 0 and data[0]["rows"] == 72 + 3 * 10
    lines = [
        line for line in (tmp_path / "ratetable_20C.csv").read_text().splitlines()
        if not line.startswith("#")
    ]
    header = lines[0].split(",")
    assert header == list(simulate.run_columns(standard_profiles.rate_table(
        [20.0], [100.0], 10.0, 0.02, axes=("x", "y", "z")), "imu-3"))
    values = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    turning = {a: values[:, header.index(f"input_rate_dph_{a}")] > 1000.0 for a in "xyz"}
    assert [int(np.flatnonzero(turning[a])[0]) for a in "xyz"] == [72, 82, 92]
    assert all(turning[a].sum() == 10 for a in "xyz")


@pytest.mark.parametrize("logger", ["pan-cold", "fridge-3day"])
def test_a_preset_refuses_profile_options_it_would_ignore(tmp_path, logger):
    # --hours with a preset and no --profile used to be dropped in silence (the preset's
    # own 2 h / 72 h program was written); now it says what to pass.
    code, _, err = run("--logger", logger, "--hours", "0.01", "--rate-hz", "1",
                       "-o", str(tmp_path / "x.csv"))
    assert code == 2
    assert "--hours" in err and "--profile" in err
    assert not (tmp_path / "x.csv").exists()
    code, _, err = run("--logger", logger, "--hours", "0.1", "--profile", "constant",
                          "--rate-hz", "1", "--spikes", "0", "-o", str(tmp_path / "y.csv"))
    assert code == 0, err
    truth = json.loads((tmp_path / "y.truth.json").read_text())
    assert truth["chamber_program"]["segments"][-1]["hold_h"] == 0.1
