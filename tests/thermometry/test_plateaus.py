"""Tests of hrgtc.thermometry.plateaus and .settling: soak plateaus and settling-curve fits.

Truth is independent of the code under test: synthetic transients with a known
f_inf and the Cramér-Rao bound of their fit computed here from the analytic
Jacobian; sample means and standard deviations recomputed with numpy on the raw
samples; the simulator's ground truth (the paper unit follows Eq. (18) of [1],
rebuilt here with numpy.polynomial from Table 1; ``resonator_c`` columns).
"""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from hrgtc import simulate
from hrgtc.core.errors import CalibrationError, InputError, RecordingError
from hrgtc.recording import Metadata, Recording
from hrgtc.simulate import units
from hrgtc.thermometry import fit as fit_thermometer
from hrgtc.thermometry import paper
from hrgtc.thermometry.plateaus import (
    Plateau,
    TransientFit,
    find_plateaus,
    fit_transient,
    plateau_table,
    plateaus_from_recordings,
)

# Eq. (18) of [1]: the least-squares cubic through Table 1, which paper-unit follows.
EQ18 = np.polynomial.Polynomial.fit(paper.TABLE1_TEMPERATURE_C, paper.TABLE1_FREQUENCY_HZ, 3)
EQ18_SLOPE_HZ_PER_C = 0.37  # linear term of Eq. (18) of [1], as the issue converts
SETPOINTS_C = [-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0]  # Section 3 of [1]
SIM_RATE_HZ = 2.0  # the thermal physics does not depend on the sample rate


def synthetic(time_s, freq_hz, chamber_c, source="synthetic.csv"):
    time_s = np.asarray(time_s, dtype=float)
    return Recording(
        {
            "time_s": time_s,
            "freq_hz": freq_hz,
            "rate_dph": np.zeros_like(time_s),
            "chamber_c": np.broadcast_to(chamber_c, time_s.shape),
        },
        Metadata(sample_rate_hz=1.0 / (time_s[1] - time_s[0])),
        source=source,
    )


# -- settling-curve fit on synthetic transients ----------------------------------------
def crb_f_inf_std(t, amplitude, tau, sigma):
    """Cramér-Rao bound of f_inf for f_inf + A exp(-t/tau) + white noise, analytic Jacobian."""
    e = np.exp(-t / tau)
    jac = np.column_stack([np.ones_like(t), e, amplitude * t / tau**2 * e])
    return float(sigma * math.sqrt(np.linalg.inv(jac.T @ jac)[0, 0]))


def test_single_exponential_f_inf_is_recovered_at_the_noise_limit():
    t = np.arange(0.0, 9000.0, 10.0)  # 2.5 h of 10 s block means
    f_inf, amplitude, tau, sigma = 4421.05, -4.0, 2400.0, 5e-4
    bound = crb_f_inf_std(t, amplitude, tau, sigma)
    z = []
    for seed in range(8):
        noise = np.random.default_rng(seed).normal(0.0, sigma, t.size)
        fit = fit_transient(t, f_inf + amplitude * np.exp(-t / tau) + noise)
        assert fit.usable
        assert fit.model in ("exp1", "exp2", "exp2-cubic")
        z.append((fit.f_inf_hz - f_inf) / bound)
        # the reported standard error is the bound (up to the extra parameters AIC may add)
        assert 0.8 * bound < fit.f_inf_std_hz < 3.0 * bound
    z = np.array(z)
    assert np.max(np.abs(z)) < 4.0
    assert 0.4 < math.sqrt(np.mean(z**2)) < 1.8  # rms z-score of an efficient estimator: ~1


