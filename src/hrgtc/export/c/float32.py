"""The float32 build of the firmware export: its constants, a numpy mirror of its arithmetic
and its worst error against the double model.

An FPU-only microcontroller (Cortex-M4F, M33) computes in float32, whose 24-bit
significand resolves 4.4 kHz only to 0.5 mHz, i.e. about 2 m°C. The float build
therefore takes the frequency *centred*: ``f = freq_hz - CENTRE_HZ`` with the
centre the drift model's reference frequency f_ref, so ``f`` is already the
model's variable (a few Hz, resolved to ~1e-7 Hz) and the thermometer is written
about the same centre (its constant term ``a0 - f_ref`` is taken in double at
export time). The df/dt filter keeps its state as differences (the first stage's
lag ``f_prev - y1`` and ``y1 - y2``), which are small and carry the rate, instead of the
two low-passed levels, whose difference would cancel float32's digits; each is
updated by a small increment, with compensated (Kahan) summation so that rounding
does not accumulate over the filter's tau/dt samples of memory. It is the filter of
:func:`hrgtc.drift.features.causal_rate` (each step exact over its own Δt, whose
weights are computed in double and rounded to float once per distinct Δt).

:func:`float_constants` rounds every constant once, so the C text
(:mod:`hrgtc.export.c.source`) prints exactly these float32 values and the
mirror below computes with them; :func:`mirror_bias`, :func:`mirror_temperature`
and :func:`mirror_rate` evaluate the generated code's operations one by one in
``numpy.float32`` (the order of the C statements), :func:`mirror_gradient` the
gradient ``g = housing_c - T(f)`` from the float inverse, and :func:`float_accuracy`
compares them with the double model over dense grids of the trained ranges.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.drift.features import Term
from hrgtc.drift.rate_filter import DT_REL_TOLERANCE, SERIES_LIMIT, series_coefficients
from hrgtc.drift.variables import variable
from hrgtc.export.c.plan import CPlan
from hrgtc.export.c.thermometer import NEWTON_MAX_ITER
from hrgtc.model import Model

F32 = np.float32
SERIES = series_coefficients()
#: Points of the error grids: the frequency line, and the grid of the drift variables.
TEMPERATURE_POINTS = 20001
BIAS_POINTS = 250_000
#: The stated bounds are this many times the worst error measured on the grids: inputs
#: between grid points (and a run's noisy df/dt) round a little differently.
MARGIN = 2.0


@dataclass(frozen=True, eq=False)
class FloatConstants:
    """Every constant of the float build, rounded once to float32.

    Attributes
    ----------
    centre_hz
        CENTRE_HZ = f_ref, kept in double: the firmware subtracts it. [Hz]
    tau_s, tau
        The df/dt filter's time constant, in double (its weights are computed in double)
        and in float (the rate is the difference divided by it). [s]
    reference_c
        Origin of the housing variable h. [°C]
    th_centre_c, th_scale_c
        z = (T - centre) / scale of the thermometer's polynomial.
    th_coefficients, th_derivative
        Scaled coefficients of f(T) - CENTRE_HZ (ascending) and of its derivative in z.
    table_f, table_t
        The inverse's start table, centred frequency ascending. [Hz, °C]
    f_low, f_high
        Calibrated range of the centred frequency. [Hz]
    tolerance
        Newton tolerance of the float inverse. [°C]
    intercept, coefficients, scales, ranges
        The drift model: B0 [°/h], scaled coefficients (term order), the variables'
        scales and training ranges.
    """

    centre_hz: float
    tau_s: float
    tau: np.float32
    reference_c: np.float32
    th_centre_c: np.float32
    th_scale_c: np.float32
    th_coefficients: np.ndarray
    th_derivative: np.ndarray
    table_f: np.ndarray
    table_t: np.ndarray
    f_low: np.float32
    f_high: np.float32
    tolerance: np.float32
    intercept: np.float32
    coefficients: np.ndarray
    scales: dict[str, np.float32]
    ranges: dict[str, tuple[np.float32, np.float32]]


def float_constants(model: Model, plan: CPlan) -> FloatConstants:
    """The float build's constants from the double plan, centred on f_ref."""
    drift, thermometer = model.drift, model.thermometer
    settings = drift.settings
    centre = float(settings.reference_freq_hz)
    centred = np.array(plan.th_coefficients, dtype=np.float64)
    centred[0] = centred[0] - centre  # a0 - f_ref in double: a few Hz
    table_f = (plan.grid_f - centre).astype(F32)
    table_t = plan.grid_t.astype(F32)
    eps = float(np.finfo(F32).eps)
    lo, hi = plan.extension
    slope_min = float(np.min(np.abs(np.diff(plan.grid_f) / np.diff(plan.grid_t))))
    # converged iterates still move by the float rounding of f(T) (its largest term) and of T
    tolerance = max(4 * eps * max(abs(lo), abs(hi), hi - lo),
                    16 * eps * float(np.sum(np.abs(centred))) / slope_min)
    return FloatConstants(
        centre_hz=centre,
        tau_s=float(plan.tau_s),
        tau=F32(plan.tau_s),
        reference_c=F32(settings.reference_c),
        th_centre_c=F32(thermometer.centre_c),
        th_scale_c=F32(thermometer.scale_c),
        th_coefficients=centred.astype(F32),
        th_derivative=np.asarray(plan.th_derivative, dtype=np.float64).astype(F32),
        table_f=table_f,
        table_t=table_t,
        f_low=F32(plan.f_range[0] - centre),
        f_high=F32(plan.f_range[1] - centre),
        tolerance=F32(tolerance),
        intercept=F32(drift.intercept_dph),
        coefficients=np.asarray(drift.scaled_coefficients, dtype=np.float64).astype(F32),
        scales={v: F32(s) for v, s in settings.scales.items()},
        ranges={v: (F32(low), F32(high)) for v, (low, high) in drift.ranges.items()},
    )


