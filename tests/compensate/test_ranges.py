"""Tests of hrgtc.compensate.ranges: which variable left its trained range, and by how much.

Issue 21: on clean data ``compensate``/``evaluate`` said "72.5 % of samples beyond the
trained temperature" when the temperature was inside its range and the gradient ``g``
was beyond its trained maximum; the °C/h figures of the range report were only
compared by sign and ratio (a factor 3600 would pass); the lower calibration edge of
``in_range`` was not tested. Truth: the simulator's resonator temperature and rate,
and the variables recomputed here with :class:`FeatureStream`.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.compensate.ranges import RangeReport
from hrgtc.drift.features import FeatureStream
from hrgtc.model import AxisModel, Model

from synthetic import THERMOMETER, lagged_run, ramp_run


@pytest.fixture(scope="module")
def gradient_model():
    terms = ("f", "df", "g")
    runs = [lagged_run(seed=5), lagged_run(seed=6, start_c=-20.0, end_c=20.0)]
    fitted = drift.fit(runs, THERMOMETER, terms=terms, initial=terms, premove=0.999999)
    return Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted), unit="gradient")


@pytest.fixture(scope="module")
def unit_model():
    return Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([ramp_run(seed=1)], THERMOMETER)))


def hot_housing(model, hours=1.5):
    """A run well inside the trained temperatures whose housing reads 4 °C above the gradient
    the model was trained on: only g leaves its range."""
    run = lagged_run(seed=9, start_c=10.0, end_c=5.0, hours=hours)
    high = model.drift.ranges["g"][1]
    return run.with_columns(housing_c=run["housing_c"] + high + 4.0)


@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_the_gradient_beyond_its_range_is_not_called_a_temperature(gradient_model, engine):
    run = hot_housing(gradient_model)
    compensator = Compensator(gradient_model, engine=engine)
    compensator.transform(run)
    report = compensator.ranges()
    # the truth: g recomputed, and the resonator temperature well inside the calibration
    g = FeatureStream(gradient_model.drift.settings, ("g",), THERMOMETER).transform(run)["g"]
    low, high = gradient_model.drift.ranges["g"]
    # counted and measured on the settled samples (the settling ones are counted apart)
    settled = run.time_s - run.time_s[0] >= gradient_model.drift.settings.warmup_s
    g = g[settled]
    beyond = int(np.count_nonzero((g < low) | (g > high)))
    assert beyond > 0.5 * len(run)
    assert report.temperature_fraction == 0.0 and report.seen_c[1] < 25.0
    (gradient,) = [v for v in report.variables if v.name == "g"]
    assert gradient.fraction == beyond / len(run)
    assert gradient.unit == "°C"
    assert gradient.excess == pytest.approx(float(np.nanmax(g)) - high, rel=1e-12)
    lines = report.warnings()
    assert not any("trained temperature" in line for line in lines)
    (line,) = [line for line in lines if "of g" in line]
    assert f"{gradient.fraction:.1%} of samples beyond the trained range of g" in line
    # the JSON says the same per variable, and reads back
    data = json.loads(json.dumps(report.to_dict()))
    assert data["temperature_fraction"] == 0.0
    assert data["variables"][0]["variable"] == "g"
    assert data["variables"][0]["fraction"] == gradient.fraction
    assert RangeReport.from_dict(data) == report
    assert report.shares_text().endswith(f"g {gradient.fraction:.1%}")


@pytest.mark.parametrize("hours", [1.5, 8.0])
def test_the_engines_count_every_variable_alike(gradient_model, hours):
    """Two chunks (counts and extremes add up); at 8 h the second chunk is long enough for
    the kernel to work its two halves on two threads (their counts are merged)."""
    from hrgtc.compensate._kernel import PARALLEL_ROWS

    run = hot_housing(gradient_model, hours)
    assert (len(run) - 20_000 >= PARALLEL_ROWS) == (hours > 2)
    a, b = Compensator(gradient_model, engine="fused"), Compensator(gradient_model,
                                                                    engine="numpy")
    for c in (a, b):
        c.transform(run.slice(0, 20_000))
        c.transform(run.slice(20_000, len(run)))
    assert a.axis._plan is not None  # the kernel did run
    assert a.axis.temperature_out == b.axis.temperature_out
    for name, (outside, low, high) in b.axis.variable_ranges.items():
        assert a.axis.variable_ranges[name][0] == outside, name
        assert a.axis.variable_ranges[name][1:] == pytest.approx([low, high], rel=1e-12), name


def test_rates_in_degrees_per_hour_are_the_simulated_ones(unit_model):
    """The °C/h figures against the simulator's resonator rate (a factor 3600 fails)."""
    trained_low, trained_high = Compensator(unit_model).ranges().trained_rate_c_per_h
    # the truth: the training run's resonator rate on 10 s window means (the fit's windows)
    training = ramp_run(seed=1)
    rows = int(10.0 * training.sample_rate_hz)
    true = np.gradient(training["resonator_c"], training.time_s) * 3600.0
    n = true.size // rows
    windows = true[: n * rows].reshape(n, rows).mean(axis=1)
    assert windows.min() < -15.0  # °C/h: the chamber cools 40 °C in 2 h through a lag
    assert trained_low == pytest.approx(windows.min(), rel=0.05)  # window noise of df/dt
    assert trained_high < 1.0
    fast = ramp_run(seed=24, start_c=0.0, end_c=10.0, hours=1.0, ramp_hours=0.1)
    compensator = Compensator(unit_model)
    compensator.transform(fast)
    seen = compensator.ranges().seen_rate_c_per_h
    true = np.gradient(fast["resonator_c"], fast.time_s) * 3600.0
    assert seen[1] == pytest.approx(true.max(), rel=0.15)  # the filter lags and smooths a bit
    assert seen[1] > 10.0  # °C/h (the same warm-up in °C/s would read 0.004)