def test_exact_transient_gives_exact_parameters_and_evaluates_back():
    t = np.arange(0.0, 18000.0, 10.0)
    freq = 4432.07 + 3.0 * np.exp(-t / 2400.0) - 1.0 * np.exp(-t / 720.0)
    fit = fit_transient(t + 100.0, freq)
    assert fit.f_inf_hz == pytest.approx(4432.07, abs=1e-7)
    assert fit.tau_s[0] == pytest.approx(2400.0, rel=1e-5)
    assert fit.tau_s[1] == pytest.approx(720.0, rel=1e-4)
    assert fit.amplitude_hz == pytest.approx((3.0, -1.0), rel=1e-4)
    assert np.max(np.abs(fit.evaluate(t + 100.0) - freq)) < 1e-6
    assert fit.end_offset_hz == pytest.approx(3.0 * math.exp(-t[-1] / 2400.0), abs=1e-6)


def test_two_node_cubic_transient_cut_to_2_5_h():
    # The two-node thermal response after a -40 °C step, through the cubic of Eq. (18):
    # a plain two-exponential model is biased; the cubic model must not be.
    t = np.arange(0.0, 9000.0, 10.0)
    tau_h, tau_r = 720.0, 2400.0
    temperature = -20.0 + 40.0 * (tau_r * np.exp(-t / tau_r) - tau_h * np.exp(-t / tau_h)) / (
        tau_r - tau_h
    )
    sigma = 4.5e-4  # 2 mHz per sample at 2 Hz, in 10 s means
    freq = EQ18(temperature) + np.random.default_rng(5).normal(0.0, sigma, t.size)
    fit = fit_transient(t, freq)
    assert fit.model == "exp2-cubic"
    assert abs(fit.f_inf_hz - EQ18(-20.0)) / EQ18_SLOPE_HZ_PER_C < 0.005
    assert abs(fit.f_inf_hz - EQ18(-20.0)) < 4 * fit.f_inf_std_hz


def test_flat_record_is_the_constant_model_with_the_plain_mean():
    t = np.arange(0.0, 3600.0, 10.0)
    freq = 4424.9 + np.random.default_rng(1).normal(0.0, 1e-3, t.size)
    fit = fit_transient(t, freq)
    assert fit.model == "constant" and fit.usable
    assert fit.f_inf_hz == pytest.approx(np.mean(freq), abs=1e-10)
    assert fit.f_inf_std_hz == pytest.approx(np.std(freq, ddof=1) / math.sqrt(t.size))


def test_linear_drift_has_no_usable_settled_frequency():
    t = np.arange(0.0, 18000.0, 10.0)
    freq = 4424.9 + 0.5 * t / 3600.0 + np.random.default_rng(2).normal(0.0, 1e-3, t.size)
    fit = fit_transient(t, freq)
    assert not fit.usable
    assert "time constant" in fit.reason


def test_fit_transient_rejects_bad_input():
    with pytest.raises(InputError, match="equal length"):
        fit_transient(np.arange(5.0), np.ones(5))
    with pytest.raises(InputError, match="increasing"):
        fit_transient(np.r_[0.0, np.arange(20.0)], np.ones(21))


# -- plateaus on synthetic recordings ------------------------------------------------
def settled_soak(hours=3.0, sample_rate_hz=2.0, seed=0, chamber_c=-10.0):
    t = np.arange(0.0, hours * 3600.0, 1.0 / sample_rate_hz)
    freq = 4421.05 + 0.8 * np.exp(-t / 600.0)
    freq = freq + np.random.default_rng(seed).normal(0.0, 2e-3, t.size)
    return synthetic(t, freq, chamber_c)


def test_settled_stretch_statistics_match_the_raw_samples():
    rec = settled_soak()
    (plateau,) = find_plateaus(rec, extrapolate=False)
    assert plateau.settled and plateau.method == "settled mean"
    inside = (rec.time_s >= plateau.start_s) & (rec.time_s <= plateau.end_s)
    assert plateau.n_samples == int(inside.sum())
    assert plateau.freq_hz == pytest.approx(np.mean(rec.freq_hz[inside]), abs=1e-9)
    assert plateau.freq_std_hz == pytest.approx(np.std(rec.freq_hz[inside], ddof=1), rel=1e-6)
    assert plateau.settled_freq_hz == plateau.freq_hz
    assert plateau.chamber_c == pytest.approx(-10.0)
    assert plateau.end_s == rec.time_s[-1]
    # The stretch starts with the first window whose robust slope (its middle 900 s
    # secant) is below 0.01 Hz/h; for 0.8 Hz exp(-t/600 s) that secant is, in Hz/h:
    s = plateau.start_s
    secant = 0.8 * (np.exp(-(s + 450.0) / 600.0) - np.exp(-(s + 1350.0) / 600.0)) * 4.0
    assert 0.008 < secant < 0.011
    assert plateau.start_s < rec.time_s[-1] - 1800.0  # longer than the minimum
    assert abs(plateau.slope_hz_per_h) < 0.01


