"""Tests of hrgtc.drift: the stepwise drift model of Eq. (21)-(22) of [1]."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.recording import Metadata, Recording

from synthetic import THERMOMETER, block_std, ramp_run, with_heating_extra


@pytest.fixture(scope="module")
def cooldown():
    return ramp_run(seed=1)


@pytest.fixture(scope="module")
def model(cooldown):
    return drift.fit([cooldown], THERMOMETER)


def test_history_adds_the_terms_that_carry_the_law(model):
    added = [s.term for s in model.history if s.action == "added"]
    # the law is 1.5 + 0.4 f + 0.02 f^2 + 3000 df
    assert {"f", "df"} <= set(added[:3])
    assert "f^2" in added
    assert model.coefficients["df"] == pytest.approx(3000.0, rel=0.15)


def test_model_compensates_a_warmup_with_another_seed(model):
    warm = ramp_run(seed=2, start_c=-20.0, end_c=20.0)
    predicted = model.predict_recording(warm)
    raw = warm.rate_dph - warm.metadata.input_rate_dph
    rows = int(10 * warm.sample_rate_hz)
    skip = int(model.settings.warmup_s * warm.sample_rate_hz)
    before = block_std(raw[skip:], rows)
    after = block_std((raw - predicted)[skip:], rows)
    assert before / after > 3.0
    # against the known truth: the residual is close to the noise floor of 10 s means
    residual = block_std((warm["bias_dph"] - predicted)[skip:], rows)
    assert residual < 0.5 * after + 0.2


def test_chunked_runs_give_the_same_model(cooldown, model):
    def chunks():
        for start in range(0, len(cooldown), 12_345):
            yield cooldown.slice(start, start + 12_345)

    chunked = drift.fit([chunks], THERMOMETER)
    assert chunked.selected == model.selected
    for name in model.selected:
        assert chunked.coefficients[name] == pytest.approx(model.coefficients[name], rel=1e-9)


def test_scaling_does_not_change_the_model_only_its_conditioning(cooldown, model):
    # The reported coefficients are in user units: predicting from them by hand agrees.
    values = {"f": np.array([-5.0, 3.0]), "df": np.array([1e-4, -2e-4])}
    by_hand = model.intercept_dph + sum(
        model.coefficients[t.name] * t.evaluate(values) for t in model._terms
    )
    np.testing.assert_allclose(model.predict(values, extrapolation="polynomial"), by_hand,
                               rtol=1e-12)


def test_json_round_trip(model, cooldown):
    again = drift.DriftModel.from_dict(json.loads(json.dumps(model.to_dict())))
    assert again.selected == model.selected
    np.testing.assert_array_equal(
        again.predict_recording(cooldown), model.predict_recording(cooldown)
    )
    assert "B = " in again.summary().text()


def test_constant_temperature_run_is_refused():
    n = 20 * 3600
    rng = np.random.default_rng(0)
    flat = Recording(
        {
            "time_s": np.arange(n) / 10.0,
            "freq_hz": 4432.07 + rng.normal(0, 0.002, n),
            "rate_dph": 10 + rng.normal(0, 2, n),
        },
        Metadata(sample_rate_hz=10.0, input_rate_dph=10.0),
    )
    with pytest.raises(CalibrationError, match=r"spans only .* °C of resonator temperature"):
        drift.fit([flat], THERMOMETER)
    with pytest.raises(CalibrationError, match="no df/dt variation"):
        drift.fit([flat], THERMOMETER, terms=["df"])


def test_bad_arguments():
    with pytest.raises(InputError, match="no drift runs"):
        drift.fit([], THERMOMETER)
    with pytest.raises(InputError, match="unknown variable"):
        drift.fit([ramp_run(seed=3, hours=1.0)], THERMOMETER, terms=["q"])


def test_tangent_extension_beyond_the_training_range(model):
    low, high = model.ranges["df"]
    f = np.full(5, -3.0)
    inside = {"f": f, "df": np.linspace(low, high, 5)}
    np.testing.assert_array_equal(model.predict(inside),
                                  model.predict(inside, extrapolation="polynomial"))
    # beyond the range: the tangent at the edge, checked by a central difference
    step = 1e-6 * (high - low)
    edge = {"f": f[:1], "df": np.array([high])}
    left = {"f": f[:1], "df": np.array([high - step])}
    right = {"f": f[:1], "df": np.array([high + step])}
    slope = (model.predict(right, extrapolation="polynomial")
             - model.predict(left, extrapolation="polynomial")) / (2 * step)
    far = {"f": f[:1], "df": np.array([high + 0.5 * (high - low)])}
    expected = model.predict(edge) + slope * 0.5 * (high - low)
    np.testing.assert_allclose(model.predict(far), expected, rtol=1e-6)
    clamped = model.predict(far, extrapolation="clamp")
    np.testing.assert_array_equal(clamped, model.predict(edge))
    with pytest.raises(InputError, match="extrapolation must be"):
        model.predict(far, extrapolation="cubic")


def test_hierarchical_fit_keeps_every_parent(cooldown, model):
    """drift.fit(hierarchical=True): each kept term's lower-order parents are kept too."""
    from hrgtc.drift.features import EQ21, hierarchy

    parents = hierarchy(EQ21)
    marginal = drift.fit([cooldown], THERMOMETER, hierarchical=True)
    for name in marginal.selected:
        assert set(parents[name]) <= set(marginal.selected), (name, marginal.selected)
    orphans = [n for n in model.selected if not set(parents[n]) <= set(model.selected)]
    assert orphans or marginal.selected == model.selected  # the option changed the fit, or needn't