def test_in_range_holds_at_both_calibration_edges_and_not_beyond():
    low_t, _ = THERMOMETER.temperature_range_c
    f_low, f_high = THERMOMETER.frequency_range_hz
    assert THERMOMETER.frequency(low_t) in (f_low, f_high)
    edges = np.array([f_low, f_high])
    outward = np.spacing(edges) * np.array([-4.0, 4.0])
    assert THERMOMETER.in_range(edges).all()
    assert not THERMOMETER.in_range(edges + outward).any()  # just beyond each edge
    assert THERMOMETER.in_range(edges - outward).all()  # just inside


@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_samples_at_the_lower_calibration_edge_are_flagged_in_range(unit_model, engine):
    """A constant frequency exactly at the lower calibrated edge: in range (the run is at
    rest, inside f's training range); one ulp below: out of range."""
    import dataclasses

    from hrgtc.recording import Metadata, Recording

    f_low, _ = THERMOMETER.frequency_range_hz
    rows = 4000
    settings = unit_model.drift.settings
    # f's training range widened past the calibration, so the calibrated edge decides
    f_range = (f_low - settings.reference_freq_hz - 1.0, unit_model.drift.ranges["f"][1])
    wide = unit_model.with_parts(drift=dataclasses.replace(
        unit_model.drift, ranges={**unit_model.drift.ranges, "f": f_range,
                                  "df": (-1.0, 1.0)}))
    for freq, expected in ((f_low, 1.0), (np.nextafter(f_low, -np.inf), 0.0)):
        run = Recording({"time_s": np.arange(rows) / settings.sample_rate_hz,
                         "freq_hz": np.full(rows, freq), "rate_dph": np.zeros(rows)},
                        Metadata(sample_rate_hz=settings.sample_rate_hz))
        compensator = Compensator(wide, engine=engine)
        out = compensator.transform(run)
        assert (out["in_range"][-100:] == expected).all(), (freq, expected)
        # counted on the settled samples only (the settling ones as such)
        settling = compensator.axis.settling
        assert compensator.axis.temperature_out == (0 if expected else rows - settling)
        assert 0 < compensator.axis.settling < rows


# -- mutants of ranges.py that no test killed (make mutation, issue 21) ----------------------
def test_a_variable_warning_says_the_variable_its_ranges_and_how_far():
    from hrgtc.compensate.ranges import VariableRange

    beyond = VariableRange("dh", "°C/h", 0.725, (-1.0, 2.0), (-0.5, 3.5))
    assert beyond.warning() == (
        "warning: 72.5% of samples beyond the trained range of dh (causal rate of h) -1 to 2 "
        "°C/h, up to 1.5 °C/h beyond (seen -0.5 to 3.5 °C/h)")


def _report(variables=()):
    return RangeReport(samples=1000, temperature_fraction=0.0, rate_fraction=0.012,
                       settling_fraction=0.05, trained_c=(10.0, 30.0), seen_c=(12.0, 29.0),
                       trained_rate_c_per_h=(-3.0, 3.0), seen_rate_c_per_h=(-3.6, 2.0),
                       variables=variables)


