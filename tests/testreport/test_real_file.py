"""``hrgtc test-report`` on a real file no one here wrote, read with its column mapping and
units only (the options every command takes): the climate-chamber cycle of
``tests/data/tofupilot-imu-chamber`` (tab-separated, time in µs, rates in rad/s) as one
sweep. Its temperature and gradient sensitivities equal an independent numpy fit of the
same 60 s block means (the Earth rate is 0 for an up axis on the equator)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

DATA = Path(__file__).resolve().parents[1] / "data" / "tofupilot-imu-chamber"
MAPPING = ["--col", "time_s=timestamp", "--col", "rate_dph_x=imu.gyro.x",
           "--col", "rate_dph_y=imu.gyro.y", "--col", "rate_dph_z=imu.gyro.z",
           "--col", "temperature_c=imu.temperature", "--time-unit", "us",
           "--rate-unit", "radps", "--thermometer", "sensor"]
MANIFEST = """title = "Chamber cycle of a flight-controller IMU"
[unit]
serial = "tofupilot-example"
firmware = "unknown"
file_axis = "z"
[site]
latitude_deg = 0.0
axis = "up"
[settings]
block_s = 60
settle_s = 0
temperature_column = "temperature_c"
[[runs]]
file = "imu_raw_data.csv"
role = "sweep"
"""


def _numpy_fit(path: Path) -> np.ndarray:
    """b0, the slope against T [°/h/°C] and against dT/dt [°/h/(°C/min)] of the 60 s block
    means of the z rate, by numpy alone."""
    c = np.genfromtxt(path, delimiter="\t", names=True, deletechars="")
    t = (c["timestamp"] - c["timestamp"][0]) * 1e-6
    rate = np.degrees(c["imu.gyro.z"]) * 3600.0
    block = np.floor(t / 60.0).astype(np.int64)
    n = np.bincount(block)
    kept = n > 0
    mean = [np.bincount(block, v)[kept] / n[kept] for v in (rate, c["imu.temperature"], t)]
    gradient = np.gradient(mean[1], mean[2]) * 60.0
    design = np.column_stack([np.ones_like(mean[1]), mean[1], gradient])
    return np.linalg.lstsq(design, mean[0], rcond=None)[0]


def test_a_real_sweep_with_its_column_mapping_gives_the_numpy_sensitivities(tmp_path):
    shutil.copy(DATA / "imu_raw_data.csv", tmp_path / "imu_raw_data.csv")
    (tmp_path / "campaign.toml").write_text(MANIFEST, encoding="utf-8")
    result = CliRunner().invoke(app, ["test-report", str(tmp_path / "campaign.toml"), "-o",
                                      str(tmp_path / "r.html"), "--no-pdf", *MAPPING])
    assert result.exit_code == 0, result.output
    figures = {f["name"]: f for f in json.loads((tmp_path / "r.json").read_text())["figures"]}
    _, slope, gradient = _numpy_fit(tmp_path / "imu_raw_data.csv")
    assert figures["bias_temperature_sensitivity_dph_per_c"]["value"] == pytest.approx(
        slope, rel=1e-3)
    assert figures["bias_gradient_sensitivity_dph_per_c_per_min"]["value"] == pytest.approx(
        gradient, rel=0.01)
    assert figures["bias_repeatability_dph"]["verdict"] == "not measured"
