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

from hrgtc.cli import app
from hrgtc.model import AxisModel, save_model
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
    from hrgtc.model import Model
    from hrgtc.thermometry.sensor import identity

    from synthetic import ramp_run

    run = ramp_run(seed=11, hours=3.0)
    rng = np.random.default_rng(0)
    reading = run.with_columns(freq_hz=run["resonator_c"] + rng.normal(0.0, 0.01, len(run)))
    thermometer = identity((-20.0, 40.0))
    model = Model.single(
        AxisModel(thermometer=thermometer, drift=drift.fit([reading], thermometer)), unit="MEMS-1")
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


# -- axis sets: a model and a recording with different axes ------------------------------------
@pytest.fixture(scope="module")
def axis_files(tmp_path_factory):
    """A three-axis recording (x, y, z: the same run on each axis), a two-axis model (x, y)
    and a single-axis model."""
    from hrgtc.model import Model, save_model
    from hrgtc.recording import Recording

    folder = tmp_path_factory.mktemp("axes")
    unit = make_model()
    run = make_run(rows=3000)
    columns = {"time_s": run.time_s}
    for axis in "xyz":
        columns[f"freq_hz_{axis}"] = run.freq_hz
        columns[f"rate_dph_{axis}"] = run.rate_dph
    xyz = write(Recording(columns, run.metadata), folder / "xyz.parquet")
    xy = save_model(Model({"x": unit.axis, "y": unit.axis}, "imu"), folder / "xy.json")
    single = save_model(unit, folder / "single.json")
    return folder, xyz, xy, single


@pytest.mark.parametrize("command", ["compensate", "evaluate", "report"])
@pytest.mark.parametrize("which", ["xy", "single"])
def test_an_axis_mismatch_is_an_error_naming_the_axes_and_the_option(axis_files, tmp_path,
                                                                     command, which):
    """Issue 21: a model with fewer axes than the recording compensated only its own axes
    without a word (exit 0); a single-axis model on a 3-axis file said 'column freq_hz not
    found'."""
    _, xyz, xy, single = axis_files
    model = xy if which == "xy" else single
    code, stdout, stderr = invoke(*COMMANDS[command](xyz, model, tmp_path))
    message = squash(stderr)
    assert code == 2, (stdout, stderr)
    assert "has axes x, y, z" in message
    if which == "xy":
        assert "axis z of the recording would be left uncompensated" in message
        assert "pass --axes x,y" in message
    else:
        assert "is single-axis: pass --axes x (one of x, y, z)" in message
    assert not (tmp_path / "out.parquet").exists()


def test_axes_says_which_to_compensate(axis_files, tmp_path):
    import pyarrow.parquet as pq

    from hrgtc.compensate import Compensator
    from hrgtc.recording import read

    _, xyz, xy, single = axis_files
    code, _, stderr = invoke("compensate", xyz, "-m", xy, "-o", tmp_path / "xy.parquet",
                             "--axes", "x,y")
    assert code == 0, stderr
    names = pq.read_schema(tmp_path / "xy.parquet").names
    assert "rate_comp_dph_x" in names and "rate_comp_dph_y" in names
    assert not any(n.endswith("_z") and n.startswith(("rate_comp", "in_range")) for n in names)
    # a single-axis model on one named axis: that axis's outputs, equal to compensating its
    # own single-axis file
    code, _, stderr = invoke("compensate", xyz, "-m", single, "-o", tmp_path / "z.parquet",
                             "--axes", "z")
    assert code == 0, stderr
    out = read(tmp_path / "z.parquet")
    expected = Compensator(make_model()).transform(make_run(rows=3000))
    np_equal = (out["rate_comp_dph_z"] == expected["rate_comp_dph"]).all()
    assert np_equal and "rate_comp_dph_x" not in out
    code, _, stderr = invoke("evaluate", xyz, "-m", single, "--axes", "y", "--json")
    assert code == 0, stderr
    code, _, stderr = invoke("report", xyz, "-m", xy, "--axes", "x,y", "-o", tmp_path / "r.html")
    assert code == 0, stderr


