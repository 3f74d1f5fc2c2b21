"""Tests of hrgtc.drift.features: term grammar and the causal df/dt filter."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from hrgtc.core.errors import InputError
from hrgtc.drift.features import (
    EQ21,
    FeatureSettings,
    FeatureStream,
    causal_rate,
    compute_variables,
    design_matrix,
    parse_term,
    parse_terms,
    required_columns,
)
from hrgtc.recording import Metadata, Recording


def test_eq21_has_the_papers_nine_terms():
    # Eq. (21) of [1]: f, f^2, f^3, df, df^2, df^3, f*df, f^2*df, f*df^2
    assert [t.name for t in EQ21] == [
        "f", "f^2", "f^3", "df", "df^2", "df^3", "f*df", "f^2*df", "f*df^2",
    ]


def test_grammar_canonicalises_and_rejects():
    assert parse_term("df*f^2").name == "f^2*df"
    assert parse_term("f*f").name == "f^2"
    assert parse_term("h^3").unit == "(°C)^3"
    assert required_columns(parse_terms(["f", "h*dh"])) == ("freq_hz", "housing_c")
    with pytest.raises(InputError, match="unknown variable 'x'"):
        parse_term("x^2")
    with pytest.raises(InputError, match="cannot read term 'f\\^\\^2'"):
        parse_term("f^^2")
    with pytest.raises(InputError, match="listed twice: f"):
        parse_terms(["f", "f"])


def test_rate_of_a_ramp_is_its_slope_after_the_transient():
    fs, tau = 10.0, 30.0
    t = np.arange(0, 3600, 1 / fs)
    x = 0.002 * t  # 0.002 units/s
    rate, _, _ = causal_rate(x, tau, fs)
    assert rate[0] == 0.0
    # A double first-order filter of a ramp converges to the slope exactly
    np.testing.assert_allclose(rate[t > 20 * tau], 0.002, rtol=1e-7)


def test_rate_filter_equals_its_transfer_function():
    # Independent check for uniform steps: the first-order-hold discretisation of
    # s/(tau s + 1)^2 as one IIR filter. Each stage is H = (p + q z^-1) / (1 - e z^-1)
    # with e = exp(-r), a = 1 - e, p = 1 - a/r, q = a - p (r = dt/tau), so
    # 1 - H = (1 - p)(1 - z^-1) / (1 - e z^-1) and rate = H (1 - H) x / tau.
    fs, tau = 20.0, 5.0
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=5000)) * 1e-3
    rate, _, _ = causal_rate(x, tau, fs)
    r = 1 / (tau * fs)
    a = -np.expm1(-r)
    e, p = 1 - a, 1 - a / r
    q = a - p
    num = np.polymul([p, q], [1.0 - p, -(1.0 - p)]) / tau
    den = np.polymul([1.0, -e], [1.0, -e])
    expected = signal.lfilter(num, den, x - x[0])
    np.testing.assert_allclose(rate, expected, atol=1e-12 * np.max(np.abs(x)))


@settings(max_examples=30, deadline=None)
@given(cuts=st.lists(st.integers(1, 1999), min_size=1, max_size=6, unique=True))
def test_chunked_stream_equals_batch(cuts):
    rng = np.random.default_rng(7)
    n = 2000
    rec = Recording(
        {
            "time_s": np.arange(n) / 10.0,
            "freq_hz": 4424.9 + np.cumsum(rng.normal(size=n)) * 1e-3,
            "rate_dph": rng.normal(size=n),
            "housing_c": 20 + np.cumsum(rng.normal(size=n)) * 1e-2,
        },
        Metadata(sample_rate_hz=10.0),
    )
    s = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, rate_tau_s=3.0)
    batch = compute_variables(rec, s, ("f", "df", "h", "dh"))
    stream = FeatureStream(s, ("f", "df", "h", "dh"))
    bounds = [0, *sorted(cuts), n]
    parts = [stream.transform(rec.slice(a, b)) for a, b in itertools.pairwise(bounds)]
    for v in batch:
        np.testing.assert_allclose(np.concatenate([p[v] for p in parts]), batch[v],
                                   rtol=1e-12, atol=1e-15)


def test_design_matrix_scaling_is_exact():
    rng = np.random.default_rng(1)
    values = {"f": rng.normal(size=50) * 10, "df": rng.normal(size=50) * 1e-3}
    scales = {"f": 10.0, "df": 1e-3}
    raw = design_matrix(EQ21, values)
    scaled = design_matrix(EQ21, values, scales)
    factors = np.array([t.scale_factor(scales) for t in EQ21])
    np.testing.assert_allclose(scaled * factors, raw, rtol=1e-13)


# -- the second rate filter, the gradient and the user's channels (issue 12, item 2) ------
def _lagged_run(n=6000, fs=5.0, seed=3):
    from synthetic import THERMOMETER

    rng = np.random.default_rng(seed)
    t = np.arange(n) / fs
    resonator = 20.0 - 10.0 * (1.0 - np.exp(-t / 900.0))
    return Recording(
        {"time_s": t, "freq_hz": THERMOMETER.frequency(resonator),
         "rate_dph": rng.normal(size=n), "housing_c": resonator - 0.5 + 0.01 * rng.normal(size=n),
         "drive_v": 2.5 + 0.1 * np.sin(t / 50.0)},
        Metadata(sample_rate_hz=fs), source="lagged.csv")


def test_grammar_knows_d2_g_and_aux_channels():
    assert parse_term("a_drive*f").name == "f*a_drive"
    assert parse_term("a_quad^2*d2*g").name == "d2*g*a_quad^2"
    assert parse_term("g").unit == "°C"
    assert required_columns(parse_terms(["f*g", "a_drive"])) == ("freq_hz", "housing_c")
    with pytest.raises(InputError, match="cannot read term 'a_'"):
        parse_term("a_")
    with pytest.raises(InputError, match="unknown variable 'd3'"):
        parse_term("d3")


def test_d2_is_the_rate_filter_with_its_own_time_constant():
    # independent: both first-order-hold stages by scipy.signal.lfilter, b = [p, q],
    # a = [1, -e] (e = exp(-r), p = 1 - (1 - e)/r, q = 1 - e - p, r = 1/(tau fs)),
    # started at rest on the first sample; the rate is (y1 - y2) / tau
    run = _lagged_run()
    fs, tau2 = 5.0, 120.0
    s = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=fs, rate_tau_s=3.0,
                        rate_tau2_s=tau2)
    values = compute_variables(run, s, ("f", "df", "d2"))
    f = run.freq_hz - 4432.0
    r = 1.0 / (tau2 * fs)
    e = np.exp(-r)
    p = 1.0 - (1.0 - e) / r
    q = 1.0 - e - p
    y1 = signal.lfilter([p, q], [1.0, -e], f, zi=[(q + e) * f[0]])[0]
    y2 = signal.lfilter([p, q], [1.0, -e], y1, zi=[(q + e) * f[0]])[0]
    expected = (y1 - y2) / tau2
    np.testing.assert_allclose(values["d2"], expected, rtol=1e-9, atol=1e-15)
    assert not np.allclose(values["d2"], values["df"])  # a slower filter, not df again
    # the slow filter lags more: on the exponential approach its rate is behind df's
    late = slice(2000, None)
    assert np.all(np.abs(values["d2"][late]) > np.abs(values["df"][late]))
    with pytest.raises(InputError, match="rate_tau2_s > 0"):
        compute_variables(run, FeatureSettings(4432.0, fs), ("d2",))


def test_g_is_housing_minus_resonator_temperature_from_the_thermometer():
    from synthetic import THERMOMETER

    run = _lagged_run()
    s = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=5.0)
    g = compute_variables(run, s, ("g",), THERMOMETER)["g"]
    np.testing.assert_allclose(g, run["housing_c"] - THERMOMETER.temperature(run.freq_hz),
                               rtol=0, atol=1e-12)
    assert abs(float(np.median(g)) + 0.5) < 0.01  # the housing logged 0.5 °C below
    with pytest.raises(InputError, match="needs the unit's thermometer"):
        compute_variables(run, s, ("g",))


def test_aux_channel_is_centred_and_a_missing_column_is_named():
    run = _lagged_run()
    s = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=5.0,
                        aux_columns={"drive": "drive_v"}, aux_centres={"drive": 2.5})
    a = compute_variables(run, s, ("a_drive",))["a_drive"]
    np.testing.assert_allclose(a, run["drive_v"] - 2.5, rtol=0, atol=1e-15)
    again = FeatureSettings.from_dict(s.to_dict())
    assert again.aux_columns == {"drive": "drive_v"} and again.aux_centres == {"drive": 2.5}
    with pytest.raises(InputError, match=r"lagged.csv: no column 'drive_v'.*--aux drive=drive_v"):
        compute_variables(run.drop("drive_v") if hasattr(run, "drop") else Recording(
            {k: run[k] for k in run.names if k != "drive_v"}, run.metadata, run.source),
            s, ("a_drive",))
    with pytest.raises(InputError, match="have no column"):
        compute_variables(run, FeatureSettings(4432.0, 5.0), ("a_quad",))