def test_range_reports_round_trip_through_json_with_missing_bounds():
    import dataclasses

    from hrgtc.compensate.ranges import VariableRange

    nan = float("nan")
    g = VariableRange("g", "°C", 0.725, (nan, 2.0), (-0.5, nan))
    report = _report((g,))
    data = json.loads(json.dumps(report.to_dict(), allow_nan=False))
    assert data["variables"] == [{"variable": "g", "unit": "°C", "fraction": 0.725,
                                  "trained": [None, 2.0], "seen": [-0.5, None],
                                  "excess": 0.0}]
    assert data["temperature_excess_c"] == 0.0 and data["trained_c"] == [10.0, 30.0]
    assert data["rate_excess_ratio"] == pytest.approx(1.2)
    untrained = dataclasses.replace(report, trained_rate_c_per_h=(0.0, 0.0))
    assert untrained.to_dict()["rate_excess_ratio"] is None  # JSON has no infinity
    back = RangeReport.from_dict(data)
    assert back.to_dict() == data
    (g_back,) = back.variables
    assert np.isnan(g_back.trained[0]) and g_back.trained[1] == 2.0
    assert g_back.seen[0] == -0.5 and np.isnan(g_back.seen[1])
    data["seen_c"] = [None, None]
    assert all(np.isnan(RangeReport.from_dict(data).seen_c))
    del data["variables"]  # a report written before variables were reported
    assert RangeReport.from_dict(data).variables == ()


def test_shares_name_temperature_df_dt_then_every_variable():
    from hrgtc.compensate.ranges import VariableRange

    report = _report((VariableRange("g", "°C", 0.725, (-1.0, 2.0), (-0.5, 3.5)),))
    assert report.shares() == {"temperature": 0.0, "df/dt": 0.012, "g": 0.725}
    assert report.shares_text() == "temperature 0.0%, df/dt 1.2%, g 72.5%"


def test_variable_unit_of_an_extra_channel_and_of_a_sensor_model():
    from hrgtc.compensate.ranges import variable_unit

    assert variable_unit("a_pressure", "resonator", {"pressure": "hPa"}) == "(unit of hPa)"
    assert variable_unit("a_pressure", "resonator", {}) == "(unit of pressure)"
    assert variable_unit("d2", "sensor", {}) == "°C/s"
    assert variable_unit("d2", "resonator", {}) == "Hz/s"


def test_the_warning_lines_say_each_excursion_once_and_nothing_inside():
    from hrgtc.compensate.ranges import VariableRange

    inside = VariableRange("g", "°C", 0.0, (-1.0, 2.0), (-0.5, 1.5))
    beyond = VariableRange("h", "°C", 0.25, (-1.0, 2.0), (-0.5, 3.5))
    report = RangeReport(samples=1000, temperature_fraction=0.1, rate_fraction=0.012,
                         settling_fraction=0.05, trained_c=(10.0, 30.0), seen_c=(8.0, 29.0),
                         trained_rate_c_per_h=(-3.0, 3.0), seen_rate_c_per_h=(-3.6, 2.0),
                         variables=(inside, beyond))
    assert report.warnings() == [
        "warning: 10.0% of samples beyond the trained temperature 10.00 to 30.00 °C, up to "
        "2.00 °C beyond (seen 8.00 to 29.00 °C)",
        "warning: 1.2% of samples beyond the trained df/dt -3.0 to +3.0 °C/h (seen -3.6 to "
        "+2.0 °C/h, up to 1.20× the largest trained on that side); train on runs this fast "
        "(calibrate --drift takes several)",
        beyond.warning()]
    untrained = RangeReport(samples=1000, temperature_fraction=0.0, rate_fraction=0.5,
                            settling_fraction=0.0, trained_c=(10.0, 30.0), seen_c=(12.0, 29.0),
                            trained_rate_c_per_h=(0.0, 0.0), seen_rate_c_per_h=(-3.6, 2.0))
    assert untrained.warnings() == [  # no largest trained df/dt to compare with
        "warning: 50.0% of samples beyond the trained df/dt +0.0 to +0.0 °C/h (seen -3.6 to "
        "+2.0 °C/h); train on runs this fast (calibrate --drift takes several)"]
    assert RangeReport(1000, 0.0, 0.0, 0.0, (10.0, 30.0), (12.0, 29.0), (-3.0, 3.0),
                       (-1.0, 1.0), (inside,)).warnings() == []