# -- the mirror: the generated C's operations, one by one, in float32 ----------------------
def _factor(x: np.ndarray, power: int) -> np.ndarray:
    if power == 1:
        return x
    if power == 2:
        return x * x
    return np.power(x, F32(power))  # powf


def _term(term: Term, x: dict[str, np.ndarray]) -> np.ndarray:
    out = None
    for v, p in term.powers:  # the C product a * b * c, left to right
        factor = _factor(x[v], p)
        out = factor if out is None else out * factor
    assert out is not None
    return out


def mirror_bias(model: Model, c: FloatConstants,
                values: dict[str, np.ndarray]) -> np.ndarray:
    """``<prefix>_bias_dph()`` of the float build. [°/h]

    ``values`` maps the model's variables (f [Hz], df [Hz/s], h [°C], dh [°C/s], g [°C],
    a_NAME [its unit] ...) to float32 arrays.
    """
    drift = model.drift
    used = list(drift.variables) if drift.selected else []
    n = np.asarray(next(iter(values.values()))).shape
    raw = {v: np.asarray(values[v], dtype=F32) for v in used}
    held, x = {}, {}
    for v in used:
        low, high = c.ranges[v]
        r = raw[v]
        held[v] = np.where(r < low, low, np.where(r > high, high, r)).astype(F32)
        x[v] = held[v] / c.scales[v]
    total = np.zeros(n, dtype=F32)
    for k, term in enumerate(drift.terms):
        total = total + c.coefficients[k] * _term(term, x)
    for v in used:
        low, high = c.ranges[v]
        outside = (raw[v] < low) | (raw[v] > high)
        if not np.any(outside):
            continue
        gradient = np.zeros(n, dtype=F32)
        for k, term in enumerate(drift.terms):
            multiplier, rest = term.derivative(v)
            if not multiplier:
                continue
            factor = c.coefficients[k] * F32(multiplier) / c.scales[v]
            gradient = gradient + (factor if rest is None else factor * _term(rest, x))
        total = np.where(outside, total + gradient * (raw[v] - held[v]), total)
    return (c.intercept + total).astype(F32)


