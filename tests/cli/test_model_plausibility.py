"""Model files that load but cannot be right (issue 21, model side), through the commands.

Each test builds the corruption the independent audit used and asserts the exit code
and what the message must name (the model file, the place in it, the term). Each
failed on the main branch before this work: an absurd coefficient was accepted by
``compensate``, ``report`` and ``export-c`` (outputs near -1e300) and ``evaluate
--json`` ended in a traceback.
"""

from __future__ import annotations

import json
import re

import pytest
from typer.testing import CliRunner

import hrgtc.cli.export_cmd  # noqa: F401  (registers the command)
from hrgtc.cli import app
from hrgtc.model import save_model
from hrgtc.model_schema import derived_coefficients
from hrgtc.recording import write

from fuzzing import make_model, make_run

runner = CliRunner()


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("plausibility")
    model_path = save_model(make_model(), folder / "model.json")
    run_path = write(make_run(rows=3000), folder / "run.parquet")
    return folder, model_path, run_path


def invoke(*args):
    result = runner.invoke(app, [str(a) for a in args])
    return result.exit_code, result.stdout, result.stderr


def squash(text: str) -> str:
    return re.sub(r"\s+", " ", text)


def absurd(model_path, target, where):
    """The model file with one parameter made absurd but finite, consistent, hash line
    removed (the README allows a deliberate edit)."""
    data = json.loads(model_path.read_text())
    drift = data["drift"]
    if where == "intercept":
        drift["intercept_dph"] = 1e308
    else:
        drift["scaled_coefficients"][0] = 1e300
        drift["coefficients"] = derived_coefficients(drift)
    del data["parameters_sha256"]
    target.write_text(json.dumps(data))
    return target


COMMANDS = {
    "compensate": lambda run, model, tmp: ["compensate", run, "-m", model, "-o",
                                           tmp / "out.parquet", "--json"],
    "evaluate": lambda run, model, tmp: ["evaluate", run, "-m", model, "--json"],
    "report": lambda run, model, tmp: ["report", run, "-m", model, "-o", tmp / "r.html"],
    "export-c": lambda run, model, tmp: ["export-c", model, "-o", tmp / "c"],
    "export-params": lambda run, model, tmp: ["export-c", model, "-o", tmp / "p",
                                              "--format", "params"],
}


@pytest.mark.parametrize("where", ["coefficient", "intercept"])
@pytest.mark.parametrize("command", list(COMMANDS))
def test_an_absurd_coefficient_is_refused_at_load(files, tmp_path, command, where):
    _, model_path, run_path = files
    broken = absurd(model_path, tmp_path / "absurd.json", where)
    code, stdout, stderr = invoke(*COMMANDS[command](run_path, broken, tmp_path))
    message = squash(stderr)
    assert code == 2, (stdout, stderr)
    assert "Traceback" not in stdout + stderr and "internal error" not in message
    assert "absurd.json: model file is invalid at drift." in message
    if where == "intercept":
        assert "drift.intercept_dph: 1e+308 °/h is beyond any gyro's bias" in message
    else:
        term = json.loads(broken.read_text())["drift"]["selected"][0]
        assert f"drift.scaled_coefficients[0]: term {term} gives a bias of" in message
    assert not (tmp_path / "out.parquet").exists() and not (tmp_path / "c").exists()


def test_a_model_just_inside_the_bound_still_loads(files, tmp_path):
    """The bound is a bias no gyro has (10,000 °/s), not a tight guess: a 4 °/s MEMS offset
    (14,400 °/h) as the intercept is a model like any other."""
    from hrgtc.model import load_model

    _, model_path, _ = files
    data = json.loads(model_path.read_text())
    data["drift"]["intercept_dph"] = 14_400.0
    del data["parameters_sha256"]
    (tmp_path / "mems.json").write_text(json.dumps(data))
    assert load_model(tmp_path / "mems.json").drift.intercept_dph == 14_400.0


def test_json_output_is_strict_even_with_figures_that_are_not_finite(capsys):
    """print_json never raises on inf/NaN (the evaluate --json traceback) and turns numpy
    scalars into numbers."""
    import math

    import numpy as np

    from hrgtc.cli._app import print_json

    print_json({"a": math.inf, "b": [np.float64(1.5), np.nan], "c": np.int64(3)})
    assert json.loads(capsys.readouterr().out) == {"a": None, "b": [1.5, None], "c": 3}


# -- a model of the other kind of thermometer --------------------------------------------------
@pytest.fixture(scope="module")
def sensor_model_path(tmp_path_factory):
    """A genuine sensor-thermometer model: the identity thermometer, drift trained on a run
    whose freq_hz column holds the resonator temperature (what --thermometer sensor reads)."""
    import numpy as np

    from hrgtc import drift
    from hrgtc.model import UnitModel
    from hrgtc.thermometry.sensor import identity

    from synthetic import ramp_run

    run = ramp_run(seed=11, hours=3.0)
    rng = np.random.default_rng(0)
    reading = run.with_columns(freq_hz=run["resonator_c"] + rng.normal(0.0, 0.01, len(run)))
    thermometer = identity((-20.0, 40.0))
    model = UnitModel(thermometer=thermometer, drift=drift.fit([reading], thermometer),
                      unit="MEMS-1")
    return save_model(model, tmp_path_factory.mktemp("sensor") / "sensor.json")


@pytest.mark.parametrize("command", ["compensate", "evaluate", "report"])
def test_a_sensor_model_on_a_frequency_recording_says_it_is_a_sensor_model(
        files, sensor_model_path, tmp_path, command):
    _, _, run_path = files
    code, stdout, stderr = invoke(*COMMANDS[command](run_path, sensor_model_path, tmp_path))
    message = squash(stderr)
    assert code == 2, (stdout, stderr)
    assert "is a sensor-thermometer model" in message
    assert "pass --thermometer sensor" in message
    assert "calibrated span" not in message


def test_a_resonator_model_read_as_a_sensor_recording_says_so(files, tmp_path):
    _, model_path, run_path = files
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o",
                             tmp_path / "out.parquet", "--thermometer", "sensor")
    message = squash(stderr)
    assert code == 2
    assert "is a resonator-thermometer model" in message and "drop --thermometer sensor" in \
        message
