"""Tests of hrgtc.export.parameter_file: the plain key = value export, read back.

The file is parsed by a small parser written here (not hrgtc's), the compensation is
evaluated from the parsed numbers alone with plain numpy, following the formula the
file's header states, and compared with :class:`hrgtc.compensate.Compensator` on a
run the model was not trained on (partly beyond its ranges: the tangent continuation).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from scipy import signal

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.core.errors import InputError, OutputExistsError
from hrgtc.export.export_c import export_c
from hrgtc.model import AxisModel, Model
from hrgtc.thermometry import paper

from synthetic import THERMOMETER, ramp_run, scale_factor, with_scale_factor


def parse(text: str) -> dict[str, float | str]:
    """key = value lines; # comments and blank lines skipped; numbers as floats."""
    out: dict[str, float | str] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        key, sep, value = line.partition("=")
        assert sep, f"line {number} is not key = value: {line!r}"
        key, value = key.strip(), value.strip()
        assert re.fullmatch(r"[a-z][a-z0-9_]*", key), key
        assert key not in out, f"{key} twice"
        try:
            out[key] = float(value)
        except ValueError:
            out[key] = value
    return out


def rate_of(x, p, time_s, prefix=""):
    """The header's step 2, sample by sample in plain Python floats (each step its own dt)."""
    tau = p[prefix + "rate_tau_s"]
    y1 = y2 = x[0]
    out = np.empty_like(x)
    out[0] = 0.0
    for i in range(1, len(x)):
        r = (time_s[i] - time_s[i - 1]) / tau
        a = -math.expm1(-r)
        weight = (sum((-1.0) ** (k + 1) * r ** k / math.factorial(k + 1) for k in range(1, 10))
                  if r < 0.1 else 1.0 - a / r)
        new_y1 = y1 + a * (x[i - 1] - y1) + weight * (x[i] - x[i - 1])
        y2 = y2 + a * (y1 - y2) + weight * (new_y1 - y1)
        y1 = new_y1
        out[i] = (y1 - y2) / tau
    return out


def factors(spelling: str):
    """'f^2*df' -> [('f', 2), ('df', 1)]."""
    out = []
    for part in spelling.split("*"):
        name, _, power = part.partition("^")
        out.append((name, int(power) if power else 1))
    return out


def bias_from(p, values):
    """The header's steps 3 and 4: held variables, scaled terms, tangent beyond the ranges."""
    n = int(p["n_terms"])
    terms = [(p[f"coefficient_{k}"], factors(p[f"term_{k}"])) for k in range(1, n + 1)]
    used = {v for _, fs in terms for v, _ in fs}
    held = {v: np.clip(values[v], p[f"range_{v}_low"], p[f"range_{v}_high"]) for v in used}
    x = {v: held[v] / p[f"scale_{v}"] for v in used}
    bias = np.full(values["f"].shape, p["intercept_dph"])
    for c, fs in terms:
        bias = bias + c * np.prod([x[v] ** q for v, q in fs], axis=0)
    for v in used:
        gradient = np.zeros_like(bias)
        for c, fs in terms:
            power = dict(fs).get(v, 0)
            if power:
                rest = [x[w] ** (q - (w == v)) for w, q in fs]
                gradient = gradient + c * power * np.prod(rest, axis=0) / p[f"scale_{v}"]
        bias = bias + gradient * (values[v] - held[v])
    return bias


def temperature_from(p, freq_hz):
    """The header's step 6: Newton's iteration on F(T) in z, from the interval's middle."""
    order = int(p["thermometer_order"])
    a = np.array([p[f"thermometer_coefficient_{j}"] for j in range(order + 1)])
    centre, scale = p["thermometer_centre_c"], p["thermometer_scale_c"]
    t = np.full(freq_hz.shape, 0.5 * (p["inverse_low_c"] + p["inverse_high_c"]))
    for _ in range(int(p["inverse_max_iterations"])):
        z = (t - centre) / scale
        value = np.polynomial.polynomial.polyval(z, a)
        slope = np.polynomial.polynomial.polyval(z, a[1:] * np.arange(1, order + 1)) / scale
        t = t - (value - freq_hz) / slope
    inside = (freq_hz >= p["inverse_freq_low_hz"]) & (freq_hz <= p["inverse_freq_high_hz"])
    return np.where(inside, t, np.nan)


