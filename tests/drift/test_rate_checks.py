"""Tests of hrgtc.drift.rate_checks: when the df/dt filter cannot follow a recording."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from hrgtc.core.errors import RateFilterWarning
from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.rate_checks import rate_filter_problems, resolution
from hrgtc.drift.rate_filter import causal_rate
from hrgtc.drift.windows import Windowing, window_means

from synthetic import ramp_run


def bursts(burst_s=5.0, period_s=300.0, hours=2.0, rate_hz=50.0):
    t = np.arange(0.0, hours * 3600.0, 1.0 / rate_hz)
    return t[np.mod(t, period_s) < burst_s - 1e-9]


def test_resolution_is_found():
    rng = np.random.default_rng(1)
    counts = np.round(20.0 / 0.0078125 + rng.normal(0, 3, 5000)) * 0.0078125  # 1/128 degC LSB
    assert resolution(counts) == pytest.approx(0.0078125)
    assert resolution(20.0 + rng.normal(0, 0.01, 5000)) is None  # continuous, noisy


def test_a_coarse_thermometer_is_named_and_bursts_alone_are_not():
    t = bursts()
    # a cool-down of 12 degC in 2 h (1.7e-3 degC/s) with 0.2 degC of noise, logged to
    # 0.1 degC: each LSB step reads as up to q/(e tau) = 3.7e-3 degC/s with tau = 10 s
    noise = np.random.default_rng(2).normal(0.0, 0.2, t.size)
    temperature = np.round((21.5 - 12.0 * t / 7200.0 + noise) / 0.1) * 0.1
    (problem,) = rate_filter_problems(t, {"housing_c": temperature}, 10.0, where="cold.csv")
    assert problem.startswith("cold.csv: housing_c moves in steps of 0.1 °C")
    # tau needed: q/(e rate) = 0.1/(e 1.7e-3 degC/s) = 20 s (the span includes the noise)
    needed = float(re.search(r"--rate-tau-s (\S+) or more", problem).group(1))
    assert 15.0 < needed < 25.0
    assert rate_filter_problems(t, {"housing_c": temperature}, 30.0) == []
    # the same bursts with a fine thermometer: nothing to say at the default tau
    fine = 21.5 - 12.0 * t / 7200.0 + np.random.default_rng(3).normal(0.0, 0.01, t.size)
    assert rate_filter_problems(t, {"housing_c": fine}, 10.0) == []
    assert rate_filter_problems(np.arange(1000) * 0.1, {"freq_hz": np.linspace(0, 1, 1000)},
                                1.0) == []


@pytest.mark.parametrize("noise_c", [0.0, 0.01])
def test_bridged_bursts_read_the_trend_better_at_a_short_tau_than_at_their_period(noise_c):
    """Across a gap the filter's step is a first-order hold: after a gap much longer than
    tau it reads the chord's slope, the gap's mean rate. On 5 s bursts every 300 s of an
    exponential cool-down (-24 °C/h at first), the bursts' mean df/dt at tau = 10 s lies
    nearer the true dT/dt than at tau = 310 s (the period, which a warning once asked
    for): the long filter's lag of 2 tau is then 10 minutes."""
    t = bursts(hours=3.0)
    temperature = 5.0 + 20.0 * np.exp(-t / 3000.0)
    true_rate = -20.0 / 3000.0 * np.exp(-t / 3000.0)
    temperature = temperature + np.random.default_rng(4).normal(0.0, noise_c, t.size)
    burst = np.floor(t / 300.0).astype(np.int64)

    def error_c_per_h(tau_s):
        rate, _, _ = causal_rate(temperature, tau_s, time_s=t)
        means = np.bincount(burst, rate - true_rate) / np.bincount(burst)
        return float(np.sqrt(np.mean(means[5:] ** 2))) * 3600.0

    short, period = error_c_per_h(10.0), error_c_per_h(310.0)
    assert short < 0.8 < 1.3 < period, (short, period)


def test_training_on_bursts_with_a_short_tau_is_silent():
    run = ramp_run(seed=3, hours=2.0)
    keep = np.mod(run.time_s, 300.0) < 5.0 - 1e-9
    from hrgtc.recording import Recording

    cut = Recording({n: run[n][keep] for n in run.names}, run.metadata, "bursts.csv")
    terms = parse_terms(["f", "df"])
    settings = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, rate_tau_s=10.0,
                               warmup_s=0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RateFilterWarning)
        window_means([cut, cut], settings, terms, Windowing(5.0))
        window_means([run], settings, terms, Windowing(5.0))  # continuous: silent


def test_the_pan_cold_test_warns_only_where_quantisation_dominates():
    # the real recording: 5 s bursts every ~305 s, a raw temperature count (LSB 1) falling
    # 2126 counts in 2 h. tau 10 s (the default): the staircase below the signal, silent;
    # tau 1 s (found by trial in issue 20): quantisation dominates. (A tau of the burst
    # period, 310 s, which a warning once asked for, leaves the cool-down's dT/dt no
    # variation to fit: calibrate refuses the rate terms.)
    from pathlib import Path

    path = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
    data = np.genfromtxt(path, delimiter=",", skip_header=1)
    time_s, count = data[:, 0] / 1000.0, data[:, 7]
    assert resolution(count) == 1.0
    levels = {"temp": count}
    assert rate_filter_problems(time_s, levels, 10.0, units={"temp": "counts"}) == []
    (at_1,) = rate_filter_problems(time_s, levels, 1.0, units={"temp": "counts"})
    assert "temp moves in steps of 1 counts" in at_1 and "--rate-tau-s 1.3 or more" in at_1


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