def test_extrapolated_settled_frequency_and_residual_of_a_settled_soak():
    (plateau,) = find_plateaus(settled_soak())
    assert plateau.method == "transient fit"
    assert plateau.settled_freq_hz == pytest.approx(4421.05, abs=5 * plateau.settled_freq_std_hz)
    assert abs(plateau.residual_unsettled_c) < 1e-4  # 0.8 Hz e^(-3 h / 600 s) ~ 1e-8 Hz


def test_robust_slope_ignores_glitches():
    rec = settled_soak(seed=4)
    freq = rec.freq_hz.copy()
    for start_s in (8000.0, 9000.0, 10000.0):  # three 10 s bursts of +0.1 Hz
        freq[(rec.time_s >= start_s) & (rec.time_s < start_s + 10.0)] += 0.1
    (plateau,) = find_plateaus(rec.with_columns(freq_hz=freq), extrapolate=False)
    assert plateau.settled


def test_never_settling_soak_says_how_far_from_settled_in_hz_and_c_per_h():
    t = np.arange(0.0, 5 * 3600.0, 0.5)
    freq = 4421.05 + 0.5 * t / 3600.0 + np.random.default_rng(3).normal(0.0, 2e-3, t.size)
    rec = synthetic(t, freq, -10.0)
    for extrapolate in (True, False):
        with pytest.raises(CalibrationError, match=r"Hz/h.*°C/h") as info:
            find_plateaus(rec, extrapolate=extrapolate)
        message = str(info.value)
        found = re.search(r"changed by ([-+.\d]+) Hz/h \(([-+.\d]+) °C/h", message)
        assert float(found[1]) == pytest.approx(0.5, rel=0.02)  # the drift put in
        assert float(found[2]) == pytest.approx(0.5 / 0.37, rel=0.02)  # at 0.37 Hz/°C
        assert "synthetic.csv" in message and "-10.00 °C" in message
        assert "Lengthen the soak" in message
        assert ("extrapolate=True" in message) is (not extrapolate)


def test_short_transient_is_refused_when_the_fit_is_too_uncertain():
    # 1.2 h after a -30 °C step: the fit runs but its f_inf is loose.
    t = np.arange(0.0, 1.2 * 3600.0, 0.5)
    freq = EQ18(-10.0 + 30.0 * np.exp(-t / 2400.0))
    freq = freq + np.random.default_rng(6).normal(0.0, 0.05, t.size)
    with pytest.raises(CalibrationError, match="max_fit_std_c"):
        find_plateaus(synthetic(t, freq, -10.0))


def test_input_errors():
    rec = settled_soak(hours=1.0)
    with pytest.raises(RecordingError, match="chamber_c"):
        find_plateaus(Recording({"time_s": rec.time_s, "freq_hz": rec.freq_hz}, rec.metadata))
    freq = rec.freq_hz.copy()
    freq[123] = np.nan
    with pytest.raises(RecordingError, match=r"'freq_hz'.*row 123"):
        find_plateaus(rec.with_columns(freq_hz=freq))
    for name, value in (("min_duration_s", -1.0), ("block_s", 0.0), ("hz_per_c", 0.0)):
        with pytest.raises(InputError, match=name):
            find_plateaus(rec, **{name: value})
    with pytest.raises(InputError, match="3 blocks"):
        find_plateaus(rec, min_duration_s=20.0)
    with pytest.raises(InputError, match="recordings"):
        plateaus_from_recordings([])
    with pytest.raises(CalibrationError, match="no plateaus"):
        plateau_table([])