def test_the_report_s_library_call_checks_the_axes_itself(axis_files, sensor_model_path,
                                                         files, tmp_path):
    """``build_report`` matches the model's axes to each run and checks the thermometer
    kind before reading (the command used to do it before the call): an in-memory model
    gets the command's refusals, and ``axes`` picks the axes to show."""
    from hrgtc.core.errors import InputError
    from hrgtc.model import load_model
    from hrgtc.report import build_report
    from hrgtc.settings.compensation import ReportSettings

    _, xyz, xy, _ = axis_files
    model = load_model(xy)
    with pytest.raises(InputError, match="pass --axes x,y"):
        build_report(model, [xyz], tmp_path / "r.html")
    assert not (tmp_path / "r.html").exists()
    page = build_report(model, [xyz], tmp_path / "r.html", ReportSettings(axes=("x",))).read_text()
    assert 'id="axis-x"' in page and 'id="axis-y"' not in page  # the x axis alone
    with pytest.raises(InputError, match="is a sensor-thermometer model"):
        build_report(load_model(sensor_model_path), [files[2]], tmp_path / "s.html")


@pytest.mark.parametrize("axes, match", [
    ("x,w", "has no axis w"),
    ("z", "the model .*xy.json has no axis z"),
    ("x_1", "'x_1' is not an axis name"),
])
def test_wrong_axes_are_named(axis_files, axes, match):
    _, xyz, xy, _ = axis_files
    code, _, stderr = invoke("evaluate", xyz, "-m", xy, "--axes", axes)
    assert code == 2
    assert re.search(match, squash(stderr)), stderr


def test_a_model_with_more_axes_than_the_recording(axis_files, tmp_path):
    from hrgtc.model import Model, save_model

    _, xyz, _, _ = axis_files
    unit = make_model()
    xyzw = save_model(Model({a: unit.axis for a in "xyzw"}, "imu4"),
                           tmp_path / "xyzw.json")
    code, _, stderr = invoke("compensate", xyz, "-m", xyzw, "-o", tmp_path / "o.parquet")
    message = squash(stderr)
    assert code == 2
    assert "the model's axis w is not in the recording; pass --axes x,y,z" in message
    code, _, stderr = invoke("compensate", xyz, "-m", xyzw, "-o", tmp_path / "o.parquet",
                             "--axes", "x,y,z")
    assert code == 0, stderr


@pytest.mark.parametrize("command", ["compensate", "evaluate", "report"])
def test_a_header_less_multi_axis_csv_says_it_has_no_header_line(axis_files, tmp_path,
                                                                  command):
    """A 3-axis CSV whose header line is gone read as a single-axis file against a 3-axis
    model ("the recording is single-axis (freq_hz, rate_dph) and the model has axes x, y,
    z"): the axis mismatch is not the problem, the missing header is."""
    from hrgtc.model import Model, save_model
    from hrgtc.recording import read

    _, xyz, _, _ = axis_files
    unit = make_model()
    model = save_model(Model({a: unit.axis for a in "xyz"}, "imu"),
                            tmp_path / "xyz.json")
    csv = write(read(xyz), tmp_path / "xyz.csv")
    lines = csv.read_text().split("\n")
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    csv.write_text("\n".join(lines[:header] + lines[header + 1:]))
    code, stdout, stderr = invoke(*COMMANDS[command](csv, model, tmp_path))
    message = squash(stderr)
    assert code == 2, (stdout, stderr)
    assert "no header line" in message and "--col" in message
    assert "single-axis" not in message


# -- the recording's noise against the training data's (Deliver 2) ------------------------------
@pytest.fixture(scope="module")
def checked_model(tmp_path_factory):
    """make_model() with the statistics of its training run, as calibrate records them."""

    from hrgtc.drift.training import TrainingStatistics

    from synthetic import ramp_run

    model = make_model().with_parts(training=TrainingStatistics.from_runs(
        [ramp_run(seed=11, hours=3.0)]))
    return save_model(model, tmp_path_factory.mktemp("checked") / "checked.json")


