"""Accounting of samples: read, used, dropped and flagged by reason; the 10 % warning."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.core.accounting import REASONS, Accounting
from hrgtc.core.errors import InputError

PAN = Path(__file__).resolve().parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
ARGS = ["--time-unit", "ms", "--thermometer", "sensor", "--rate-unit", "radps", "--col",
        "time_s=time (ms),temperature_c=temp,rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
        "rate_dph_z=gyroz rad/s", "--temp-scale", "0.00587", "--temp-offset", "24.28",
        "--gaps", "bridge"]


def test_counts_used_fraction_and_the_warning_above_ten_percent():
    a = Accounting(read=1000)
    a.drop("warmup", 60)
    a.drop("duplicates", 40)
    a.flag("out_of_range", 7)
    assert a.used == 900 and a.dropped_fraction == pytest.approx(0.10)
    assert a.warning is None  # 10 % exactly is not more than 10 %
    a.drop("warmup", 1)
    assert a.warning.startswith("10% of the samples dropped (most for warm-up")
    text = a.summary().text()
    assert "-- warning:" in text and "7 out of the calibrated range" in text
    assert Accounting.from_dict(json.loads(json.dumps(a.to_dict()))) == a
    other = Accounting(read=10)
    other.drop("spikes", 3)
    a.merge(other)
    assert a.read == 1010 and a.dropped["spikes"] == 3
    with pytest.raises(InputError, match="unknown accounting reason 'mood'"):
        a.drop("mood", 1)
    assert {"warmup", "gap_edges", "motion", "spikes", "out_of_range", "slicing",
            "duplicates"} <= set(REASONS)


def test_start_and_end_slice_every_reading_command_by_seconds():
    runner = CliRunner()
    whole = json.loads(runner.invoke(app, ["info", str(PAN), *ARGS, "--json"]).stdout)
    part = runner.invoke(app, ["info", str(PAN), *ARGS, "--start", "600", "--end", "3600",
                               "--json"])
    assert part.exit_code == 0, part.stderr
    data = json.loads(part.stdout)
    assert data["rows"] == 10 * 250 and data["timeline"]["segments"] == 10
    assert whole["rows"] == 6250
    assert data["start_time_s"] - whole["start_time_s"] >= 600.0
    clock = runner.invoke(app, ["info", str(PAN), *ARGS, "--start", "2020-03-07T16:00"])
    assert clock.exit_code != 0
    assert "no clock times" in " ".join((clock.stderr + clock.stdout).split())