def test_a_ramp_is_no_soak():
    t = np.arange(0.0, 3 * 3600.0, 1.0)
    rec = synthetic(t, 4424.9 + 0.37 * 0.5 * t / 60.0, 20.0 - 0.5 * t / 60.0)
    with pytest.raises(CalibrationError, match=r"no soak found.*chamber_tolerance_c"):
        find_plateaus(rec)


def test_round_trip_summary_and_progress():
    calls = []
    plateaus = find_plateaus(
        [settled_soak(), settled_soak(seed=1)], progress=lambda *a: calls.append(a)
    )
    assert calls == [(1.0, 2.0), (2.0, 2.0)]
    for plateau in plateaus:
        data = json.loads(json.dumps(plateau.to_dict()))
        assert Plateau.from_dict(data) == plateau
        assert TransientFit.from_dict(data["fit"]) == plateau.fit
        assert f"{plateau.settled_freq_hz:.5f}" in plateau.summary().text()
    with pytest.raises(InputError, match="plateau record"):
        Plateau.from_dict({"chamber_c": 1.0})
    temperatures, frequencies = plateau_table(plateaus)
    assert temperatures.tolist() == [p.chamber_c for p in plateaus]
    assert frequencies.tolist() == [p.settled_freq_hz for p in plateaus]


# -- simulator: soaks with ground truth ----------------------------------------------
def c_error(freq_hz, truth_hz):
    return np.abs(np.asarray(freq_hz) - truth_hz) / EQ18_SLOPE_HZ_PER_C


def test_simulated_5h_soak_to_minus_10_gives_eq18_within_the_noise():
    unit = units.get("paper-unit")
    rec = simulate.simulate_run(simulate.soak(-10.0, 5.0), sample_rate_hz=SIM_RATE_HZ, seed=11)
    (plateau,) = find_plateaus(rec)
    assert plateau.chamber_c == pytest.approx(-10.0, abs=1e-9)
    # within the per-sample frequency noise (2 mHz, ~0.005 °C)
    assert abs(plateau.settled_freq_hz - EQ18(-10.0)) < unit.frequency_noise_hz
    # residual unsettled temperature against the simulator's resonator temperature
    truth_c = rec["resonator_c"][-1] - (-10.0)
    assert 0.01 < truth_c < 0.1  # 5 h is not quite settled: Section 3 of [1]
    assert plateau.residual_unsettled_c == pytest.approx(truth_c, rel=0.1)
    # extrapolate=False: the plain mean is off by about the unsettled remainder
    with pytest.raises(CalibrationError, match="°C/h"):
        find_plateaus(rec, extrapolate=False)
    (mean_only,) = find_plateaus(rec, extrapolate=False, slope_threshold_hz_per_h=0.1)
    assert mean_only.method == "settled mean"
    assert c_error(mean_only.settled_freq_hz, EQ18(-10.0)) > 0.02


@pytest.fixture(scope="module")
def campaign():
    """Seven soaks of 5 h (Section 3 of [1]) and the same soaks cut to 2.5 h."""
    recordings = [
        simulate.simulate_run(profile, sample_rate_hz=SIM_RATE_HZ, seed=20 + i)
        for i, profile in enumerate(simulate.soak_campaign(SETPOINTS_C, 5.0))
    ]
    cut = [rec.slice(0, round(2.5 * 3600.0 * SIM_RATE_HZ)) for rec in recordings]
    return find_plateaus(recordings), plateaus_from_recordings(cut)


@pytest.mark.slow
def test_campaign_5h_table_is_eq18(campaign):
    full, _ = campaign
    temperatures, frequencies = plateau_table(full)
    assert temperatures == pytest.approx(SETPOINTS_C, abs=1e-9)
    assert np.max(c_error(frequencies, EQ18(temperatures))) < 0.005


