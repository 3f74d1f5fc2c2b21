"""The real cold test (``tests/data/pan-cold-test``) calibrated once for the newer commands'
checks on real files: the model a newcomer makes on its first 60 % (the documented
``calibrate`` with ``--temp-ref``, tests/test_against_a_line.py), a three-axis model of a
raw temperature count with the count's map to °C in the file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

DATA = Path(__file__).resolve().parents[1] / "data" / "pan-cold-test"
RUN = DATA / "pan_tvc_cold_2020-03-07.csv"
LOG = DATA / "pan_etu_cold_handlog_2020-03-07.csv"
#: The column mapping and units a newcomer passes to every command (the raw count as it is).
MAPPING = ("--thermometer", "sensor", "--gaps", "bridge", "--time-unit", "ms",
           "--rate-unit", "radps", "--col",
           "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
           "rate_dph_z=gyroz rad/s,temperature_c=temp")
#: °/h per rad/s.
DPH_PER_RADPS = 180.0 / np.pi * 3600.0


@pytest.fixture(scope="session")
def pan_model(tmp_path_factory) -> Path:
    """The cold test's model: calibrated on the first 60 % with the hand log's map."""
    path = tmp_path_factory.mktemp("pan") / "pan.json"
    result = CliRunner().invoke(app, [
        "calibrate", "--drift", str(RUN), *MAPPING, "--temp-ref", str(LOG),
        "--temp-ref-col", "time_s=Time,temperature_c=C1 (C)", "--temp-ref-start", "15:45",
        "--holdout-fraction", "0.4", "-o", str(path)])
    assert result.exit_code == 0, result.output
    return path


def pan_columns() -> dict[str, np.ndarray]:
    """The file by numpy alone: seconds, the rates [°/h] and the signed 16-bit count."""
    table = np.genfromtxt(RUN, delimiter=",", names=True, encoding="utf-8-sig")
    count = np.where(table["temp"] > 32767, table["temp"] - 65536.0, table["temp"])
    out = {"time_s": table["time_ms"] / 1000.0, "count": count}
    out.update({a: table[f"gyro{a}_rads"] * DPH_PER_RADPS for a in "xyz"})
    return out
