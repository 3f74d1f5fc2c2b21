"""``hrgtc calibrate``: an output that cannot be written fails before the fit (issue 11); the
input options reach the library as its types (issue 22)."""

from __future__ import annotations

import os
import time

from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.recording import write

from fuzzing import make_run

runner = CliRunner()


def test_unwritable_output_fails_at_once_not_after_the_fit(tmp_path, monkeypatch):
    from hrgtc.core import files

    run = write(make_run(), tmp_path / "run.parquet")
    args = ["calibrate", "--soak", str(run), "--drift", str(run)]
    start = time.perf_counter()
    result = runner.invoke(app, [*args, "-o", str(tmp_path / "missing" / "unit.json")])
    assert result.exit_code == 2
    assert "directory" in result.stderr and "does not exist; create it first" in result.stderr
    real_access = os.access
    monkeypatch.setattr(files.os, "access",
                        lambda path, mode, **k: not mode & os.W_OK and real_access(path, mode))
    result = runner.invoke(app, [*args, "-o", str(tmp_path / "unit.json")])
    assert result.exit_code == 2 and "is not writable" in result.stderr
    assert time.perf_counter() - start < 5.0  # no soak was read, no model fitted


def test_input_options_reach_the_library_as_typed_objects(tmp_path, monkeypatch):
    """``--aux`` (repeated), ``--temp-ref*`` and ``--holdout-*``, generated from
    :class:`~hrgtc.settings.inputs.CalibrationInputs`, reach ``calibrate`` whole, which
    reads them as the aux mapping, one :class:`TemperatureReference` and the holdout; not
    given, the fields' defaults (no channel, no log, no holdout)."""
    import pytest

    from hrgtc.pipeline import calibration
    from hrgtc.pipeline.terms import parse_aux
    from hrgtc.thermometry.reference import TemperatureReference

    seen: list[dict] = []

    def calibrate(soaks, drifts, validate, **kwargs):
        inputs = kwargs["inputs"]
        seen.append({"aux": parse_aux(inputs.aux),
                     "temperature_reference": calibration.temperature_reference(
                         inputs.reference), "holdout_s": inputs.holdout.holdout_s,
                     "holdout_fraction": inputs.holdout.holdout_fraction})
        raise KeyboardInterrupt  # stop before the fit: only the arguments matter

    monkeypatch.setattr(calibration, "calibrate", calibrate)
    log = tmp_path / "hand.csv"
    args = ["calibrate", "--drift", str(tmp_path / "run.csv"), "-o", str(tmp_path / "m.json")]
    runner.invoke(app, [*args, "--aux", "drive=drive_v", "--aux", " quad = quad_v ",
                        "--temp-ref", str(log), "--temp-ref-col", "time_s=Time",
                        "--temp-ref-col", "temperature_c=C1 (C)", "--temp-ref-start", "15:45",
                        "--temp-ref-unit", "F", "--temp-ref-tz", "+01:00",
                        "--temp-ref-lag-s", "0", "--holdout-fraction", "0.25"])
    runner.invoke(app, args)
    runner.invoke(app, [*args, "--holdout-s", "30"])
    given, default, seconds = seen
    assert given["aux"] == {"drive": "drive_v", "quad": "quad_v"}
    assert given["temperature_reference"] == TemperatureReference(
        log, {"time_s": "Time", "temperature_c": "C1 (C)"}, unit="F", start="15:45",
        tz="+01:00", lag_s=0.0)
    assert (given["holdout_s"], given["holdout_fraction"]) == (None, pytest.approx(0.25))
    assert default["aux"] == {} and default["temperature_reference"] is None
    assert (default["holdout_s"], default["holdout_fraction"]) == (None, None)
    assert (seconds["holdout_s"], seconds["holdout_fraction"]) == (30.0, None)
