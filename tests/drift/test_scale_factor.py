"""Tests of hrgtc.drift.scale_factor: k(f) from rate-table segments.

Truth: synthetic rate-table runs built here with numpy (rate = Ω·(1 + k(T)·1e-6) +
b(T) + noise, f(T) the cubic of Table 1 of [1]), statsmodels and numpy.lstsq for the
per-temperature fits, exact polynomial data for the stepwise fit, JSON round trips and
the JSON Schema.
"""

from __future__ import annotations

import json
import math

import jsonschema
import numpy as np
import pytest
import statsmodels.api as sm

from hrgtc.core.errors import HrgtcWarning, InputError
from hrgtc.drift import (
    SCALE_FACTOR_JSON_SCHEMA,
    FeatureSettings,
    RateSegment,
    ScaleFactorModel,
    find_rate_segments,
    fit_scale_factor,
    group_segments,
    segment_scale_errors,
)
from hrgtc.recording import Metadata, Recording

from synthetic import THERMOMETER

DPS = 3600.0  # °/h per °/s
INPUTS_DPH = DPS * np.array([0.0, 10.0, -10.0, 100.0, -100.0, 300.0, -300.0])
TRAIN_C = (-20.0, -5.0, 10.0, 25.0, 40.0)
HELD_OUT_C = (-12.0, 3.0, 17.0, 33.0)
SETTINGS = FeatureSettings(reference_freq_hz=float(THERMOMETER.frequency(20.0)),
                           sample_rate_hz=10.0, scales={"f": 8.0})


def k_true_ppm(temperature_c):
    """Truth: scale-factor error, several hundred ppm over the range. [ppm]"""
    d = np.asarray(temperature_c) - 20.0
    return 200.0 + 12.0 * d + 0.08 * d ** 2


def bias_true_dph(temperature_c):
    return 4.0 + 0.3 * (np.asarray(temperature_c) - 20.0)


def rate_table_run(temperatures_c, seed=0, hold_s=60.0, sample_rate_hz=10.0, noise_dph=2.0,
                   inputs_dph=INPUTS_DPH):
    """Holds at every input rate at each temperature plateau, back to back."""
    rng = np.random.default_rng(seed)
    per_hold = round(hold_s * sample_rate_hz)
    temperature = np.repeat(np.asarray(temperatures_c, dtype=float), per_hold * len(inputs_dph))
    n = temperature.size
    temperature = temperature + 0.03 * np.sin(np.arange(n) / 500.0)  # a plateau is not flat
    inputs = np.tile(np.repeat(inputs_dph, per_hold), len(temperatures_c))
    bias = bias_true_dph(temperature)
    rate = inputs * (1.0 + k_true_ppm(temperature) * 1e-6) + bias + rng.normal(0, noise_dph, n)
    return Recording({"time_s": np.arange(n) / sample_rate_hz,
                      "freq_hz": THERMOMETER.frequency(temperature) + rng.normal(0, 0.002, n),
                      "rate_dph": rate, "input_rate_dph": inputs, "resonator_c": temperature,
                      "bias_dph": bias},
                     Metadata(sample_rate_hz=sample_rate_hz, unit="synthetic"), source="table-run")


@pytest.fixture(scope="module")
def train():
    return rate_table_run(TRAIN_C, seed=1)


@pytest.fixture(scope="module")
def model(train):
    return fit_scale_factor(find_rate_segments(train), SETTINGS)


def test_groups_are_the_plateaus(model, train):
    assert len(model.groups) == len(TRAIN_C)
    assert [g.n for g in model.groups] == [len(INPUTS_DPH)] * len(TRAIN_C)
    freqs = THERMOMETER.frequency(np.array(TRAIN_C))
    np.testing.assert_allclose(sorted(g.freq_hz for g in model.groups), np.sort(freqs),
                               atol=0.01)
    assert model.weighted
    assert model.input_rate_range_dph == (0.0, 300.0 * DPS)


def test_group_fit_equals_statsmodels_and_lstsq(train):
    segments = find_rate_segments(train)
    model = fit_scale_factor(segments, SETTINGS)
    for group, members in zip(model.groups,
                              group_segments(segments, 0.02 * SETTINGS.scales["f"]),
                              strict=True):
        x = np.array([s.input_rate_dph for s in members])
        y = np.array([s.rate_dph for s in members])
        ols = sm.OLS(y, sm.add_constant(x)).fit()
        assert group.k_ppm == pytest.approx((ols.params[1] - 1.0) * 1e6, abs=1e-6)
        assert group.k_se_ppm == pytest.approx(ols.bse[1] * 1e6, rel=1e-6)
        assert group.bias_dph == pytest.approx(ols.params[0], abs=1e-6)
        solution = np.linalg.lstsq(np.column_stack([np.ones_like(x), x]), y - x, rcond=None)[0]
        assert group.k_ppm == pytest.approx(solution[1] * 1e6, abs=1e-6)