@pytest.mark.parametrize("command", ["compensate", "evaluate", "report"])
def test_rate_unit_dps_on_degrees_per_hour_is_refused(checked_model, tmp_path, command):
    """The issue's case: --rate-unit dps on °/h data (every value × 3600) passed validation
    and was compensated (exit 0)."""
    run_path = write(make_run(rows=3000), tmp_path / "run.csv")
    args = [*COMMANDS[command](run_path, checked_model, tmp_path), "--rate-unit", "dps"]
    code, stdout, stderr = invoke(*args)
    message = squash(stderr)
    assert code == 2, (stdout, stderr)
    assert "run.csv: column 'rate_dph': its noise" in message
    assert "near the unit factor 3600" in message and "--rate-unit dps on a rate in °/h" in \
        message
    assert not (tmp_path / "out.parquet").exists()


@pytest.mark.parametrize("offset_dph", [360_000.0, 14_400.0])
def test_a_rate_table_run_and_a_biased_mems_file_are_accepted(checked_model, tmp_path,
                                                              offset_dph):
    """100 °/s on a rate table, or a 4 °/s offset, against a model trained at rest: another
    level, the same noise."""
    run = make_run(rows=3000)
    run_path = write(run.with_columns(rate_dph=run.rate_dph + offset_dph),
                     tmp_path / "level.parquet")
    code, _, stderr = invoke("compensate", run_path, "-m", checked_model, "-o",
                                  tmp_path / "out.parquet", "--json")
    assert code == 0, stderr
    assert "note:" not in stderr  # the model has statistics: the check ran
    code, _, stderr = invoke("evaluate", run_path, "-m", checked_model, "--json")
    assert code == 0, stderr


def _with_temperature(axes: str):
    """make_run's rows with the resonator temperature as ``temperature_c``, on one axis or
    on x, y, z (one shared temperature)."""
    from hrgtc.recording import Recording

    from synthetic import ramp_run

    run = ramp_run(seed=3, start_c=10.0, end_c=5.0, hours=3000 / 36000.0)
    columns = {"time_s": run["time_s"]}
    for suffix in ([""] if axes == "1" else ["_x", "_y", "_z"]):
        columns |= {f"freq_hz{suffix}": run["freq_hz"], f"rate_dph{suffix}": run["rate_dph"]}
    columns["temperature_c"] = run["resonator_c"]
    return Recording(columns, run.metadata)


@pytest.mark.parametrize("axes", ["1", "3"])
@pytest.mark.parametrize("command", ["compensate", "evaluate", "report"])
def test_swapped_rate_and_temperature_headers_are_named(checked_model, tmp_path, command,
                                                        axes):
    """Issue 21's audit: with the headers rate_dph and temperature_c swapped, a temperature
    was compensated as the rate (exit 0): its noise, 5e-5 of the training rate's, is no
    unit factor. The temperature column has the rate's noise: the swap is named."""
    from hrgtc.model import Model, load_model, save_model
    from hrgtc.recording import Recording

    run = _with_temperature(axes)
    rate = "rate_dph" if axes == "1" else "rate_dph_x"
    swapped = {({rate: "temperature_c", "temperature_c": rate}).get(k, k): run[k]
               for k in run.names}
    run_path = write(Recording(swapped, run.metadata), tmp_path / "swapped.parquet")
    model = checked_model
    if axes == "3":
        unit = load_model(checked_model)
        model = save_model(Model({a: unit.axis for a in "xyz"}, "imu"),
                                tmp_path / "xyz.json")
    code, stdout, stderr = invoke(*COMMANDS[command](run_path, model, tmp_path))
    message = squash(stderr)
    assert code == 2, (stdout, stderr)
    assert "swapped.parquet" in message
    assert f"headers {rate} and temperature_c look swapped" in message
    # the undamaged file passes
    good = write(run, tmp_path / "good.parquet")
    code, _, stderr = invoke(*COMMANDS[command](good, model, tmp_path), "--force")
    assert code == 0, stderr


def test_an_older_model_without_statistics_loads_and_says_so_once(files, tmp_path):
    _, model_path, run_path = files
    data = json.loads(model_path.read_text())
    data.pop("training")  # a file written before the statistics were recorded
    data.pop("parameters_sha256")  # the hash may be removed (it covers the statistics)
    model_path = tmp_path / "older.json"
    model_path.write_text(json.dumps(data))
    code, _, stderr = invoke("compensate", run_path, "-m", model_path, "-o",
                             tmp_path / "out.parquet", "--json")
    assert code == 0, stderr
    assert squash(stderr).count("has no statistics of its training data") == 1
