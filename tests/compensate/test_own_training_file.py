"""A model applied to its own training file (issue 20): nothing it trained on is out of range.

Two defects a new-user test found on the PAN cold test (``--rate-tau-s 310``: 28 % of its
own training file flagged beyond the trained temperature and df/dt):

* the warm-up samples (flagged ``warmup``) were counted again as out of range;
* the trained ranges were the extremes of 10 s window means, narrower than the samples
  the model was fitted on (and, by round-off, a sample at the very minimum fell outside).

The trained range is the extremes of the samples training used, and a sample of the
filter's settling time is flagged by that reason only, so on its own training file a
model flags no sample out of range at all (beyond its warm-up and spikes).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc import drift
from hrgtc.cli import app
from hrgtc.compensate import Compensator
from hrgtc.drift.features import FeatureStream
from hrgtc.model import AxisModel, Model
from hrgtc.simulate import cooldown
from hrgtc.simulate.logged_files import write_logged
from hrgtc.simulate.logger import Logger, log_run
from hrgtc.simulate.reflog import TemperatureChannel

from synthetic import THERMOMETER, ramp_run

runner = CliRunner()
DATA = Path(__file__).parents[1] / "data" / "pan-cold-test"
RUN = DATA / "pan_tvc_cold_2020-03-07.csv"
LOG = DATA / "pan_etu_cold_handlog_2020-03-07.csv"
COLD = ["--thermometer", "sensor", "--gaps", "bridge", "--time-unit", "ms",
        "--rate-unit", "radps",
        "--col", "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
        "rate_dph_z=gyroz rad/s,temperature_c=temp"]


def _cli(*args: str) -> dict:
    result = runner.invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.stderr + result.stdout
    text = result.stdout
    return json.loads(text[text.index("{"):])


def _own_file(path: Path, options: list[str], calibrate: list[str], directory: Path) -> dict:
    model = directory / "own.json"
    _cli("calibrate", "--drift", str(path), *options, *calibrate, "-o", str(model))
    report = _cli("compensate", str(path), "-m", str(model), *options,
                  "-o", str(directory / "own.parquet"))
    document = json.loads(model.read_text())
    warmups = {axis: entry["drift"]["settings"]["warmup_s"]
               for axis, entry in document.get("axes", {"": document}).items()}
    for axis, entry in (report.get("axes") or {"": report}).items():
        entry["warmup_s"] = warmups.get(axis, max(warmups.values()))
    report["warmup_s"] = max(warmups.values())
    return report


def _assert_inside(report: dict) -> None:
    """Nothing out of range; the warm-up counted once, under its own reason (none when the
    model has no rate term, warmup_s 0: no filter to wait for)."""
    flagged = report["accounting"]["flagged"]
    ranges = report["ranges"]
    assert (flagged.get("warmup", 0) > 0) == (report["warmup_s"] > 0), flagged
    assert ranges["settling_fraction"] == pytest.approx(flagged.get("warmup", 0)
                                                        / ranges["samples"])
    assert report["out_of_range_fraction"] == 0.0, ranges
    assert report["rate_out_of_range_fraction"] == 0.0, ranges
    assert "out_of_range" not in flagged and "rate_out_of_range" not in flagged, flagged
    # the seen extremes are those of the settled samples: inside the trained ones
    assert ranges["trained_c"][0] <= ranges["seen_c"][0] <= ranges["seen_c"][1] \
        <= ranges["trained_c"][1], ranges


def test_cold_test_model_flags_nothing_of_its_own_training_file(tmp_path):
    """The PAN cold test with the new user's ``--rate-tau-s 310`` (was 28.0 % and 28.0 %:
    the 1500 warm-up rows again, and 250 beyond the window means' extremes)."""
    report = _own_file(RUN, COLD, ["--temp-ref", str(LOG), "--temp-ref-col",
                                   "time_s=Time,temperature_c=C1 (C)",
                                   "--temp-ref-start", "15:45", "--rate-tau-s", "310"], tmp_path)
    assert report["accounting"]["flagged"].get("warmup", 0) == (
        1500 if report["warmup_s"] > 0 else 0)
    _assert_inside(report)


@pytest.mark.parametrize(("kind", "time_unit", "decimals"), [
    ("burst", "ms", 3),  # was 1.9 % and 2.5 %
    ("continuous", "us", 2),  # many samples exactly at the coldest 0.01 °C step
])
def test_logger_model_flags_nothing_of_its_own_training_file(tmp_path, kind, time_unit,
                                                             decimals):
    """A simulated logger (bursts of 5 s every 60 s, or continuous, at 10 Hz, rad/s) on a
    cool-down: the temperature logged in steps, so the coldest step holds many samples at
    exactly the trained minimum (a round-off below it flagged them, issue 20)."""
    logger = Logger(kind=kind, sample_rate_hz=10.0, burst_s=5.0, period_s=60.0,
                    time_unit=time_unit, rate_unit="radps", frequency=False,
                    temperature=TemperatureChannel(decimals=decimals, noise_c=0.005))
    run = log_run(cooldown(22.0, 5.0, hours=2.0, ramp_c_per_min=0.15), "mems-3", logger,
                  seed=11)
    files = write_logged(run, tmp_path / f"{kind}.csv")
    report = _own_file(Path(files.path), run.info["hrgtc_options"], [], tmp_path)
    for axis in report["axes"].values() if "axes" in report else [report]:
        _assert_inside(axis)


@pytest.mark.parametrize("seed", [1, 2])
def test_trained_ranges_are_the_extremes_of_the_used_samples(seed):
    """f's and df's ranges are the extremes of the samples after the warm-up (not of window
    means), so the model's own run is inside them to the last bit, in both engines."""
    run = ramp_run(seed=seed)
    model = Model.single(AxisModel(thermometer=THERMOMETER, drift=drift.fit([run], THERMOMETER)))
    fitted = model.drift
    values = FeatureStream(fitted.settings, ("f", "df")).transform(run)
    used = run.time_s - run.time_s[0] >= fitted.settings.warmup_s
    for v in ("f", "df"):
        assert fitted.ranges[v] == (float(values[v][used].min()), float(values[v][used].max()))
    for engine in ("fused", "numpy"):
        compensator = Compensator(model, engine=engine)
        out = compensator.transform(run)
        assert compensator.axis.out_of_range == 0, engine
        assert compensator.axis.rate_out_of_range == 0, engine
        assert compensator.axis.settling == int(np.count_nonzero(~used))
        assert np.array_equal(out["in_range"] == 1.0, used), engine