@pytest.mark.slow
def test_soaks_cut_to_2_5h_give_the_5h_table_within_0_02_c(campaign):
    full, cut = campaign
    t_full, f_full = plateau_table(full)
    t_cut, f_cut = plateau_table(cut)
    assert np.array_equal(t_full, t_cut)
    assert np.max(c_error(f_cut, f_full)) < 0.02  # issue 4, through the Eq. (18) slope
    assert not any(p.settled for p in cut if p.chamber_c != 20.0)  # all needed the fit
    # ... and the thermometers fitted to both tables agree within 0.02 °C
    th_full, th_cut = fit_thermometer(t_full, f_full, 3), fit_thermometer(t_cut, f_cut, 3)
    grid = np.linspace(-19.0, 39.0, 59)
    assert np.max(np.abs(th_cut.temperature(th_full.frequency(grid)) - grid)) < 0.02
    assert np.max(np.abs(th_cut.temperature(EQ18(grid)) - grid)) < 0.02


def test_one_file_with_many_setpoints_gives_one_plateau_each():
    setpoints = [-20.0, 0.0, 40.0, 10.0]
    profile = simulate.soak_series(setpoints, 3.0)
    rec = simulate.simulate_run(profile, sample_rate_hz=SIM_RATE_HZ, seed=31)
    plateaus = find_plateaus(rec)
    assert [p.chamber_c for p in plateaus] == pytest.approx(setpoints, abs=1e-3)
    assert np.max(c_error([p.settled_freq_hz for p in plateaus], EQ18(setpoints))) < 0.02
    ends = [p.end_s for p in plateaus]
    assert ends == sorted(ends)
    starts = np.array([p.segment_start_s for p in plateaus])
    # each soak begins when the chamber, slewing at 2 °C/min, reaches its set-point
    slew_s = np.abs(np.diff([20.0, *setpoints])) / 2.0 * 60.0
    expected = np.arange(4) * 3 * 3600.0 + slew_s
    assert np.max(np.abs(starts - expected)) < 30.0


def test_unit_b_soaks_cut_to_2_5h():
    unit = units.get("unit-b")
    setpoints = [-20.0, 10.0, 40.0]
    recordings = [
        simulate.simulate_run(p, unit="unit-b", sample_rate_hz=SIM_RATE_HZ, seed=40 + i)
        for i, p in enumerate(simulate.soak_campaign(setpoints, 2.5))
    ]
    plateaus = find_plateaus(recordings)
    truth = unit.frequency_law.frequency_hz(np.array(setpoints))
    slope = (unit.frequency_law.frequency_hz(np.array(setpoints) + 0.5) - truth) / 0.5
    errors_c = (np.array([p.settled_freq_hz for p in plateaus]) - truth) / slope
    assert np.max(np.abs(errors_c)) < 0.02


def test_block_sums_are_numpy_bincounts_bit_for_bit():
    """The compiled block statistics of the plateaus (one pass) equal the five
    ``numpy.bincount`` calls they replace, bit for bit, on a jittery clock with an empty
    block and float values that do not sum exactly."""
    from hrgtc.thermometry._plateau_kernel import block_sums

    rng = np.random.default_rng(7)
    time = np.cumsum(rng.uniform(0.05, 0.15, 20_000))
    time = time[(time < 300.0) | (time > 330.0)]  # blocks 30-32 of 10 s: none
    freq = 4417.0 + 0.01 * rng.standard_normal(time.size) + 1e-5 * time
    chamber = 20.0 + 0.05 * rng.standard_normal(time.size)
    idx = np.floor_divide(time - time[0], 10.0).astype(np.intp)
    ref = float(freq[0])
    count, time_sum, dev_sum, dev_sq_sum, chamber_sum = block_sums(idx, time, freq, ref,
                                                                   chamber)
    dev = freq - ref
    assert count.tolist() == np.bincount(idx).tolist()
    assert 0 in count.tolist()
    for mine, numpy_sum in ((time_sum, np.bincount(idx, time)),
                            (dev_sum, np.bincount(idx, dev)),
                            (dev_sq_sum, np.bincount(idx, dev * dev)),
                            (chamber_sum, np.bincount(idx, chamber))):
        assert mine.tobytes() == numpy_sum.tobytes()
