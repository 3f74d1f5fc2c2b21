"""Tests of hrgtc.drift.features: term grammar and the causal df/dt filter."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

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
from hrgtc.errors import InputError
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
    # Independent check: the exact discretisation of s/(tau s + 1)^2 as one IIR filter.
    fs, tau = 20.0, 5.0
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=5000)) * 1e-3
    rate, _, _ = causal_rate(x, tau, fs)
    a = -np.expm1(-1 / (tau * fs))
    b1 = 1 - a
    # y1 = H x with H = a / (1 - b1 z^-1); rate = g (y1 - H y1) = g H (1 - H) x, with the
    # ramp gain g = a fs / b1; (1 - H) = (1 - a - b1 z^-1) / (1 - b1 z^-1).
    gain = a * fs / b1
    num = gain * a * np.array([1.0 - a, -b1])
    den = np.polymul([1.0, -b1], [1.0, -b1])
    expected = signal.lfilter(num, den, x - x[0])
    np.testing.assert_allclose(rate, expected, atol=1e-15 * np.max(np.abs(x)) + 1e-18)


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
    parts = [stream.process(rec.slice(a, b)) for a, b in itertools.pairwise(bounds)]
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


def test_sample_rate_mismatch_is_refused():
    rec = Recording({"time_s": [0.0, 0.1], "freq_hz": [1.0, 1.0], "rate_dph": [0.0, 0.0]},
                    Metadata(sample_rate_hz=10.0), source="run.parquet")
    s = FeatureSettings(reference_freq_hz=1.0, sample_rate_hz=200.0)
    with pytest.raises(InputError, match=r"run.parquet: sample rate 10 Hz differs.*200 Hz"):
        s.check_sample_rate(rec)