def test_prediction_std_equals_monte_carlo_over_the_coefficients(model, cooldown):
    import dataclasses

    from hrgtc.drift.features import compute_variables

    cov = np.asarray(model.stepwise.result.cov_params)
    # the covariance of the final fit (inflated by Newey-West) gives the standard errors
    assert np.sqrt(cov[0, 0]) == pytest.approx(model.standard_errors["const"], rel=1e-9)
    assert model.variance_inflation > 1.0
    values = compute_variables(cooldown, model.settings, model.variables)
    values = {v: x[::500] for v, x in values.items()}
    low, high = model.ranges["f"]
    values["f"] = np.concatenate([values["f"], [high + 0.5 * (high - low)]])  # beyond: tangent
    values["df"] = np.concatenate([values["df"], [0.0]])
    std = model.prediction_std(values)
    mean = np.array([model.intercept_dph, *model.scaled_coefficients])
    draws = np.random.default_rng(3).multivariate_normal(mean, cov, size=4000)
    predictions = np.array([
        dataclasses.replace(model, intercept_dph=float(d[0]),
                            scaled_coefficients=tuple(map(float, d[1:]))).predict(values)
        for d in draws])
    np.testing.assert_allclose(std, predictions.std(axis=0), rtol=0.06)
    assert std.min() > 0.0 and std[-1] > np.median(std)  # grows beyond the training range


def test_heating_switch_dpos_carries_a_heating_only_rate_term(cooldown):
    from hrgtc.drift.features import EQ21_TERMS, SWITCH_FRACTION, heating_part

    warm = with_heating_extra(ramp_run(seed=5, start_c=-20.0, end_c=20.0))
    runs = [cooldown, warm]
    with_switch = drift.fit(runs, THERMOMETER, terms=(*EQ21_TERMS, "dpos"))
    plain = drift.fit(runs, THERMOMETER)
    assert "dpos" in with_switch.selected
    assert with_switch.coefficients["dpos"] == pytest.approx(2000.0, rel=0.25)
    delta = with_switch.settings.switch_hz_per_s
    assert delta > 0.0
    rates = drift.fit([cooldown], THERMOMETER).ranges["df"]
    assert delta < SWITCH_FRACTION * 2.0 * max(abs(rates[0]), abs(rates[1])) + 1e-12
    back = drift.DriftModel.from_dict(json.loads(json.dumps(with_switch.to_dict())))
    assert back.settings.switch_hz_per_s == delta
    held_out = with_heating_extra(ramp_run(seed=6, start_c=-15.0, end_c=15.0))
    truth, rows = held_out["bias_dph"], int(10 * held_out.sample_rate_hz)
    skip = int(with_switch.settings.warmup_s * held_out.sample_rate_hz)
    errors = [block_std((truth - m.predict_recording(held_out))[skip:], rows)
              for m in (with_switch, plain)]
    assert errors[0] < 0.7 * errors[1]
    assert heating_part(np.array([-5.0 * delta]), delta)[0] == pytest.approx(0.0, abs=1e-3 * delta)
    with pytest.raises(InputError, match="switch_hz_per_s"):
        drift.features.FeatureStream(plain.settings, ("f", "dpos")).transform(cooldown)


