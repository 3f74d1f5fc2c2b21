"""Small synthetic runs with a known bias law, independent of the simulator."""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import signal

from hrgtc.drift.scale_factor import ScaleFactorModel, ScaleGroup
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Metadata, Recording
from hrgtc.thermometry import fit

# Table 1 of [1]
TABLE1_T = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0])
TABLE1_F = np.array([4416.97, 4421.05, 4424.90, 4428.56, 4432.07, 4435.56, 4439.20])
THERMOMETER = fit(TABLE1_T, TABLE1_F, order=3)


def law(f_hz, df_hz_per_s):
    """The known bias law of these runs: 1.5 + 0.4 f + 0.02 f² + 3000 df. [°/h]"""
    return 1.5 + 0.4 * f_hz + 0.02 * f_hz**2 + 3000.0 * df_hz_per_s


def ramp_run(seed, start_c=20.0, end_c=-20.0, hours=5.0, sample_rate_hz=10.0, noise_dph=2.0,
             tau_s=2600.0, ramp_hours=2.0, input_rate_dph=10.0):
    """Chamber ramp then hold; resonator a first-order lag; bias = :func:`law` + white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 1.0 / sample_rate_hz)
    chamber = np.clip(start_c + (end_c - start_c) * t / (ramp_hours * 3600.0),
                      min(start_c, end_c), max(start_c, end_c))
    a = -np.expm1(-1.0 / (tau_s * sample_rate_hz))
    resonator = signal.lfilter([a], [1.0, a - 1.0], chamber, zi=[(1.0 - a) * start_c])[0]
    rate_c_per_s = (chamber - resonator) / tau_s
    f = THERMOMETER.frequency(resonator) - THERMOMETER.frequency(20.0)
    df = THERMOMETER.slope_hz_per_c(resonator) * rate_c_per_s
    bias = law(f, df)
    return Recording(
        {
            "time_s": t,
            "freq_hz": THERMOMETER.frequency(resonator) + rng.normal(0.0, 0.002, t.size),
            "rate_dph": input_rate_dph + bias + rng.normal(0.0, noise_dph, t.size),
            "chamber_c": chamber,
            "resonator_c": resonator,
            "bias_dph": bias,
        },
        Metadata(sample_rate_hz=sample_rate_hz, input_rate_dph=input_rate_dph, unit="synthetic"),
        source=f"synthetic-{seed}",
    )


def block_std(x, rows):
    """1-sigma of non-overlapping block means (bias stability by hand)."""
    n = x.size // rows
    return float(np.std(x[: n * rows].reshape(n, rows).mean(axis=1), ddof=1))


# -- a scale factor with known coefficients (for the firmware exports) -------------------
def scale_factor(reference_hz: float) -> ScaleFactorModel:
    """k = 150 - 12 x + 3 x^2 ppm, x = (freq - f_ref) / 8 Hz, fitted over -10..+30 degC."""
    low, high = THERMOMETER.frequency(np.array([-10.0, 30.0]))
    return ScaleFactorModel(
        reference_hz=reference_hz, scale_hz=8.0, candidates=("f", "f^2", "f^3"),
        selected=("f", "f^2"), intercept_ppm=150.0,
        coefficients_ppm={"f": -12.0 / 8.0, "f^2": 3.0 / 64.0},
        standard_errors_ppm={"const": 1.0, "f": 0.1, "f^2": 0.01},
        pvalues={"const": 0.0, "f": 0.0, "f^2": 0.0}, scaled_coefficients=(-12.0, 3.0),
        covariance=((1.0, 0.0, 0.0), (0.0, 0.01, 0.0), (0.0, 0.0, 0.0001)),
        freq_range_hz=(float(low), float(high)), input_rate_range_dph=(3.6e4, 1.08e6),
        residual_ppm=2.0,
        groups=tuple(ScaleGroup(freq_hz=float(f), k_ppm=150.0, k_se_ppm=1.0, bias_dph=0.0, n=4,
                                rows=4000)
                     for f in THERMOMETER.frequency(np.array([-10.0, 10.0, 30.0]))))


def with_scale_factor(model: Model | AxisModel, sf: ScaleFactorModel) -> Model | AxisModel:
    """The model (every axis) or the axis with a scale factor."""
    if isinstance(model, AxisModel):
        return dataclasses.replace(model, scale_factor=sf)
    return dataclasses.replace(model, axes={a: dataclasses.replace(p, scale_factor=sf)
                                            for a, p in model.axes.items()})


def with_heating_extra(run, per_hz_per_s=2000.0, tau_s=2600.0):
    """A :func:`ramp_run` whose bias has an extra per_hz_per_s·df while heating (hysteresis)."""
    df = (THERMOMETER.slope_hz_per_c(run["resonator_c"])
          * (run["chamber_c"] - run["resonator_c"]) / tau_s)
    extra = per_hz_per_s * np.maximum(df, 0.0)
    return run.with_columns(rate_dph=run.rate_dph + extra, bias_dph=run["bias_dph"] + extra)


#: Terms of :func:`lagged_model`: the second rate filter, the gradient and an extra channel.
LAGGED_TERMS = ("f", "f^2", "df", "d2", "g", "f*g", "a_drive", "f*a_drive")


def lagged_run(seed, start_c=20.0, end_c=-20.0, hours=3.0, drive_amplitude_v=0.05):
    """A :func:`ramp_run` with a housing thermistor (lag 900 s of the chamber) and a logged
    drive amplitude ``drive_v``; the bias also depends on the housing - resonator gradient
    and the drive."""
    run = ramp_run(seed, start_c=start_c, end_c=end_c, hours=hours)
    chamber, resonator, t = run["chamber_c"], run["resonator_c"], run.time_s
    a = -np.expm1(-1.0 / (900.0 * run.sample_rate_hz))
    housing = signal.lfilter([a], [1.0, a - 1.0], chamber, zi=[(1.0 - a) * chamber[0]])[0]
    drive = 2.5 + drive_amplitude_v * np.sin(2.0 * np.pi * t / 1700.0 + seed)
    extra = 0.4 * (housing - resonator) + 20.0 * (drive - 2.5)
    return run.with_columns(housing_c=housing, drive_v=drive, rate_dph=run.rate_dph + extra,
                            bias_dph=run["bias_dph"] + extra)


def lagged_model():
    """A unit model whose drift terms use d2, g and a_drive (all of :data:`LAGGED_TERMS`)."""
    from hrgtc import drift
    from hrgtc.model import Model

    fitted = drift.fit([lagged_run(seed=5), lagged_run(seed=6, start_c=-20.0, end_c=20.0)],
                       THERMOMETER, terms=LAGGED_TERMS, initial=LAGGED_TERMS, premove=0.999999,
                       options={"rate_tau2_s": 120.0}, aux_columns={"drive": "drive_v"})
    return Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted), unit="synthetic-lagged")