def mirror_scale(model: Model, f_hz: np.ndarray) -> np.ndarray:
    """``<prefix>_scale_ppm()`` of the float build, from the centred frequency. [ppm]"""
    sf = model.scale_factor
    assert sf is not None
    f = np.asarray(f_hz, dtype=F32)
    offset = sf.reference_hz - model.drift.settings.reference_freq_hz
    if offset:
        f = f - F32(offset)
    low = F32(sf.freq_range_hz[0] - sf.reference_hz)
    high = F32(sf.freq_range_hz[1] - sf.reference_hz)
    scale = F32(sf.scale_hz)
    coefficients = np.asarray(sf.scaled_coefficients, dtype=np.float64).astype(F32)
    held = np.where(f < low, low, np.where(f > high, high, f)).astype(F32)
    x = {"f": held / scale}
    k = np.full(f.shape, F32(sf.intercept_ppm), dtype=F32)
    for j, term in enumerate(sf.terms):
        k = k + coefficients[j] * _term(term, x)
    if sf.terms:
        gradient = np.zeros(f.shape, dtype=F32)
        for j, term in enumerate(sf.terms):
            multiplier, rest = term.derivative("f")
            factor = coefficients[j] * F32(multiplier) / scale
            gradient = gradient + (factor if rest is None else factor * _term(rest, x))
        k = np.where((f < low) | (f > high), k + gradient * (f - held), k)
    return k.astype(F32)


def _horner(coefficients: np.ndarray, z: np.ndarray) -> np.ndarray:
    r = np.full(z.shape, coefficients[-1], dtype=F32)
    for k in range(coefficients.size - 2, -1, -1):
        r = r * z + coefficients[k]
    return r


def mirror_temperature(c: FloatConstants, f_hz: np.ndarray, increasing: bool) -> np.ndarray:
    """``<prefix>_temperature_c()`` of the float build, from the centred frequency. [°C]"""
    f = np.asarray(f_hz, dtype=F32)
    out = np.full(f.shape, np.nan, dtype=F32)
    inside = (f >= c.table_f[0]) & (f <= c.table_f[-1])
    fi = f[inside]
    low = np.maximum(np.searchsorted(c.table_f, fi, side="left"), 1)
    f0, f1 = c.table_f[low - 1], c.table_f[low]
    t0, t1 = c.table_t[low - 1], c.table_t[low]
    lower = np.where(t0 < t1, t0, t1)
    upper = np.where(t0 < t1, t1, t0)
    t = t0 + (fi - f0) * (t1 - t0) / (f1 - f0)
    t = np.where(t < lower, lower, np.where(t > upper, upper, t))
    active = np.ones(fi.shape, dtype=bool)
    half = F32(0.5)
    for _ in range(NEWTON_MAX_ITER):
        if not np.any(active):
            break
        z = (t - c.th_centre_c) / c.th_scale_c
        residual = _horner(c.th_coefficients, z) - fi
        step = residual / (_horner(c.th_derivative, z) / c.th_scale_c)
        candidate = t - step
        above = residual > 0 if increasing else ~(residual > 0)
        upper = np.where(active & above, np.where(t < upper, t, upper), upper)
        lower = np.where(active & ~above, np.where(t > lower, t, lower), lower)
        candidate = np.where((candidate >= lower) & (candidate <= upper), candidate,
                             half * (lower + upper))
        change = np.abs(candidate - t)
        t = np.where(active, candidate, t)
        active = active & (change > c.tolerance)
    out[inside] = t
    return out


