"""``hrgtc test-report`` on the real cold test with its calibrated three-axis model: the
manifest names the model and the axis (``file_axis``), the newcomer passes the column mapping
and units only (no ``--temp-ref``: the model file holds the count's map to °C)."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

from .conftest import MAPPING, RUN, pan_columns

MANIFEST = """title = "Cold test of a CubeSat engineering unit"
[unit]
serial = "pan-etu"
firmware = "unknown"
model = "pan.json"
file_axis = "y"
[site]
latitude_deg = 0.0
axis = "up"
[settings]
block_s = 60
settle_s = 0
temperature_column = "temperature_c"
[[runs]]
file = "pan_tvc_cold_2020-03-07.csv"
role = "sweep"
"""


def _numpy_fit(scale: float, offset: float) -> np.ndarray:
    """b0, the slope against T [°/h/°C] and against dT/dt [°/h/(°C/min)] of the 60 s block
    means of the y rate, the count mapped to °C by the model's map, by numpy alone."""
    c = pan_columns()
    t = c["time_s"] - c["time_s"][0]
    temperature = scale * c["count"] + offset
    block = np.floor(t / 60.0).astype(np.int64)
    n = np.bincount(block)
    kept = n > 0
    mean = [np.bincount(block, v)[kept] / n[kept] for v in (c["y"], temperature, t)]
    gradient = np.gradient(mean[1], mean[2]) * 60.0
    design = np.column_stack([np.ones_like(mean[1]), mean[1], gradient])
    return np.linalg.lstsq(design, mean[0], rcond=None)[0]


def test_a_three_axis_model_of_a_raw_count_reports_one_axis_in_degrees(pan_model, tmp_path):
    shutil.copy(RUN, tmp_path / RUN.name)
    shutil.copy(pan_model, tmp_path / "pan.json")
    (tmp_path / "campaign.toml").write_text(MANIFEST, encoding="utf-8")
    result = CliRunner().invoke(app, ["test-report", str(tmp_path / "campaign.toml"), "-o",
                                      str(tmp_path / "r.html"), "--no-pdf", *MAPPING])
    assert result.exit_code == 0, result.output
    figures = {f["name"]: f for f in json.loads((tmp_path / "r.json").read_text())["figures"]}
    found = json.loads(pan_model.read_text())["temperature_map"]
    _, slope, gradient = _numpy_fit(found["scale_c_per_count"], found["offset_c"])
    # per °C of the mapped count (per count it would be 170× smaller)
    assert figures["bias_temperature_sensitivity_dph_per_c"]["value"] == pytest.approx(
        slope, rel=1e-3)
    assert figures["bias_gradient_sensitivity_dph_per_c_per_min"]["value"] == pytest.approx(
        gradient, rel=0.01)
    after = figures["bias_temperature_sensitivity_compensated_dph_per_c"]
    assert after["verdict"] != "not measured", after
    # the model (trained on this axis's first 60 %) takes most of the slope out
    assert abs(after["value"]) < 0.5 * abs(slope), (after, slope)


VN100 = RUN.parents[1] / "vn100-waves-in-ice" / "vn100_F00379-F00383.csv"
VN100_MAPPING = ["--col", "time_s=millis", "--col", "rate_dph_x=GyroX", "--col",
                 "rate_dph_y=GyroY", "--col", "rate_dph_z=GyroZ", "--col", "temperature_c=Temp",
                 "--time-unit", "ms", "--rate-unit", "radps", "--thermometer", "sensor"]
#: At rest, in the logger's seconds (millis / 1000; the file's README).
VN100_AT_REST = ((48.0, 1082.0), (1115.0, 1294.0), (1829.0, 3287.0), (3440.0, 4500.0))