def test_the_model_keeps_what_an_update_needs(model):
    """The coefficient prior in user units agrees with the fit's figures and, propagated
    through the terms in user units, with :meth:`DriftModel.prediction_std`, which works
    on the scaled variables (two routes to one covariance)."""
    names, mean, covariance = model.coefficient_prior()
    assert names == ("const", *model.selected)
    for k, name in enumerate(model.selected, start=1):
        assert mean[k] == pytest.approx(model.coefficients[name], rel=1e-12)
        assert np.sqrt(covariance[k, k]) == pytest.approx(model.standard_errors[name],
                                                          rel=1e-12)
    np.testing.assert_allclose(covariance, covariance.T, rtol=0, atol=0)
    assert np.all(np.linalg.eigvalsh(covariance) > 0)
    # inside the trained ranges the model is linear in its coefficients: J Σ Jᵀ
    rng = np.random.default_rng(4)
    values = {v: rng.uniform(*model.ranges[v], 50) for v in model.variables}
    jacobian = np.column_stack([np.ones(50), *(t.evaluate(values) for t in model.terms)])
    expected = np.sqrt(np.einsum("ij,jk,ik->i", jacobian, covariance, jacobian))
    np.testing.assert_allclose(model.prediction_std(values), expected, rtol=1e-9)


def test_fits_sharing_one_window_pass_are_the_fits_alone(cooldown):
    """``fit_jointly`` (the drift model and the housing baseline of ``calibrate``: their
    window means from one reading of the runs) gives each fit's own model, field for
    field, on two streamed runs; the runs are read once for the windows of both; a later
    fit that fails gives its error in its place, the others go on."""
    from hrgtc.drift.fit_stages import TrainingReading
    from hrgtc.settings.drift import DriftSettings

    warm = ramp_run(seed=2, start_c=-20.0, end_c=20.0)
    reads = []

    def streamed(run, label):
        def chunks():
            reads.append(label)
            for start in range(0, len(run), 50_000):
                yield run.slice(start, start + 50_000)
        return chunks

    runs = [streamed(cooldown, "cool"), streamed(warm, "warm")]
    first = DriftSettings()
    second = DriftSettings(terms=("f", "f^2", "df"), select="cv", window_s=10.0)
    failing = DriftSettings(terms=("f",), window_s=1e-6)  # no sample in a window
    alone = [drift.fit(runs, THERMOMETER, s) for s in (first, second)]
    reads.clear()
    joint = drift.fit_jointly(runs, THERMOMETER, [drift.FitRequest(first),
                                                  drift.FitRequest(failing),
                                                  drift.FitRequest(second)],
                              reading=TrainingReading(rest_cache={}))
    assert isinstance(joint[1], InputError) and "window_s" in str(joint[1])
    for mine, own in zip((joint[0], joint[2]), alone, strict=True):
        assert json.dumps(mine.to_dict(), sort_keys=True) == json.dumps(own.to_dict(),
                                                                        sort_keys=True)
    # each run read whole twice for the three fits: the at-rest pass (shared through the
    # cache) and one window pass; the first run's head once more per fit
    assert reads.count("warm") == 2 and reads.count("cool") == 3 + 2
