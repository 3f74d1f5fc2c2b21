"""The measurements on synthetic block means whose answer is exact."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from hrgtc.drift.rate_segments import RateSegment
from hrgtc.testreport.manifest import CampaignSettings, RunEntry
from hrgtc.testreport.measures import (
    _lag1_widening,
    scale_factor_figures,
    temperature_figures,
    turn_on_figures,
    turn_ons,
)
from hrgtc.testreport.series import RunSeries

SETTINGS = CampaignSettings(block_s=60.0, settle_s=600.0, turn_on_tolerance_dph=0.5)


def _series(role, time_s, bias_dph, temperature_c, settle_s=None, **extra):
    return RunSeries(RunEntry(Path(f"{role}.csv"), role, settle_s=settle_s), "0" * 64,
                     len(time_s) * 60, 1.0, 0.0, np.asarray(time_s, float),
                     np.asarray(bias_dph, float), None, np.asarray(temperature_c, float),
                     **extra)


def test_turn_on_time_is_the_end_of_the_last_block_outside_the_band():
    time = np.arange(30) * 60.0
    bias = np.full(30, 2.0)
    bias[:7] = 2.0 + np.array([3.0, 2.0, 1.0, 0.6, 0.2, -0.7, 0.1])  # block 5 is the last out
    found = turn_ons([_series("turn-on", time, bias, np.full(30, 20.0))], SETTINGS)[0]
    assert found.bias_dph == pytest.approx(2.0)
    assert found.turn_on_time_s == 6 * 60.0
    assert found.warm_up_drift_dph == pytest.approx(3.0)  # blocks before settle_s = 600 s


def test_repeatability_needs_two_turn_ons_and_says_so():
    time = np.arange(30) * 60.0
    one = turn_ons([_series("turn-on", time, np.full(30, 1.0), np.full(30, 20.0))], SETTINGS)
    figures = {f.name: f for f in turn_on_figures(one, SETTINGS, compensated=False)}
    assert figures["bias_dph"].value == pytest.approx(1.0)
    assert figures["bias_repeatability_dph"].value is None
    assert "two or more" in figures["bias_repeatability_dph"].reason


@pytest.mark.parametrize("with_soaks", [False, True])
def test_temperature_and_gradient_sensitivities_of_an_exact_law(with_soaks):
    """bias = 1 + 0.2 T + 3 dT/dt [°C/min], exactly: both slopes come back to rounding."""
    t_min = np.arange(200.0)
    temperature = 20.0 - 0.5 * np.clip(t_min - 20.0, 0.0, 80.0)  # hold, ramp, hold
    rate = np.gradient(temperature, t_min)
    sweep = _series("sweep", t_min * 60.0, 1.0 + 0.2 * temperature + 3.0 * rate, temperature)
    soaks = []
    if with_soaks:
        for k, t in enumerate((-20.0, 0.0, 20.0, 40.0)):
            time = np.arange(40) * 60.0
            soaks.append(_series("soak", time, np.full(40, 1.0 + 0.2 * t + 0.01 * k),
                                 np.full(40, t)))
    figures, points = temperature_figures(soaks, [sweep], SETTINGS, compensated=False)
    found = {f.name: f for f in figures}
    sensitivity = found["bias_temperature_sensitivity_dph_per_c"]
    gradient = found["bias_gradient_sensitivity_dph_per_c_per_min"]
    assert gradient.value == pytest.approx(3.0, abs=0.02 if with_soaks else 1e-9)
    if with_soaks:
        assert len(points) == 4 and sensitivity.dof == 2
        slope = np.polyfit([p.temperature_c for p in points], [p.bias_dph for p in points], 1)[0]
        assert sensitivity.value == pytest.approx(slope, rel=1e-12)
    else:
        assert sensitivity.value == pytest.approx(0.2, abs=1e-9)


def test_lag1_widening_is_that_of_an_ar1_series():
    rng = np.random.default_rng(3)
    rho = 0.6
    x = np.zeros(200_000)
    noise = rng.normal(size=x.size)
    for k in range(1, x.size):
        x[k] = rho * x[k - 1] + noise[k]
    assert _lag1_widening(x) == pytest.approx(math.sqrt((1 + rho) / (1 - rho)), rel=0.02)
    assert _lag1_widening(noise) == pytest.approx(1.0, abs=0.01)


def _hold(rate_dph, k_ppm, bias_dph=2.0):
    return RateSegment(0.0, 100.0, rate_dph, bias_dph + rate_dph * (1.0 + k_ppm * 1e-6),
                       4424.0, 100)


def test_scale_factor_per_plateau_and_its_slope():
    """Holds with k = 100 + 2 (T - 20) ppm exactly, at three plateaus; a hold whose
    temperature spans 5 °C is left out."""
    rates = (3600.0, -3600.0, 36000.0, -36000.0)
    segments, temps, spans = [], [], []
    for t in (0.0, 20.0, 40.0):
        for r in rates:
            segments.append(_hold(r, 100.0 + 2.0 * (t - 20.0)))
            temps.append(t + (0.1 if abs(r) > 4000.0 else -0.1))  # means: t
            spans.append(0.2)
    segments.append(_hold(3600.0, 900.0))
    temps.append(30.0)
    spans.append(5.0)
    table = _series("rate-table", [0.0], [0.0], [20.0], segments=tuple(segments),
                    segment_temperature_c=tuple(temps), segment_span_c=tuple(spans))
    figures, plateaus = scale_factor_figures([table], SETTINGS)
    assert [p.holds for p in plateaus] == [4, 4, 4]
    found = {f.name: f for f in figures}
    assert found["scale_factor_error_ppm"].value == pytest.approx(100.0, abs=1e-6)
    assert found["scale_factor_temperature_sensitivity_ppm_per_c"].value == pytest.approx(
        2.0, rel=1e-9)


def test_no_warm_up_period_leaves_the_warm_up_drift_not_measured():
    time = np.arange(30) * 60.0
    runs = [_series("turn-on", time, np.full(30, b), np.full(30, 20.0)) for b in (1.0, 2.0)]
    settings = CampaignSettings(settle_s=0.0)
    figures = {f.name: f for f in turn_on_figures(turn_ons(runs, settings), settings, False)}
    assert figures["warm_up_drift_dph"].value is None
    assert figures["turn_on_time_s"].reason == "no turn_on_tolerance_dph in [settings]"
    assert figures["bias_repeatability_dph"].value == pytest.approx(np.std([1.0, 2.0], ddof=1))