def mirror_gradient(c: FloatConstants, housing_c: np.ndarray, f_hz: np.ndarray,
                    increasing: bool) -> np.ndarray:
    """The float build's ``g = housing_c - T(f)``, T from :func:`mirror_temperature`. [°C]

    ``housing_c`` as firmware passes it (float32), ``f_hz`` centred; NaN beyond the inverse.
    """
    temperature = mirror_temperature(c, f_hz, increasing)
    return (np.asarray(housing_c, dtype=F32) - temperature).astype(F32)


def step_weights64(dt_s: float, tau_s: float) -> tuple[float, float]:
    """The C ``rate_weights()``: (a, p) of one step, in double, the same operations."""
    r = dt_s / tau_s
    a = -math.expm1(-r)
    if r < SERIES_LIMIT:
        q = SERIES[-1]
        for coefficient in SERIES[-2::-1]:
            q = q * r
            q = q + coefficient
        return a, q * r
    return a, (r - a) / r


def mirror_rate(c: FloatConstants, x: np.ndarray, dt_s: np.ndarray,
                tau_s: float | None = None) -> np.ndarray:
    """The float build's causal rate of one signal (df/dt of f, or dh/dt), from rest. [/s]

    Its ``rate_update()``: the lag ``x_prev - y1`` and the difference ``y1 - y2`` of the
    two stages, each updated by its small increment with compensated (Kahan) summation,
    with the weights of each step's ``dt_s`` (float, as firmware passes it; the first is
    ignored) computed in double and rounded to float when dt moves by more than the
    tolerance. Runs along the last axis (rows of signals at once, one dt per column).
    ``tau_s``: the filter's time constant (default the df/dt filter's; d2's
    ``rate_tau2_s``). [s]
    """
    tau64 = c.tau_s if tau_s is None else float(tau_s)
    tau32 = F32(tau64)
    x = np.asarray(x, dtype=F32)
    dt_s = np.asarray(dt_s, dtype=F32)
    out = np.empty_like(x)
    if x.shape[-1] == 0:
        return out
    previous = x[..., 0].copy()
    lag = np.zeros_like(previous)
    lag_carry = np.zeros_like(previous)
    difference = np.zeros_like(previous)
    difference_carry = np.zeros_like(previous)
    tolerance = F32(DT_REL_TOLERANCE)
    cached, a, p = F32(-1.0), F32(0.0), F32(0.0)
    out[..., 0] = 0.0
    for i in range(1, x.shape[-1]):
        dt = dt_s[i] if dt_s[i] > 0 else F32(0.0)
        if not abs(dt - cached) <= tolerance * cached:
            a64, p64 = step_weights64(float(dt), tau64)
            cached, a, p = dt, F32(a64), F32(p64)
        delta = x[..., i] - previous
        previous = x[..., i]
        c1 = a * lag + p * delta
        increment = (delta - c1) - lag_carry
        total = lag + increment
        lag_carry = (total - lag) - increment
        lag = total
        c2 = a * difference + p * c1
        increment = (c1 - c2) - difference_carry
        total = difference + increment
        difference_carry = (total - difference) - increment
        difference = total
        out[..., i] = difference / tau32
    return out


# -- the worst error against the double model ----------------------------------------------
@dataclass(frozen=True)
class FloatAccuracy:
    """Worst float32-against-double differences of the float build, measured at export.

    Attributes
    ----------
    temperature_c
        Over the calibrated frequency range (``TEMPERATURE_POINTS`` frequencies). [°C]
    bias_dph
        B(f, df, ...) over a grid of the trained ranges of its variables; g enters as
        firmware computes it, ``housing_c`` (float32) minus the float inverse, so the
        temperature's float error is part of the figure. [°/h]
    ramp_bias_dph
        B end to end through the df/dt filter on steady ramps at rates spread over the
        trained df/dt range (0 when the model has no df term). [°/h]
    grid_points
        Points of the bias grid.
    scale_ppm
        The scale-factor error k over the calibrated frequency range (0 without one). [ppm]
    """

    temperature_c: float
    bias_dph: float
    ramp_bias_dph: float
    grid_points: int
    scale_ppm: float = 0.0

    @property
    def bound_c(self) -> float:
        """The stated bound of the temperature error: :data:`MARGIN` x the worst measured. [°C]"""
        return _round_up(MARGIN * self.temperature_c)

    @property
    def bound_dph(self) -> float:
        """Stated bound of the bias error: :data:`MARGIN` x the worst of grid and ramps. [°/h]"""
        return _round_up(MARGIN * max(self.bias_dph, self.ramp_bias_dph))