def housing_run(seed, **kwargs):
    run = ramp_run(seed, **kwargs)
    chamber = run["chamber_c"]
    a = -np.expm1(-1.0 / (900.0 * run.sample_rate_hz))
    housing = signal.lfilter([a], [1.0, a - 1.0], chamber, zi=[(1.0 - a) * chamber[0]])[0]
    extra = 0.3 * (housing - 20.0) + 4000.0 * (chamber - housing) / 900.0
    return run.with_columns(housing_c=housing, rate_dph=run.rate_dph + extra)


@pytest.mark.parametrize("kind", ["frequency", "housing"])
def test_parameters_evaluated_by_hand_equal_the_compensator(kind, tmp_path):
    if kind == "housing":
        fitted = drift.fit([housing_run(seed=3)], THERMOMETER,
                           terms=("f", "f^2", "df", "h", "dh", "f*dh", "f^2*dh"))
        recording = housing_run(seed=8, start_c=25.0, end_c=-25.0, hours=3.0)
    else:
        fitted = drift.fit([ramp_run(seed=1)], THERMOMETER)
        recording = ramp_run(seed=7, start_c=25.0, end_c=-25.0, hours=3.0)
    model = Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted), unit="u1")
    (path,) = export_c(model, tmp_path, prefix="u1", output_format="params")
    assert path.name == "u1_params.txt"
    text = path.read_text()
    p = parse(text)

    # every key documented: a comment line right above it
    lines = text.splitlines()
    for k, line in enumerate(lines):
        if line and not line.startswith("#"):
            assert lines[k - 1].startswith("# "), f"{line!r} has no comment above it"
    assert p["uses_housing"] == float(kind == "housing")
    assert p["n_terms"] == len(fitted.selected)
    assert [p[f"term_{k}"] for k in range(1, len(fitted.selected) + 1)] == list(fitted.selected)

    expected = Compensator(model).transform(recording)
    values = {"f": recording.freq_hz - p["reference_freq_hz"]}
    values["df"] = rate_of(values["f"], p, recording.time_s)
    if kind == "housing":
        values["h"] = recording["housing_c"] - p["reference_c"]
        values["dh"] = rate_of(values["h"], p, recording.time_s)
    bias = bias_from(p, values)
    beyond = values["f"] > p["range_f_high"]
    assert 0.01 < beyond.mean() < 0.5  # the tangent continuation is exercised
    np.testing.assert_allclose(bias, expected["bias_model_dph"], rtol=1e-12,
                               atol=1e-12 * np.max(np.abs(bias)))
    np.testing.assert_allclose(recording.rate_dph - bias, expected["rate_comp_dph"], rtol=1e-12,
                               atol=1e-12 * np.max(np.abs(recording.rate_dph)))
    temperature = temperature_from(p, recording.freq_hz)
    np.testing.assert_allclose(temperature, expected["resonator_c_est"], rtol=0, atol=1e-9)

    # the raw (Eq. 22) coefficients give the same bias inside the ranges
    raw = np.full(bias.shape, p["intercept_dph"])
    for k in range(1, int(p["n_terms"]) + 1):
        raw += p[f"coefficient_raw_{k}"] * np.prod(
            [values[v] ** q for v, q in factors(p[f"term_{k}"])], axis=0)
    inside = expected["in_range"] == 1.0
    np.testing.assert_allclose(raw[inside], bias[inside], rtol=1e-9, atol=1e-9)


