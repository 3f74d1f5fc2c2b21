"""Fused compensation kernel: one pass over a block, sample by sample (numba, private).

:class:`hrgtc.compensate.Compensator` calls :func:`compensate_block` instead of a
dozen numpy passes. Per sample it does, in the same floating-point operations
and order as the numpy reference path (so results agree to rounding):

* the causal df/dt (dh/dt) filter of :func:`hrgtc.features.causal_rate`, two
  exact first-order stages ``y = z + alpha x; z = beta y`` (scipy's ``lfilter``
  in transposed direct form II), state carried across calls;
* the drift model of :func:`hrgtc.features.tangent_extension`: each term a
  product of powers of the scaled variables, summed in term order, and beyond
  the training ranges the gradient at the clipped point times the excess;
* the thermometer inverse of :meth:`hrgtc.thermometry.Thermometer.temperature`:
  the Chebyshev start, clipped to the bracket, then Newton steps until one is
  below the one-step limit; a sample that does not converge is marked NaN and
  counted, and the caller hands it to the bracketed slow path;
* the range flags and out-of-range counts of the compensator.

The term grammar is not hard-coded: terms come in as an exponent matrix over
the variables ``(f, df, h, dh)`` and their derivatives as precomputed
(factor, exponents) tables, built by :func:`plan` from a fitted model. Compiled
with ``cache=True`` (first call compiles, later processes load the cache) and
``nogil=True`` (a writer thread runs beside it); no fastmath, so no
reassociation or fused multiply-add changes the numbers.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from hrgtc.drift import DriftModel
from hrgtc.features import VARIABLES, rate_filter_coefficients
from hrgtc.thermometry import Thermometer

#: Variable order of the exponent matrices: the grammar's order (f, df, h, dh).
ORDER = tuple(VARIABLES)
#: Slots of ``counts``: samples outside the f/h ranges, outside the df/dh ranges,
#: and samples whose Newton iteration did not converge (left NaN).
OUT_OF_RANGE, RATE_OUT_OF_RANGE, NOT_CONVERGED = 0, 1, 2


@dataclass(frozen=True)
class KernelPlan:
    """A fitted model laid out as the arrays :func:`compensate_block` reads.

    Attributes
    ----------
    filter
        ``[alpha, beta, gain, reference_freq_hz, reference_c]`` of the rate filter
        (gain ``alpha * sample_rate_hz / beta`` turns y1 - y2 into a rate).
    uses_housing
        Whether h/dh are computed (the recording then needs ``housing_c``).
    exponents
        (n_terms, 4) powers of (f, df, h, dh) in each term. ``int64``
    coefficients
        Scaled coefficients, term order; ``intercept`` is B0. [°/h]
    scales
        Scale of each variable (1 where unused).
    tangent, low, high
        Per variable: continue along the tangent beyond [low, high] (a used
        variable with a training range).
    flagged
        Per variable: counted in ``in_range`` (f, h) or the rate count (df, dh).
    d_factor, d_exponents, d_constant
        Derivative of term k by variable v: ``d_factor[v, k] * rest``, rest the
        term of exponents ``d_exponents[v, k]`` or 1 when ``d_constant[v, k]``;
        ``d_factor`` is 0 where the term lacks v.
    thermometer
        ``[centre_c, scale_c, map offset, map scale, t_low, t_high, f_low, f_high,
        f_cal_low, f_cal_high, one_step_limit, tolerance]`` of the inverse.
    poly, slope, chebyshev
        Scaled f(z) coefficients, their derivative, the Chebyshev start series.
    """

    filter: np.ndarray
    uses_housing: bool
    exponents: np.ndarray
    coefficients: np.ndarray
    intercept: float
    scales: np.ndarray
    tangent: np.ndarray
    low: np.ndarray
    high: np.ndarray
    flagged: np.ndarray
    d_factor: np.ndarray
    d_exponents: np.ndarray
    d_constant: np.ndarray
    thermometer: np.ndarray
    poly: np.ndarray
    slope: np.ndarray
    chebyshev: np.ndarray


def plan(drift: DriftModel, thermometer: Thermometer, variables: tuple[str, ...]) -> KernelPlan:
    """Lay out a drift model and thermometer for the kernel.

    Parameters
    ----------
    drift
        The drift model applied (frequency or housing).
    thermometer
        The unit's thermometer (must be monotonic; the caller checks).
    variables
        Variables the compensator computes (``f``, ``df`` and the model's).
    """
    s = drift.settings
    alpha, beta = rate_filter_coefficients(s.rate_tau_s, s.sample_rate_hz)
    terms = drift._terms
    used = {v for t in terms for v in t.variables}
    n = len(terms)
    exponents = np.zeros((n, 4), dtype=np.int64)
    d_factor = np.zeros((4, n))
    d_exponents = np.zeros((4, n, 4), dtype=np.int64)
    d_constant = np.zeros((4, n), dtype=np.bool_)
    scales = np.ones(4)
    for j, v in enumerate(ORDER):
        if v in used:
            scales[j] = s.scales[v]
    for k, (term, c) in enumerate(zip(terms, drift.scaled_coefficients, strict=True)):
        for v, p in term.powers:
            exponents[k, ORDER.index(v)] = p
        for j, v in enumerate(ORDER):
            multiplier, rest = term.derivative(v)
            if multiplier and v in used:
                d_factor[j, k] = c * multiplier / s.scales[v]  # as tangent_extension
                d_constant[j, k] = rest is None
                for w, p in () if rest is None else rest.powers:
                    d_exponents[j, k, ORDER.index(w)] = p
    low = np.array([drift.ranges.get(v, (-np.inf, np.inf))[0] for v in ORDER], dtype=float)
    high = np.array([drift.ranges.get(v, (-np.inf, np.inf))[1] for v in ORDER], dtype=float)
    tangent = np.array([v in used and v in drift.ranges for v in ORDER])
    flagged = np.array([v in drift.ranges and v in variables for v in ORDER])
    inverse = thermometer._inverse
    a = np.asarray(thermometer.scaled_coefficients, dtype=np.float64)
    return KernelPlan(
        filter=np.array([alpha, beta, alpha * s.sample_rate_hz / beta, s.reference_freq_hz,
                         s.reference_c]),
        uses_housing=any(v in ("h", "dh") for v in variables),
        exponents=exponents,
        coefficients=np.asarray(drift.scaled_coefficients, dtype=np.float64).reshape(n),
        intercept=float(drift.intercept_dph),
        scales=scales,
        tangent=tangent,
        low=low,
        high=high,
        flagged=flagged,
        d_factor=d_factor,
        d_exponents=d_exponents,
        d_constant=d_constant,
        thermometer=np.array([thermometer.centre_c, thermometer.scale_c, *inverse.start_map,
                              *inverse.t_bracket, *inverse.f_bracket, *inverse.f_calibrated,
                              inverse.one_step_limit, inverse.tolerance], dtype=np.float64),
        poly=a,
        slope=a[1:] * np.arange(1, a.size),  # as Thermometer.slope_hz_per_c
        chebyshev=np.asarray(inverse.start_coefficients, dtype=np.float64),
    )


def new_state() -> np.ndarray:
    """Filter state at rest: ``[y1_f, y2_f, y1_h, y2_h, started_f, started_h]``."""
    return np.zeros(6)


# -- the kernel -------------------------------------------------------------------------
@njit(cache=True, nogil=True)
def _term(exponents, k, x):  # pragma: no cover - compiled
    """Product of powers x_v ** p_v of row k, as features.Term.evaluate multiplies."""
    out = 1.0
    first = True
    for v in range(4):
        p = exponents[k, v]
        if p > 0:
            factor = x[v]
            for _ in range(p - 1):
                factor = factor * x[v]
            if first:
                out = factor
                first = False
            else:
                out = out * factor
    return out


@njit(cache=True, nogil=True)
def _horner(c, z):  # pragma: no cover - compiled
    result = c[c.size - 1]
    for i in range(c.size - 2, -1, -1):
        result = result * z
        result = result + c[i]
    return result


@njit(cache=True, nogil=True)
def _filter(x, alpha, beta, state, i1, i2, started):  # pragma: no cover - compiled
    """One sample of the two low-pass stages; returns y1 - y2."""
    if state[started] == 0.0:
        state[i1] = x
        state[i2] = x
        state[started] = 1.0
    y1 = beta * state[i1] + alpha * x
    y2 = beta * state[i2] + alpha * y1
    state[i1] = y1
    state[i2] = y2
    return y1 - y2


@njit(cache=True, nogil=True)
def compensate_block(freq_hz, rate_dph, housing_c, filt, uses_housing, state,
                     exponents, coefficients, intercept, scales, tangent, low, high, flagged,
                     d_factor, d_exponents, d_constant, therm, poly, slope, chebyshev,
                     out_rate, out_bias, out_temp, out_in_range, counts):  # pragma: no cover
    """Compensate one block in place; see the module docstring for what is computed.

    ``state`` (filter) and ``counts`` (int64, see :data:`OUT_OF_RANGE`) are updated.
    """
    alpha, beta, gain, ref_f, ref_h = filt[0], filt[1], filt[2], filt[3], filt[4]
    centre, scale_c, map_offset, map_scale = therm[0], therm[1], therm[2], therm[3]
    t_low, t_high, f_low, f_high = therm[4], therm[5], therm[6], therm[7]
    f_cal_low, f_cal_high, one_step_limit, tolerance = therm[8], therm[9], therm[10], therm[11]
    n_terms = coefficients.size
    n_cheb = chebyshev.size
    value = np.zeros(4)
    held = np.zeros(4)
    scaled = np.zeros(4)
    delta = np.zeros(4)
    for i in range(freq_hz.size):
        # variables f, df (h, dh): features.FeatureStream
        value[0] = freq_hz[i] - ref_f
        value[1] = _filter(value[0], alpha, beta, state, 0, 1, 4) * gain
        if uses_housing:
            value[2] = housing_c[i] - ref_h
            value[3] = _filter(value[2], alpha, beta, state, 2, 3, 5) * gain
        # drift model: features.tangent_extension
        outside = False
        for v in range(4):
            x = value[v]
            if tangent[v]:
                if x < low[v]:
                    x = low[v]
                elif x > high[v]:
                    x = high[v]
            held[v] = x
            delta[v] = value[v] - x
            outside = outside or (tangent[v] and delta[v] != 0.0)
            scaled[v] = x / scales[v]
        bias = intercept
        for k in range(n_terms):
            bias += coefficients[k] * _term(exponents, k, scaled)
        if outside:
            for v in range(4):
                if tangent[v] and delta[v] != 0.0:
                    gradient = 0.0
                    for k in range(n_terms):
                        if d_factor[v, k] != 0.0:
                            if d_constant[v, k]:
                                gradient += d_factor[v, k]
                            else:
                                gradient += d_factor[v, k] * _term(d_exponents[v], k, scaled)
                    bias += gradient * delta[v]
        out_bias[i] = bias
        out_rate[i] = rate_dph[i] - bias
        # thermometer inverse: Thermometer.temperature
        f = freq_hz[i]
        clipped = f
        if clipped < f_low:
            clipped = f_low
        elif clipped > f_high:
            clipped = f_high
        u = map_offset + map_scale * clipped
        two_u = 2.0 * u
        b1 = 0.0
        b2 = 0.0
        for j in range(n_cheb - 1, 0, -1):
            b1, b2 = two_u * b1 - b2 + chebyshev[j], b1
        t = u * b1 - b2 + chebyshev[0]
        if t < t_low:
            t = t_low
        elif t > t_high:
            t = t_high
        limit = one_step_limit
        step = np.inf
        for _ in range(4):
            z = (t - centre) / scale_c
            step = (_horner(poly, z) - clipped) / (_horner(slope, z) / scale_c)
            t -= step
            if not abs(step) > limit:
                break
            limit = tolerance
        if not (f >= f_low and f <= f_high):
            t = np.nan
        elif not (abs(step) <= limit and t >= t_low and t <= t_high):
            t = np.nan
            counts[2] += 1
        out_temp[i] = t
        # flags: Compensator._block
        ok = f >= f_cal_low and f <= f_cal_high
        rate_ok = True
        for v in range(4):
            if flagged[v]:
                inside = value[v] >= low[v] and value[v] <= high[v]
                if v == 0 or v == 2:
                    ok = ok and inside
                else:
                    rate_ok = rate_ok and inside
        out_in_range[i] = 1.0 if ok else 0.0
        if not ok:
            counts[0] += 1
        if not rate_ok:
            counts[1] += 1


def run(block_plan: KernelPlan, state: np.ndarray, freq_hz: np.ndarray, rate_dph: np.ndarray,
        housing_c: np.ndarray | None, out: dict[str, np.ndarray], counts: np.ndarray) -> None:
    """Call :func:`compensate_block` with a plan's arrays (outputs in ``out``)."""
    p = block_plan
    compensate_block(
        freq_hz, rate_dph, freq_hz if housing_c is None else housing_c, p.filter,
        p.uses_housing, state, p.exponents, p.coefficients, p.intercept, p.scales, p.tangent,
        p.low, p.high, p.flagged, p.d_factor, p.d_exponents, p.d_constant, p.thermometer,
        p.poly, p.slope, p.chebyshev, out["rate_comp_dph"], out["bias_model_dph"],
        out["resonator_c_est"], out["in_range"], counts,
    )
