"""``hrgtc update`` on real files, with the column mapping and units only.

* The cold test (a chamber cooling; 5 s bursts every 5 min): the update reads the raw count
  through the model file's map to °C (as ``compensate`` does) and is refused for the true
  reason, a ramp (numpy finds the chamber cooling faster than the limit between nearly
  every pair of bursts).
* The VN-100 file (at rest for 1000 s and more at a time, its README): the update must not
  say that the unit moved throughout (the motion detector's still periods were once cut at
  every late record, each piece shorter than a 600 s block).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from hrgtc.cli import app

from .conftest import MAPPING, RUN, pan_columns

VN100 = (Path(__file__).resolve().parents[1] / "data" / "vn100-waves-in-ice"
         / "vn100_F00379-F00383.csv")
VN100_MAPPING = ("--col", "time_s=millis", "--col", "rate_dph_x=GyroX", "--col",
                 "rate_dph_y=GyroY", "--col", "rate_dph_z=GyroZ", "--col", "temperature_c=Temp",
                 "--time-unit", "ms", "--rate-unit", "radps", "--thermometer", "sensor",
                 "--temp-unit", "C")
#: Each burst (5 s) is one still block.
BLOCK = ("--block-s", "4")


def _update(*args: str) -> tuple[int, str]:
    result = CliRunner().invoke(app, ["update", *map(str, args)], terminal_width=200)
    assert "internal error" not in result.output, result.output
    return result.exit_code, " ".join(result.output.split())


def test_a_cooling_chamber_is_refused_as_a_ramp(pan_model, tmp_path):
    found = json.loads(pan_model.read_text())["temperature_map"]
    code, said = _update(pan_model, RUN, *MAPPING, *BLOCK, "--temp-scale",
                         repr(found["scale_c_per_count"]), "--temp-offset",
                         repr(found["offset_c"]), "-o", tmp_path / "pan-2.json")
    assert code == 2, said
    assert "on a temperature ramp" in said and "a ramp posing as ageing" in said, said
    assert not (tmp_path / "pan-2.json").exists()
    # numpy: the temperature's rate between consecutive bursts, against the 2 °C/h limit
    c = pan_columns()
    bursts = np.split(np.arange(c["time_s"].size), np.flatnonzero(np.diff(c["time_s"]) > 1) + 1)
    t = np.array([c["time_s"][b].mean() for b in bursts])
    temperature = np.array([c["count"][b].mean() for b in bursts]) * found["scale_c_per_count"]
    rate_c_per_h = np.abs(np.diff(temperature) / np.diff(t)) * 3600.0
    assert np.mean(rate_c_per_h > 2.0) > 0.8, rate_c_per_h
    # the update's own figure is the fastest block's (a 5 s burst's slope: noisier)
    assert float(said.split("(up to ")[1].split(" °C/h")[0]) > 2.0, said


def test_the_update_reads_the_count_through_the_model_s_map(pan_model, tmp_path):
    code, said = _update(pan_model, RUN, *MAPPING, *BLOCK, "-o", tmp_path / "pan-2.json")
    assert code == 2 and "a ramp posing as ageing" in said, said


def test_a_logger_at_rest_for_an_hour_is_not_said_to_move_throughout(pan_model, tmp_path):
    # any three-axis sensor model will do: the still periods are the file's
    _, said = _update(pan_model, VN100, *VN100_MAPPING, "-o", tmp_path / "vn-2.json")
    assert "moved throughout" not in said, said