def test_parameter_thermometer_gives_table2(tmp_path):
    model = Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([ramp_run(seed=1)], THERMOMETER)))
    (path,) = export_c(model, tmp_path, output_format="params")
    p = parse(path.read_text())
    # Table 2 of [1], printed to 3 decimals
    np.testing.assert_allclose(temperature_from(p, paper.TABLE2_FREQUENCY_HZ),
                               paper.TABLE2_CALCULATED_C, rtol=0, atol=1e-3)
    order = int(p["thermometer_order"])
    raw = [p[f"thermometer_raw_coefficient_{j}"] for j in range(order + 1)]
    # f_ref is the thermometer at the model's reference (the training data's centre)
    reference_c = model.drift.settings.reference_c
    np.testing.assert_allclose(np.polynomial.polynomial.polyval(reference_c, raw),
                               p["reference_freq_hz"], rtol=1e-12)
    assert p["format_version"] == 1.0
    with pytest.raises(OutputExistsError, match=r"hrgtc_params\.txt"):
        export_c(model, tmp_path, output_format="params")
    with pytest.raises(InputError, match="format 'json' is not one of c, params"):
        export_c(model, tmp_path, output_format="json")
    # the library refuses what the command refuses (it used to write doubles silently)
    with pytest.raises(InputError, match="--precision applies to --format c only"):
        export_c(model, tmp_path / "single", output_format="params", precision="single")
    assert not (tmp_path / "single").exists()


def scale_from(p, freq_hz):
    """The header's step 5 with the scale factor: k(g), tangent beyond the range."""
    g = freq_hz - p["sf_reference_hz"]
    low = p["sf_range_low_hz"] - p["sf_reference_hz"]
    high = p["sf_range_high_hz"] - p["sf_reference_hz"]
    held = np.clip(g, low, high)
    x = held / p["sf_scale_hz"]
    k = np.full(g.shape, p["sf_intercept_ppm"])
    gradient = np.zeros_like(g)
    for j in range(1, int(p["sf_n_terms"]) + 1):
        ((name, power),) = factors(p[f"sf_term_{j}"])
        assert name == "f"
        k = k + p[f"sf_coefficient_{j}"] * x**power
        gradient = gradient + p[f"sf_coefficient_{j}"] * power * x ** (power - 1) / p[
            "sf_scale_hz"]
    return k + gradient * (g - held)


def test_parameters_with_a_scale_factor(tmp_path):
    fitted = drift.fit([ramp_run(seed=1)], THERMOMETER)
    sf = scale_factor(fitted.settings.reference_freq_hz + 0.5)
    model = with_scale_factor(Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted)), sf)
    (path,) = export_c(model, tmp_path, output_format="params")
    p = parse(path.read_text())
    assert p["uses_scale_factor"] == 1.0
    recording = ramp_run(seed=7, start_c=25.0, end_c=-25.0, hours=3.0, input_rate_dph=3.6e5)
    k = scale_from(p, recording.freq_hz)
    np.testing.assert_allclose(k, sf.ppm(recording.freq_hz), rtol=1e-12, atol=1e-12 * 150)
    values = {"f": recording.freq_hz - p["reference_freq_hz"]}
    values["df"] = rate_of(values["f"], p, recording.time_s)
    bias = bias_from(p, values)
    expected_bias = Compensator(model).transform(recording)["bias_model_dph"]
    np.testing.assert_allclose(bias, expected_bias, rtol=1e-12, atol=1e-12 * 100)
    # the contract's law, from the library's own pieces
    np.testing.assert_allclose((recording.rate_dph - bias) / (1 + 1e-6 * k),
                               (recording.rate_dph - expected_bias) / (1 + 1e-6 * sf.ppm(
                                   recording.freq_hz)), rtol=1e-12)
    plain = parse(export_c(Model.single(
        AxisModel(thermometer=THERMOMETER, drift=fitted)), tmp_path / "plain",
                           output_format="params")[0].read_text())
    assert plain["uses_scale_factor"] == 0.0 and "sf_intercept_ppm" not in plain