def test_temperatures_far_beyond_the_thermometer_continue_along_its_chord():
    from hrgtc.compensate.ranges import _temperature

    low, high = THERMOMETER.temperature_range_c
    f_low, f_high = float(THERMOMETER.frequency(low)), float(THERMOMETER.frequency(high))
    chord = (f_high - f_low) / (high - low)  # Hz/°C, may be negative
    far = np.array([f_low - 1000.0 * chord, f_high + 1000.0 * chord])
    t = _temperature(THERMOMETER, far)
    assert t.dtype == np.float64 and np.isfinite(t).all()
    np.testing.assert_allclose(t, [low - 1000.0, high + 1000.0], rtol=1e-9)
    inside = np.array([f_low, float(THERMOMETER.frequency(10.0)), f_high])
    np.testing.assert_allclose(_temperature(THERMOMETER, inside), [low, 10.0, high], atol=1e-6)


def test_range_report_from_the_compensators_counts_and_extremes(gradient_model):
    import dataclasses

    from hrgtc.compensate.ranges import _temperature, range_report

    model = gradient_model
    f_ref = model.drift.settings.reference_freq_hz
    counts = np.array([100, 12, 0, 50])
    extremes = np.array([-5.0, 4.0, -1e-4, 2e-4])  # f min, f max [Hz], df min, max [Hz/s]
    h_seen = {"g": (250, -0.5, 3.5)}
    report = range_report(model.drift, THERMOMETER, 1000, counts, extremes, h_seen)
    seen = _temperature(THERMOMETER, extremes[:2] + f_ref)
    assert report.seen_c == (float(seen[0]), float(seen[1]))
    assert report.temperature_fraction == 0.1 and report.rate_fraction == 0.012
    assert report.settling_fraction == 0.05
    (h,) = report.variables
    assert (h.name, h.unit, h.fraction, h.seen) == ("g", "°C", 0.25, (-0.5, 3.5))
    assert h.trained == model.drift.ranges["g"]
    no_f = dataclasses.replace(model.drift, ranges={k: v for k, v in model.drift.ranges.items()
                                                    if k != "f"})
    untrained = range_report(no_f, THERMOMETER, 1000, counts, extremes)
    assert untrained.trained_c == THERMOMETER.temperature_range_c  # the calibrated span
    empty = range_report(model.drift, THERMOMETER, 0, np.zeros(4), extremes, h_seen)
    assert np.isnan(empty.seen_c).all() and np.isnan(empty.variables[0].seen).all()
    assert empty.temperature_fraction == 0.0 and empty.variables[0].fraction == 0.0


def test_rates_are_reported_per_hour_of_resonator_temperature(gradient_model):
    import dataclasses
    import math

    from hrgtc.compensate.ranges import range_report

    model = gradient_model
    ranges = {**model.drift.ranges, "dh": (-1e-4, 2e-4)}  # °C/s
    drift_dh = dataclasses.replace(model.drift, ranges=ranges)
    extremes = np.array([-5.0, 4.0, np.nan, 3e-3])  # df min unknown: f's extremes still used
    report = range_report(drift_dh, THERMOMETER, 1000, np.array([0, 12, 0, 0]), extremes,
                          {"dh": (100, -3e-4, 1e-4)})
    assert np.isfinite(report.seen_c).all()
    (dh,) = report.variables
    assert dh.unit == "°C/h" and dh.fraction == 0.1
    assert dh.trained == pytest.approx((-0.36, 0.72), rel=1e-12)
    assert dh.seen == pytest.approx((-1.08, 0.36), rel=1e-12)
    # df/dt [Hz/s] as a resonator temperature rate [°C/h] at the middle of the trained span
    slope = float(THERMOMETER.slope_hz_per_c(0.5 * sum(report.trained_c)))
    df_low, df_high = model.drift.ranges["df"]
    assert report.trained_rate_c_per_h == pytest.approx(
        tuple(sorted((df_low / slope * 3600.0, df_high / slope * 3600.0))), rel=1e-12)
    no_df = dataclasses.replace(model.drift, ranges={k: v for k, v in model.drift.ranges.items()
                                                     if k != "df"})
    untrained = range_report(no_df, THERMOMETER, 1000, np.zeros(4), extremes)
    assert untrained.trained_rate_c_per_h == (-math.inf, math.inf)