def _vn100_fit(at_rest_only: bool) -> np.ndarray:
    """As :func:`_numpy_fit`, on the VN-100's z axis, all samples or those at rest only."""
    c = np.genfromtxt(VN100, delimiter=",", names=True, usecols=("millis", "GyroZ", "Temp"))
    s = c["millis"] / 1000.0
    keep = np.ones(s.size, dtype=bool)
    if at_rest_only:
        keep = np.any([(s >= a) & (s < b) for a, b in VN100_AT_REST], axis=0)
    t = (s - s[0])[keep]
    block = np.floor(t / 60.0).astype(np.int64)
    n = np.bincount(block)
    kept = n > 0
    rate = np.degrees(c["GyroZ"][keep]) * 3600.0
    mean = [np.bincount(block, v)[kept] / n[kept] for v in (rate, c["Temp"][keep], t)]
    gradient = np.gradient(mean[1], mean[2]) * 60.0
    design = np.column_stack([np.ones_like(mean[1]), mean[1], gradient])
    return np.linalg.lstsq(design, mean[0], rcond=None)[0]


def test_a_sweep_with_handling_is_judged_on_its_samples_at_rest(tmp_path):
    """The VN-100 is carried about for 9 minutes between its warm-up and its cool-down (up to
    177 °/s): the sensitivities are those of numpy's fit of the samples its README calls at
    rest, not of all samples (the gradient sensitivity's sign flips)."""
    shutil.copy(VN100, tmp_path / VN100.name)
    manifest = MANIFEST.replace('model = "pan.json"\n', "").replace(
        'file_axis = "y"', 'file_axis = "z"').replace(RUN.name, VN100.name)
    (tmp_path / "campaign.toml").write_text(manifest, encoding="utf-8")
    result = CliRunner().invoke(app, ["test-report", str(tmp_path / "campaign.toml"), "-o",
                                      str(tmp_path / "r.html"), "--no-pdf", *VN100_MAPPING])
    assert result.exit_code == 0, result.output
    document = json.loads((tmp_path / "r.json").read_text())
    figures = {f["name"]: f["value"] for f in document["figures"]}
    _, slope, gradient = _vn100_fit(at_rest_only=True)
    _, _, gradient_all = _vn100_fit(at_rest_only=False)
    assert gradient < 0.0 < gradient_all  # what handling does to the figure
    assert figures["bias_temperature_sensitivity_dph_per_c"] == pytest.approx(slope, rel=0.02)
    assert figures["bias_gradient_sensitivity_dph_per_c_per_min"] == pytest.approx(gradient,
                                                                                 rel=0.05)
    assert any("not at rest" in note for note in document["notes"]), document["notes"]


def test_the_noise_figures_of_a_run_with_handling_come_from_its_longest_stretch_at_rest(
        tmp_path):
    """The VN-100 as a turn-on: its Allan deviation is of the longest stretch at rest (the
    cool-down, about 1435 s), not of samples that include 9 minutes of carrying about
    (with them the angle random walk read 447 °/√h). The angle random walk is numpy's white
    noise of the README's still cool-down, within 5 %."""
    shutil.copy(VN100, tmp_path / VN100.name)
    manifest = MANIFEST.replace('model = "pan.json"\n', "").replace(
        'file_axis = "y"', 'file_axis = "z"').replace(RUN.name, VN100.name).replace(
        'role = "sweep"', 'role = "turn-on"')
    (tmp_path / "campaign.toml").write_text(manifest, encoding="utf-8")
    result = CliRunner().invoke(app, ["test-report", str(tmp_path / "campaign.toml"), "-o",
                                      str(tmp_path / "r.html"), "--no-pdf", *VN100_MAPPING])
    assert result.exit_code == 0, result.output
    figures = {f["name"]: f for f in json.loads((tmp_path / "r.json").read_text())["figures"]}
    arw = figures["angle_random_walk_deg_per_rt_h"]
    c = np.genfromtxt(VN100, delimiter=",", names=True, usecols=("millis", "GyroZ"))
    s = c["millis"] / 1000.0
    a, b = VN100_AT_REST[2]
    still = np.degrees(c["GyroZ"][(s >= a) & (s < b)]) * 3600.0
    white_dph = np.std(np.diff(still)) / np.sqrt(2.0)
    assert arw["value"] == pytest.approx(white_dph * np.sqrt(0.1) / 60.0, rel=0.05), arw
    stretch_s = float(re.search(r"longest stretch at rest after the settling, (\S+) s",
                                arw["uncertainty_basis"]).group(1))
    assert abs(stretch_s - (b - a)) < 60.0, arw["uncertainty_basis"]