def test_params_export_of_every_model_the_demo_writes(paper_campaign, imu_campaign, tmp_path):
    """Issue 21: ``export-c --format params`` failed with KeyError 'g' on every model whose
    runs log housing_c. The demo's two models, calibrated as :mod:`hrgtc.pipeline.demo` does
    (default
    terms), on the shared simulated campaigns, exported through the CLI."""
    import warnings

    from typer.testing import CliRunner

    from hrgtc.cli import app
    from hrgtc.core.errors import HrgtcWarning
    from hrgtc.model import save_model
    from hrgtc.pipeline.calibration import RateTables, calibrate

    files = paper_campaign
    unit = calibrate(files.soaks, [files.cooldown]).model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HrgtcWarning)
        imu = imu_campaign
        instrument = calibrate(imu.soaks, [imu.cooldown], [imu.warmup],
                               rate_tables=RateTables([imu.rate_table],
                                                      [imu.rate_table_heldout])).model
    paths = [save_model(unit, tmp_path / "paper-unit.json"),
             save_model(instrument, tmp_path / "imu-3.json")]
    used = set(unit.drift.variables).union(*(a.drift.variables for a in instrument.axes.values()))
    # calibration records its training data's statistics, per axis (issue 21, Deliver 2)
    for model in (unit, *instrument.axes.values()):
        assert model.training is not None and model.training.rate_noise_dph > 0.0
    assert "g" in used  # the housing gradient the demo's runs give: the variable that crashed
    for path in paths:
        done = CliRunner().invoke(app, ["export-c", str(path), "-o", str(tmp_path / path.stem),
                                        "--format", "params"])
        assert done.exit_code == 0, done.output
        p = parse((tmp_path / path.stem / "hrgtc_params.txt").read_text())
        keys = [k for k in p if k.endswith("range_g_high")]
        assert keys, "the gradient's range is written"


def test_exports_say_the_orientation_offsets_they_do_not_apply(tmp_path):
    """A model fitted with --offsets orientation (a MEMS unit turned between still
    periods): compensate adds each sample's orientation offset (from its accelerometer),
    the C code and the parameter file apply none, and said nothing of it (a firmware
    user lost up to 400 °/h in silence on the fridge-3day logger)."""
    import dataclasses
    from pathlib import Path

    from typer.testing import CliRunner

    from hrgtc.cli import app
    from hrgtc.model import load_model, save_model

    golden = (Path(__file__).parents[1] / "data" / "golden-models" / "v2"
              / "unit-sensor-thermometer-ee60050.json")
    model = load_model(golden)
    offsets = {"orientation 0": 136.5, "orientation 1": -96.9, "orientation 2": -399.6}
    turned = model.with_parts(drift=dataclasses.replace(
        model.drift, offset_mode="orientation", offsets_dph=offsets,
        orientations=((0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0))))
    path = save_model(turned, tmp_path / "turned.json")
    for fmt, name in (("c", "hrgtc_model.h"), ("params", "hrgtc_params.txt")):
        done = CliRunner().invoke(app, ["export-c", str(path), "--format", fmt,
                                        "-o", str(tmp_path / fmt)])
        assert done.exit_code == 0, done.output
        text = (tmp_path / fmt / name).read_text()
        assert "OFFSETS NOT APPLIED HERE (calibrate --offsets orientation)" in text, name
        assert "orientation 2: -399.6 (gravity along -1.000, +0.000, +0.000)" in text, name
    plain = CliRunner().invoke(app, ["export-c", str(golden), "-o", str(tmp_path / "plain")])
    assert plain.exit_code == 0
    assert "OFFSETS" not in (tmp_path / "plain" / "hrgtc_model.h").read_text()
