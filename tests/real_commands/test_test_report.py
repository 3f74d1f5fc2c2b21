"""``hrgtc test-report`` on the real cold test with its calibrated three-axis model: the
manifest names the model and the axis (``file_axis``), the newcomer passes the column mapping
and units only (no ``--temp-ref``: the model file holds the count's map to °C)."""

from __future__ import annotations

import json
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
