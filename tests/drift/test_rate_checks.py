"""Tests of hrgtc.drift.rate_checks: when the df/dt filter cannot follow a recording."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from hrgtc.core.errors import RateFilterWarning
from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.rate_checks import burst_period_s, rate_filter_problems, resolution
from hrgtc.drift.windows import Windowing, window_means

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
        window_means([cut, cut], settings, terms, Windowing(5.0))
    assert len([w for w in caught if issubclass(w.category, RateFilterWarning)]) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("error", RateFilterWarning)
        window_means([run], settings, terms, Windowing(5.0))  # continuous: silent
        slow = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0,
                               rate_tau_s=300.0, warmup_s=0.0)
        window_means([cut], slow, terms, Windowing(5.0))


def test_the_pan_cold_test_triggers_both_warnings_where_it_should():
    # the real recording: 5 s bursts every ~305 s, a raw temperature count (LSB 1) falling
    # 2126 counts in 2 h. tau 10 s: shorter than the burst period, the staircase below the
    # signal; tau 1 s (found by trial in issue 20): quantisation dominates too; tau 310 s:
    # silent.
    from pathlib import Path

    path = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
    data = np.genfromtxt(path, delimiter=",", skip_header=1)
    time_s, count = data[:, 0] / 1000.0, data[:, 7]
    assert burst_period_s(time_s) == pytest.approx(305.0, abs=1.0)
    assert resolution(count) == 1.0
    levels = {"temp": count}
    at_10 = rate_filter_problems(time_s, levels, 10.0, units={"temp": "counts"})
    assert len(at_10) == 1 and "--rate-tau-s 310 or more" in at_10[0]
    at_1 = rate_filter_problems(time_s, levels, 1.0, units={"temp": "counts"})
    assert len(at_1) == 2 and "temp moves in steps of 1 counts" in at_1[1]
    assert rate_filter_problems(time_s, levels, 310.0, units={"temp": "counts"}) == []


def test_a_sensor_s_temperature_is_named_as_such_in_degrees():
    # --thermometer sensor fills freq_hz with the temperature column: the message names
    # temperature_c in °C, not freq_hz in Hz.
    t = np.arange(7200.0)
    level = np.round((21.5 - 12.0 * t / 7200.0) / 0.1) * 0.1
    (sensor,) = rate_filter_problems(t, {"freq_hz": level}, 10.0, thermometer_source="sensor")
    assert "temperature_c moves in steps of 0.1 °C" in sensor and "°C/s" in sensor
    assert "freq_hz" not in sensor and "Hz" not in sensor
    (resonator,) = rate_filter_problems(t, {"freq_hz": level}, 10.0)
    assert "freq_hz moves in steps of 0.1 Hz" in resonator


def test_a_term_s_unit_follows_the_thermometer():
    from hrgtc.drift.features import parse_terms

    (term,) = parse_terms(["f^2*df"])
    assert term.unit == term.unit_for("resonator") == "(Hz)^2·Hz/s"
    assert term.unit_for("sensor") == "(°C)^2·°C/s"