def _round_up(value: float) -> float:
    """``value`` rounded up to two significant digits (a number a header can state)."""
    if not value > 0:
        return 0.0
    digits = 1 - int(np.floor(np.log10(value)))
    return float(np.ceil(value * 10.0**digits) / 10.0**digits)


def float_accuracy(model: Model, plan: CPlan, c: FloatConstants) -> FloatAccuracy:
    """Evaluate the float build's arithmetic against the double model over the trained ranges.

    The double side is hrgtc's model at the exact inputs; the float side gets the same
    inputs rounded to float32 (the centred frequency ``freq_hz - CENTRE_HZ``), as firmware
    would pass them, so input rounding is part of the figure.
    """
    drift, thermometer = model.drift, model.thermometer
    f_low, f_high = thermometer.frequency_range_hz
    freq = np.linspace(f_low, f_high, TEMPERATURE_POINTS)
    t64 = thermometer.temperature(freq, warn=False)
    t32 = mirror_temperature(c, (freq - c.centre_hz).astype(F32), plan.increasing)
    temperature_error = float(np.max(np.abs(t32.astype(np.float64) - t64)))
    # the grid over the trained ranges of the computed variables
    axes = [v for v in plan.computed if v in drift.ranges]
    per_axis = max(2, round(BIAS_POINTS ** (1.0 / max(len(axes), 1))))
    lines = [np.linspace(*drift.ranges[v], per_axis) for v in axes]
    mesh = np.meshgrid(*lines, indexing="ij") if lines else []
    values = {v: m.ravel() for v, m in zip(axes, mesh, strict=True)}
    values.setdefault("f", np.linspace(plan.f_range[0], plan.f_range[1], per_axis)
                      - c.centre_hz)
    n = values["f"].size
    for v in plan.computed:
        values.setdefault(v, np.zeros(n))
    inputs = {v: _firmware(v, x, drift.settings) for v, x in values.items()}
    if plan.gradient:
        values, inputs = _gradient_inputs(model, plan, c, values, inputs)
    b64 = drift.predict({v: values[v] for v in drift.variables} or values)
    b32 = mirror_bias(model, c, inputs)
    bias_error = float(np.nanmax(np.abs(b32.astype(np.float64) - b64)))
    scale_error = 0.0
    scale_factor = model.scale_factor
    if scale_factor is not None:
        k64 = scale_factor.ppm(freq)
        k32 = mirror_scale(model, (freq - c.centre_hz).astype(F32))
        scale_error = float(np.max(np.abs(k32.astype(np.float64) - k64)))
    return FloatAccuracy(temperature_c=temperature_error, bias_dph=bias_error,
                         ramp_bias_dph=_ramp_error(model, plan, c), grid_points=n,
                         scale_ppm=scale_error)


def _firmware(name: str, value: np.ndarray, settings: Any) -> np.ndarray:
    """The float32 value of variable ``name`` the float build computes where the double
    model has ``value``: its module's ``firmware_value`` (a_NAME: the logged value in float
    minus the float centre), else ``value`` rounded to float32."""
    code = variable(name).c_code
    if code is None:
        return np.asarray(value).astype(F32)
    return code.firmware_value(value, name, settings)