def test_recovers_k_at_held_out_temperatures(model):
    held_out = np.array(HELD_OUT_C)
    freq = THERMOMETER.frequency(held_out)
    error = model.ppm(freq) - k_true_ppm(held_out)
    std = model.ppm_std(freq)
    assert np.all(std < 3.0)
    assert np.all(np.abs(error) <= 3.0 * std), (error, std)


def test_compensated_scale_error_at_held_out_temperatures(model):
    run = rate_table_run(HELD_OUT_C, seed=7)
    raw = segment_scale_errors(run, run["bias_dph"])
    assert raw.max_abs_ppm > 300.0  # several hundred ppm before
    compensated = run.with_columns(
        rate_dph=(run.rate_dph - run["bias_dph"]) / (1.0 + model.ppm(run.freq_hz) * 1e-6))
    after = segment_scale_errors(compensated, segments=raw.segments)
    assert after.max_abs_ppm <= 20.0
    assert after.rms_ppm < raw.rms_ppm / 20.0
    assert len(raw.segments) == len(HELD_OUT_C) * 6  # zero-input holds left out


def test_exact_cubic_is_recovered():
    """Segments whose k is exactly a cubic in x_f: stepwise keeps all three, exactly."""
    scale = SETTINGS.scales["f"]
    x_f = np.array([-1.0, -0.5, 0.1, 0.4, 0.9, 1.3])
    coefficients = (120.0, -80.0, 30.0, 12.0)  # const, f, f^2, f^3 on x_f [ppm]
    segments = []
    for n, x in enumerate(x_f):
        k = coefficients[0] + sum(c * x ** p for p, c in enumerate(coefficients[1:], 1))
        for j, omega in enumerate(INPUTS_DPH):
            noise = 1e-6 * (-1) ** (j + n)  # tiny, so every se is finite
            segments.append(RateSegment(start_s=100.0 * (7 * n + j), end_s=0.0,
                                        input_rate_dph=omega, rate_dph=omega * (1 + k * 1e-6)
                                        + 3.0 + noise, freq_hz=SETTINGS.reference_freq_hz
                                        + x * scale, rows=100))
    fitted = fit_scale_factor(segments, SETTINGS, penter=0.01)
    assert fitted.selected == ("f", "f^2", "f^3")
    np.testing.assert_allclose((fitted.intercept_ppm, *fitted.scaled_coefficients),
                               coefficients, rtol=0, atol=1e-4)
    # user units: ppm per Hz^p
    assert fitted.coefficients_ppm["f^2"] == pytest.approx(30.0 / scale ** 2, rel=1e-5)


def test_round_trip_and_schema(model):
    data = model.to_dict()
    text = json.dumps(data, allow_nan=False)
    back = ScaleFactorModel.from_dict(json.loads(text))
    assert back.to_dict() == data
    assert json.dumps(back.to_dict(), allow_nan=False) == text
    freq = np.linspace(model.freq_range_hz[0] - 2, model.freq_range_hz[1] + 2, 50)
    np.testing.assert_array_equal(back.ppm(freq), model.ppm(freq))
    jsonschema.Draft202012Validator.check_schema(SCALE_FACTOR_JSON_SCHEMA)
    jsonschema.validate(data, SCALE_FACTOR_JSON_SCHEMA)
    broken = {**data, "scale_hz": -1.0}
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, SCALE_FACTOR_JSON_SCHEMA)
    with pytest.raises(InputError, match="scale-factor-model record"):
        ScaleFactorModel.from_dict({k: v for k, v in data.items() if k != "groups"})
    assert "temperature groups" in model.summary().text()


def test_extrapolation_is_tangent(model):
    high = model.freq_range_hz[1]
    slope = (model.ppm(high) - model.ppm(high - 1e-4)) / 1e-4
    beyond = model.ppm(high + 1.0)
    assert beyond == pytest.approx(model.ppm(high) + slope, rel=1e-6)
    assert model.ppm(high + 1.0, "clamp") == pytest.approx(model.ppm(high))
    with pytest.raises(InputError, match="extrapolation"):
        model.ppm(high, "cubic")


def test_one_input_rate_in_a_group_is_refused(train):
    segments = [s for s in find_rate_segments(train)
                if s.input_rate_dph == 0.0 or s.freq_hz > THERMOMETER.frequency(0.0)]
    with pytest.raises(InputError, match=r"temperature group 1 .*one input rate"):
        fit_scale_factor(segments, SETTINGS)


def test_one_sign_warns_and_foreign_terms_are_refused(train):
    segments = [s for s in find_rate_segments(train) if s.input_rate_dph >= 0.0]
    with pytest.warns(HrgtcWarning, match="one sign"):
        fit_scale_factor(segments, SETTINGS)
    with pytest.raises(InputError, match="only f"):
        fit_scale_factor(find_rate_segments(train), SETTINGS, terms=("f", "df"))
    with pytest.raises(InputError, match="no rate-table segments"):
        fit_scale_factor([], SETTINGS)


