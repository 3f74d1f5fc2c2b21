"""Tests of hrgtc.drift.rate_checks: when the df/dt filter cannot follow a recording."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.rate_checks import burst_period_s, rate_filter_problems, resolution
from hrgtc.drift.windows import window_means
from hrgtc.errors import RateFilterWarning

from synthetic import ramp_run


def bursts(burst_s=5.0, period_s=300.0, hours=2.0, rate_hz=50.0):
    t = np.arange(0.0, hours * 3600.0, 1.0 / rate_hz)
    return t[np.mod(t, period_s) < burst_s - 1e-9]


def test_burst_period_and_resolution_are_found():
    assert burst_period_s(bursts()) == pytest.approx(300.0)
    assert burst_period_s(np.arange(1000) * 0.02) is None
    one_gap = np.concatenate([np.arange(100) * 0.1, 50.0 + np.arange(100) * 0.1])
    assert burst_period_s(one_gap) == pytest.approx(50.0 - 9.9 + 0.1)
    rng = np.random.default_rng(1)
    counts = np.round(20.0 / 0.0078125 + rng.normal(0, 3, 5000)) * 0.0078125  # 1/128 degC LSB
    assert resolution(counts) == pytest.approx(0.0078125)
    assert resolution(20.0 + rng.normal(0, 0.01, 5000)) is None  # continuous, noisy


def test_short_tau_on_bursts_and_a_coarse_thermometer_are_named():
    t = bursts()
    # a cool-down of 12 degC in 2 h (1.7e-3 degC/s) with 0.2 degC of noise, logged to
    # 0.1 degC: each LSB step reads as up to q/(e tau) = 3.7e-3 degC/s with tau = 10 s
    noise = np.random.default_rng(2).normal(0.0, 0.2, t.size)
    temperature = np.round((21.5 - 12.0 * t / 7200.0 + noise) / 0.1) * 0.1
    problems = rate_filter_problems(t, {"housing_c": temperature}, 10.0, where="cold.csv")
    assert len(problems) == 2
    assert "cold.csv: the df/dt filter's time constant 10 s is shorter than the 300 s " \
           "burst period" in problems[0] and "--rate-tau-s 300" in problems[0]
    assert "housing_c moves in steps of 0.1 °C" in problems[1]
    # tau needed: q/(e rate) = 0.1/(e 1.7e-3 degC/s) = 20 s (the span includes the noise)
    needed = float(re.search(r"--rate-tau-s (\S+) or more", problems[1]).group(1))
    assert 15.0 < needed < 25.0
    assert rate_filter_problems(t, {"housing_c": temperature}, 300.0) == []
    # a continuous recording: no burst period, nothing to say
    assert rate_filter_problems(np.arange(1000) * 0.1, {"freq_hz": np.linspace(0, 1, 1000)},
                                1.0) == []


def test_training_on_bursts_with_a_short_tau_warns_once():
    run = ramp_run(seed=3, hours=2.0)
    keep = np.mod(run.time_s, 300.0) < 5.0 - 1e-9
    from hrgtc.recording import Recording

    cut = Recording({n: run[n][keep] for n in run.names}, run.metadata, "bursts.csv")
    terms = parse_terms(["f", "df"])
    settings = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, rate_tau_s=10.0,
                               warmup_s=0.0)
    with pytest.warns(RateFilterWarning, match="shorter than the 300 s burst period") as caught:
        window_means([cut, cut], settings, terms, window_s=5.0)
    assert len([w for w in caught if issubclass(w.category, RateFilterWarning)]) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error", RateFilterWarning)
        window_means([run], settings, terms, window_s=5.0)  # continuous: silent
        slow = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0,
                               rate_tau_s=300.0, warmup_s=0.0)
        window_means([cut], slow, terms, window_s=5.0)