def _gradient_inputs(model: Model, plan: CPlan, c: FloatConstants,
                     values: dict[str, np.ndarray], inputs: dict[str, np.ndarray]
                     ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """g of the double model and of the float build at the same f and housing_c.

    ``housing_c = g + T(f)`` in double; the double side keeps g exact, the float side
    gets ``float32(housing_c) - T32(f32)`` as the generated step() computes it. Where f
    is beyond the inverse both are NaN (left out of the worst error).
    """
    centre = c.centre_hz
    temperature = model.thermometer.temperature(values["f"] + centre, warn=False)
    housing = values["g"] + temperature
    values = {**values, "g": housing - temperature}
    inputs = {**inputs, "g": mirror_gradient(c, housing.astype(F32), inputs["f"],
                                             plan.increasing)}
    return values, inputs


def _ramp_error(model: Model, plan: CPlan, c: FloatConstants) -> float:
    """Worst |B32 - B64| on steady ramps through the float and the double filters.

    Nine ramps with rates spread over the trained df/dt range (and dh/dt, when the model
    uses the housing thermistor, whose input enters as ``housing_c`` in float as firmware
    passes it), from rest, for 12 filter time constants.
    """
    drift = model.drift
    rated = [v for v in drift.variables if variable(v).kind == "rate" and v in drift.ranges]
    if not rated:
        return 0.0
    from hrgtc.drift.features import causal_rate

    settings = drift.settings
    fs, tau = settings.sample_rate_hz, settings.rate_tau_s
    samples = int(min(12 * tau * fs, 100_000))
    centred_time_s = (np.arange(samples) - samples / 2) / fs
    dt32 = np.full(samples, F32(1.0 / fs))
    values64: dict[str, np.ndarray] = {}
    values32: dict[str, np.ndarray] = {}
    for level, rate in (("f", "df"), ("h", "dh")):
        if level not in plan.computed and rate not in plan.computed:
            continue
        middle = 0.5 * sum(drift.ranges[level]) if level in drift.ranges else 0.0
        rates = np.linspace(*drift.ranges[rate], 9) if rate in drift.ranges else np.zeros(9)
        x = middle + rates[:, None] * centred_time_s[None, :]
        if level == "h":  # firmware passes housing_c; the code subtracts REFERENCE_C
            x32 = (x + settings.reference_c).astype(F32) - c.reference_c
        else:
            x32 = x.astype(F32)
        values64[level], values32[level] = x, x32
        values64[rate] = np.vstack([causal_rate(row, tau, fs)[0] for row in x])
        values32[rate] = mirror_rate(c, x32, dt32)
    if plan.gradient:  # g held at the middle of its range, through both inverses
        middle = 0.5 * sum(drift.ranges["g"]) if "g" in drift.ranges else 0.0
        values64["g"] = np.full(values64["f"].shape, middle)
        values64, values32 = _gradient_inputs(model, plan, c, values64, values32)
    for v in drift.variables:  # the other rates (d2) through their own float and double filters
        spec = variable(v)
        if v not in values64 and spec.rate_of is not None and spec.rate_of[0] in values64:
            level, field = spec.rate_of
            tau_v = float(getattr(settings, field))
            values64[v] = np.vstack([causal_rate(row, tau_v, fs)[0] for row in values64[level]])
            values32[v] = mirror_rate(c, values32[level], dt32, tau_v)
    for v in drift.variables:  # the other levels (a_NAME) held at the middle of their range
        if v not in values64:
            middle = 0.5 * sum(drift.ranges[v]) if v in drift.ranges else 0.0
            values64[v] = np.full(values64["f"].shape, middle)
            values32[v] = _firmware(v, values64[v], settings)
    worst = 0.0
    for row in range(9):
        b64 = drift.predict({v: values64[v][row] for v in drift.variables})
        b32 = mirror_bias(model, c, {v: x[row] for v, x in values32.items()})
        worst = max(worst, float(np.nanmax(np.abs(b32.astype(np.float64) - b64))))
    return worst