def test_one_temperature_gives_a_constant(train):
    segments = [s for s in find_rate_segments(train)
                if abs(s.freq_hz - THERMOMETER.frequency(10.0)) < 0.1]
    fitted = fit_scale_factor(segments, SETTINGS)
    assert fitted.selected == ()
    assert fitted.intercept_ppm == fitted.groups[0].k_ppm
    assert fitted.standard_errors_ppm["const"] == pytest.approx(fitted.groups[0].k_se_ppm)
    # the plateau wanders by ±0.03 °C, i.e. k by ±0.36 ppm, within and between holds
    assert abs(fitted.intercept_ppm - k_true_ppm(10.0)) < 3.0 * fitted.groups[0].k_se_ppm + 0.4
    assert math.isnan(fitted.pvalues["const"])
    assert ScaleFactorModel.from_dict(json.loads(json.dumps(fitted.to_dict()))).to_dict() \
        == fitted.to_dict()


def test_k_of_f_equals_statsmodels_wls_on_the_groups(model):
    """The stepwise fit of the selected terms is the weighted least squares on x_f."""
    x_f = (np.array([g.freq_hz for g in model.groups]) - model.reference_hz) / model.scale_hz
    k = np.array([g.k_ppm for g in model.groups])
    se = np.array([g.k_se_ppm for g in model.groups])
    powers = [t.power_of("f") for t in model.terms]
    assert model.history and model.history[0].action == "added"
    wls = sm.WLS(k, np.column_stack([x_f ** p for p in (0, *powers)]), weights=se ** -2).fit()
    np.testing.assert_allclose((model.intercept_ppm, *model.scaled_coefficients), wls.params,
                               rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(np.sqrt(np.diag(np.asarray(model.covariance))), wls.bse,
                               rtol=1e-6)
    assert model.standard_errors_ppm["const"] == pytest.approx(wls.bse[0], rel=1e-6)


def test_grouping_tolerance(train):
    segments = find_rate_segments(train)
    assert len(group_segments(segments, 0.5)) == len(TRAIN_C)
    # a tolerance wider than the 5 Hz between plateaus joins them all
    assert len(group_segments(segments, 7.0)) == 1
    with pytest.raises(InputError, match="tolerance_hz"):
        group_segments(segments, 0.0)
    # one group over five temperatures is still a (poor) constant model
    joined = fit_scale_factor(segments, SETTINGS, tolerance_hz=7.0)
    assert len(joined.groups) == 1 and joined.selected == ()


def test_frequency_scale_defaults_to_the_largest_offset(train):
    segments = find_rate_segments(train)
    bare = FeatureSettings(reference_freq_hz=SETTINGS.reference_freq_hz, sample_rate_hz=10.0)
    fitted = fit_scale_factor(segments, bare)
    largest = max(abs(s.freq_hz - bare.reference_freq_hz) for s in segments)
    assert fitted.scale_hz == largest
    # the same polynomial whatever the scaling of x_f
    freq = THERMOMETER.frequency(np.array(HELD_OUT_C))
    reference = fit_scale_factor(segments, SETTINGS)
    np.testing.assert_allclose(fitted.ppm(freq), reference.ppm(freq), rtol=1e-9)


def test_summary_agrees_in_text_rich_html_and_json(model):
    """``ScaleFactorModel.summary()`` (what ``hrgtc calibrate`` prints and the report's
    scale-factor table shows): every figure the same in the text, the rich tables, the HTML
    and the model file's record, where its name is a place (``scale_factor.groups[0].k_ppm``);
    the model's k at each group is :meth:`ppm` there."""
    import io
    import json

    from rich.console import Console

    from hrgtc.cli.summary_tables import print_summary
    from summary_checks import check_renderings

    summary = model.summary()
    out = io.StringIO()
    print_summary(summary, Console(file=out, width=400))
    document = {"scale_factor": json.loads(json.dumps(model.to_dict()))}
    places = check_renderings(summary, out.getvalue(), document)
    assert places == 5 * len(model.groups) + 2 * len(model.selected) + 6
    figures = summary.figures()
    for k, g in enumerate(model.groups):
        assert figures[f"scale_factor.groups[{k}].model_ppm"].value == pytest.approx(
            float(model.ppm(g.freq_hz)[0]), rel=1e-12)
    headers, _ = summary.grid("scale-factor temperature groups")
    assert headers == ["mean frequency [Hz]", "k [ppm]", "std error [ppm]", "model k [ppm]",
                       "bias [°/h]", "holds"]
    assert model.equation() in summary.text() and "[ppm]" in out.getvalue()
