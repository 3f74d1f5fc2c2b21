"""Fused compensation kernel: one pass over a block, sample by sample (numba, private).

:class:`hrgtc.compensate.Compensator` calls :func:`compensate_block` instead of a
dozen numpy passes. Per sample it does, in the same floating-point operations
and order as the numpy reference path (so results agree to rounding):

* the causal df/dt (dh/dt) filter of :func:`hrgtc.drift.features.causal_rate`, two
  first-order stages updated exactly over each sample's own Δt (the samples'
  times), by the very function the numpy path runs
  (:func:`hrgtc.drift._rate_numba.filter_run`), state carried across calls;
* the drift model of :func:`hrgtc.drift.features.tangent_extension`: each term a
  product of powers of the scaled variables, summed in term order, and beyond
  the training ranges the gradient at the clipped point times the excess;
* the thermometer inverse of :meth:`hrgtc.thermometry.Thermometer.temperature`:
  the Chebyshev start, clipped to the bracket, then Newton steps until one is
  below the one-step limit; a sample that does not converge is counted and solved
  by the safeguarded Newton iteration in its cell of the dense table (the slow path
  of ``Thermometer._bracketed_newton``). It runs before the drift model, which needs
  it for the gradient ``g = housing_c - T(freq_hz)`` of
  :class:`hrgtc.drift.features.FeatureStream` (NaN beyond the bracket, as there);
* the range flags and out-of-range counts of the compensator.

The term grammar is not hard-coded: terms come in as an exponent matrix over
the variables ``(f, df, h, dh, g)`` and their derivatives as precomputed
(factor, exponents) tables, built by :func:`plan` from a fitted model.

Speed: the block is worked through in tiles of :data:`TILE` samples whose
scratch rows stay in cache, every inner loop runs over samples (the filter is
the only serial one) and the thermometer's series have fixed, zero-padded
lengths, so LLVM vectorises the loops; :func:`run` compensates the two halves of
a long chunk on two threads. Compiled with ``cache=True`` (the first call
compiles, later processes load the cache), ``nogil=True`` and
``error_model="numpy"`` (IEEE division, as numpy, instead of Python's
ZeroDivisionError check, which also blocks vectorisation); no fastmath, so no
reassociation or fused multiply-add changes the numbers.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from hrgtc.compensate._kernel_thermometer import (
    CHEBYSHEV_SIZE,
    POLY_SIZE,
    _bracketed_scalar,
    _newton_scalar,
    _start_and_step,
)
from hrgtc.core.timeline import settle_threshold_s
from hrgtc.drift import DriftModel
from hrgtc.drift._rate_numba import filter_run
from hrgtc.drift.rate_filter import STATE_SIZE, check_tau
from hrgtc.drift.rate_filter import new_state as new_filter_state
from hrgtc.drift.variables import unsupported
from hrgtc.thermometry import Thermometer

#: Variable order of the exponent matrices (f, df, h, dh, g). The heating/cooling switch
#: ``dpos``, the second rate filter ``d2`` and the user's channels ``a_NAME`` are not
#: computed here (:func:`supports_variables`): a model using them runs on the numpy engine,
#: which gives the same numbers.
ORDER = ("f", "df", "h", "dh", "g")
#: Indices of the rates in :data:`ORDER` (flagged in the rate count; the others are levels).
RATES = (1, 3)
#: Slots of ``counts``: settled samples outside the f/h/g ranges, outside the df/dh
#: ranges, samples whose Newton iteration did not converge (solved by the bracketed slow
#: path), and samples of the filter's settling time at the start of the run (the range
#: counts and ``extremes`` leave those out: they are flagged by that reason only).
OUT_OF_RANGE, RATE_OUT_OF_RANGE, NOT_CONVERGED, SETTLING = 0, 1, 2, 3
#: Then ``counts[VARIABLE_OUT + v]``: samples outside the training range of variable v of
#: :data:`ORDER` (each apart, so the range report can say which variable left its range),
#: and ``counts[TEMPERATURE_OUT]``: outside the calibrated frequencies or f's range.
VARIABLE_OUT = 4
TEMPERATURE_OUT = VARIABLE_OUT + len(ORDER)
#: Length of ``counts``.
N_COUNTS = TEMPERATURE_OUT + 1
#: Slots of ``extremes``: the smallest and largest f and df/dt seen [Hz, Hz/s]; then,
#: for every variable v of :data:`ORDER`, ``extremes[2 v]`` and ``extremes[2 v + 1]``.
F_MIN, F_MAX, DF_MIN, DF_MAX = 0, 1, 2, 3


@dataclass(frozen=True)
class KernelPlan:
    """A fitted model laid out as the arrays :func:`compensate_block` reads.

    Attributes
    ----------
    filter
        ``[tau_s, 0, 1/tau_s, reference_freq_hz, reference_c, settle_s]`` of the rate
        filter (the samples of the first ``warmup_s`` seconds after the filter (re)started,
        on the time axis, are flagged, as training skips them; ``settle_s`` is
        :func:`hrgtc.core.timeline.settle_threshold_s`).
    uses_housing
        Whether h/dh are computed (the recording then needs ``housing_c``).
    uses_gradient
        Whether g is computed (the recording then needs ``housing_c``).
    exponents
        (n_terms, 5) powers of (f, df, h, dh, g) in each term. ``int64``
    coefficients
        Scaled coefficients, term order; ``intercept`` is B0. [°/h]
    scales
        Scale of each variable (1 where unused).
    tangent, low, high
        Per variable: continue along the tangent beyond [low, high] (a used
        variable with a training range).
    flagged
        Per variable: counted in ``in_range`` (f, h, g) or the rate count (df, dh).
    d_factor, d_exponents, d_constant
        Derivative of term k by variable v: ``d_factor[v, k] * rest``, rest the
        term of exponents ``d_exponents[v, k]`` or 1 when ``d_constant[v, k]``;
        ``d_factor`` is 0 where the term lacks v.
    thermometer
        ``[centre_c, scale_c, map offset, map scale, t_low, t_high, f_low, f_high,
        f_cal_low, f_cal_high, one_step_limit, tolerance]`` of the inverse.
    poly, slope, chebyshev
        Scaled f(z) coefficients, their derivative, the Chebyshev start series.
    grid_t, grid_f
        The inverse's dense table (f increasing) for the bracketed slow path. [°C, Hz]
    """

    filter: np.ndarray
    uses_housing: bool
    uses_gradient: bool
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
    grid_t: np.ndarray
    grid_f: np.ndarray

    @property
    def needs_housing(self) -> bool:
        """Whether the kernel reads ``housing_c`` (for h, dh or g)."""
        return self.uses_housing or self.uses_gradient


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
    tau = check_tau(s.rate_tau_s)
    terms = drift._terms
    used = {v for t in terms for v in t.variables}
    n, nv = len(terms), len(ORDER)
    exponents = np.zeros((n, nv), dtype=np.int64)
    d_factor = np.zeros((nv, n))
    d_exponents = np.zeros((nv, n, nv), dtype=np.int64)
    d_constant = np.zeros((nv, n), dtype=np.bool_)
    scales = np.ones(nv)
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
        filter=np.array([tau, 0.0, 1.0 / tau, s.reference_freq_hz, s.reference_c,
                         settle_threshold_s(s.warmup_s)]),
        uses_housing=any(v in ("h", "dh") for v in variables),
        uses_gradient="g" in variables,
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
        poly=_padded(a, POLY_SIZE),
        slope=_padded(a[1:] * np.arange(1, a.size), POLY_SIZE - 1),  # as slope_hz_per_c
        chebyshev=_padded(np.asarray(inverse.start_coefficients, dtype=np.float64),
                          CHEBYSHEV_SIZE),
        grid_t=np.asarray(inverse.grid_t, dtype=np.float64),
        grid_f=np.asarray(inverse.grid_f, dtype=np.float64),
    )


def supports_variables(variables: tuple[str, ...]) -> bool:
    """Whether the kernel computes every variable (not dpos, d2, a_NAME: numpy does), as
    :mod:`hrgtc.drift.variables` lists for the backend ``numba``."""
    return not unsupported(variables, "numba")


def supports(thermometer: Thermometer) -> bool:
    """Whether the kernel's fixed-length series hold this thermometer's (order <= 5)."""
    return (len(thermometer.scaled_coefficients) <= POLY_SIZE
            and len(thermometer._inverse.start_coefficients) <= CHEBYSHEV_SIZE)


def _padded(coefficients: np.ndarray, size: int) -> np.ndarray:
    """Ascending coefficients with zeros appended up to ``size``."""
    out = np.zeros(size)
    out[: coefficients.size] = coefficients
    return out


#: Slots of the kernel's state: the f filter's state, the h filter's, and the time the
#: filter (re)started (NaN before the first sample: the settling counts from there). [s]
F_STATE = slice(0, STATE_SIZE)
H_STATE = slice(STATE_SIZE, 2 * STATE_SIZE)
ORIGIN = 2 * STATE_SIZE


def new_state() -> np.ndarray:
    """Filter state at rest: two :func:`hrgtc.drift.rate_filter.new_state` and the time the
    filter started (NaN: not yet)."""
    return np.concatenate([new_filter_state(), new_filter_state(), [np.nan]])


def new_extremes() -> np.ndarray:
    """``extremes`` before the first sample: [+inf, -inf] for every variable of :data:`ORDER`."""
    return np.tile([np.inf, -np.inf], len(ORDER))


# -- the kernel -------------------------------------------------------------------------
#: Samples worked on together: the kernel's scratch rows (about 20 x TILE doubles) stay in
#: the L1/L2 cache, and every inner loop runs over samples, so it vectorises.
TILE = 256


@njit(cache=True, nogil=True, error_model="numpy")
def _term(exponents, k, x, m, out, factor):  # pragma: no cover - compiled
    """out[:m] = row k's product of powers of the rows of x, as features.Term.evaluate.

    Each factor x_v ** p is x_v * x_v * ... (left to right), and the factors are
    multiplied in variable order, so the rounding is that of the numpy path.
    """
    first = True
    for v in range(exponents.shape[1]):
        p = exponents[k, v]
        if p == 0:
            continue
        xv = x[v]
        target = out if first else factor
        for i in range(m):
            target[i] = xv[i]
        for _ in range(p - 1):
            for i in range(m):
                target[i] = target[i] * xv[i]
        if not first:
            for i in range(m):
                out[i] = out[i] * factor[i]
        first = False


class DriftArrays(NamedTuple):
    """A :class:`KernelPlan`'s drift arrays, one argument of :func:`compensate_block`."""

    filter: np.ndarray
    uses_housing: bool
    uses_gradient: bool
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


@njit(cache=True, nogil=True, error_model="numpy")
def compensate_block(columns, drift, inverse, state, outputs, counts,
                     extremes):  # pragma: no cover
    """Compensate one block in place; see the module docstring for what is computed.

    ``columns``: ``(time_s, restart, freq_hz, rate_dph, housing_c)``; ``drift``: a
    :class:`DriftArrays`; ``inverse``: ``(thermometer, poly, slope, chebyshev, grid_t,
    grid_f)`` of a :class:`KernelPlan`; ``outputs``: ``(rate, bias, temperature, in_range)``.
    ``state`` (filter, samples seen), ``counts`` (int64, see :data:`OUT_OF_RANGE`) and
    ``extremes`` (see :data:`F_MIN`) are updated. ``restart`` (int8 per sample, or empty:
    none) restarts the filters at rest on those samples and the settling time with them
    (the segment starts of ``gaps="split"``, and restarts of the logger).
    """
    time_s, restart, freq_hz, rate_dph, housing_c = columns
    (filt, uses_housing, uses_gradient, exponents, coefficients, intercept, scales, tangent, low,
     high, flagged, d_factor, d_exponents, d_constant) = drift
    therm, poly, slope, chebyshev, grid_t, grid_f = inverse
    out_rate, out_bias, out_temp, out_in_range = outputs
    has_restart = restart.size > 0
    tau, ref_f, ref_h = filt[0], filt[3], filt[4]
    centre, scale_c, map_offset, map_scale = therm[0], therm[1], therm[2], therm[3]
    t_low, t_high, f_low, f_high = therm[4], therm[5], therm[6], therm[7]
    f_cal_low, f_cal_high, one_step_limit, tolerance = therm[8], therm[9], therm[10], therm[11]
    n_terms = coefficients.size
    nv = scales.size
    value = np.zeros((nv, TILE))
    scaled = np.zeros((nv, TILE))
    delta = np.zeros((nv, TILE))
    term = np.empty(TILE)
    factor = np.empty(TILE)
    bias = np.empty(TILE)
    gradient = np.empty(TILE)
    ok = np.empty(TILE)
    rate_ok = np.empty(TILE)
    settled = np.empty(TILE)
    no_lag = np.empty(0)
    f_state = state[0:8]  # F_STATE, H_STATE
    h_state = state[8:16]
    n = freq_hz.size
    for start in range(0, n, TILE):
        m = min(TILE, n - start)
        freq = freq_hz[start:start + m]
        temp = out_temp[start:start + m]
        # thermometer inverse: Thermometer.temperature (Chebyshev start, one Newton step);
        # the series have a fixed length (zero-padded), so this loop unrolls and vectorises
        n_more = 0
        n_lost = 0
        for i in range(m):
            fi = freq[i]
            t, step = _start_and_step(fi, (f_low, f_high), (map_offset, map_scale),
                                      (t_low, t_high), chebyshev, centre, scale_c, poly, slope)
            inside = (fi >= f_low) & (fi <= f_high)
            more = abs(step) > one_step_limit
            converged = (abs(step) <= one_step_limit) & (t >= t_low) & (t <= t_high)
            temp[i] = t if inside & converged else np.nan
            n_more += inside & more
            n_lost += inside & (not converged) & (not more)
        if n_more or n_lost:  # rare: a poor start, Newton goes on for those samples (one by one)
            n_lost = 0
            for i in range(m):
                fi = freq[i]
                if not ((fi >= f_low) & (fi <= f_high)):
                    continue
                t, step = _start_and_step(fi, (f_low, f_high), (map_offset, map_scale),
                                          (t_low, t_high), chebyshev, centre, scale_c, poly,
                                          slope)
                limit = one_step_limit
                if abs(step) > one_step_limit:
                    clipped = min(max(fi, f_low), f_high)
                    t, step, limit = _newton_scalar(t, clipped, poly, slope, centre, scale_c,
                                                    tolerance)
                if not ((abs(step) <= limit) & (t >= t_low) & (t <= t_high)):
                    t = _bracketed_scalar(fi, grid_t, grid_f, poly, slope, centre, scale_c,
                                          tolerance)
                    n_lost += 1
                temp[i] = t
        counts[2] += n_lost
        # variables f, df (h, dh, g): features.FeatureStream; the filter is the only serial loop
        f, df = value[0], value[1]
        time = time_s[start:start + m]
        for i in range(m):
            f[i] = freq[i] - ref_f
        marks = restart[start:start + m] if has_restart else restart
        filter_run(f[:m], time, tau, marks, f_state, df[:m], no_lag)
        housing = housing_c[start:start + m]
        if uses_housing:
            h, dh = value[2], value[3]
            for i in range(m):
                h[i] = housing[i] - ref_h
            filter_run(h[:m], time, tau, marks, h_state, dh[:m], no_lag)
        if uses_gradient:
            g = value[4]
            for i in range(m):
                g[i] = housing[i] - temp[i]
        # drift model: features.tangent_extension (linear_combination at the held point)
        outside = False
        for v in range(nv):
            x, sv, dv = value[v], scaled[v], delta[v]
            lo, hi, scale = low[v], high[v], scales[v]
            if tangent[v]:
                count = 0
                for i in range(m):
                    held = x[i]
                    held = lo if held < lo else held
                    held = hi if held > hi else held
                    dv[i] = x[i] - held
                    sv[i] = held / scale
                    count += dv[i] != 0.0
                outside = outside or count > 0
            else:
                for i in range(m):
                    sv[i] = x[i] / scale
        for i in range(m):
            bias[i] = intercept
        for k in range(n_terms):
            _term(exponents, k, scaled, m, term, factor)
            c = coefficients[k]
            for i in range(m):
                bias[i] += c * term[i]
        if outside:
            for v in range(nv):
                if not tangent[v]:
                    continue
                for i in range(m):
                    gradient[i] = 0.0
                for k in range(n_terms):
                    fk = d_factor[v, k]
                    if fk == 0.0:
                        continue
                    if d_constant[v, k]:
                        for i in range(m):
                            gradient[i] += fk
                    else:
                        _term(d_exponents[v], k, scaled, m, term, factor)
                        for i in range(m):
                            gradient[i] += fk * term[i]
                dv = delta[v]
                for i in range(m):
                    bias[i] += gradient[i] * dv[i]
        rate = rate_dph[start:start + m]
        for i in range(m):
            out_bias[start + i] = bias[i]
            out_rate[start + i] = rate[i] - bias[i]
        # settling: seconds since the filter (re)started, on the time axis (ORIGIN), as
        # training's warm-up skip (drift.windows: time - origin >= warmup_s); a settling
        # sample is flagged by that reason only, not counted out of range as well
        origin = state[16]
        if origin != origin and m > 0:  # NaN: the run's first sample
            origin = time[0]
        n_settling = 0
        for i in range(m):
            if has_restart and restart[start + i] != 0:
                origin = time[i]
            settled[i] = 1.0 if time[i] - origin >= filt[5] else 0.0
            n_settling += settled[i] == 0.0
        n_settled = m - n_settling
        state[16] = origin
        # flags: Compensator._block (1.0 inside, 0.0 outside; NaN is outside); counted
        # on the settled samples
        for i in range(m):
            fi = freq[i]
            ok[i] = 1.0 if (fi >= f_cal_low) & (fi <= f_cal_high) else 0.0
            rate_ok[i] = 1.0
        for v in range(nv):
            if flagged[v]:
                flag = rate_ok if v == RATES[0] or v == RATES[1] else ok
                x, lo, hi = value[v], low[v], high[v]
                n_out = 0
                for i in range(m):
                    inside = (x[i] >= lo) & (x[i] <= hi)
                    flag[i] = flag[i] if inside else 0.0
                    n_out += (not inside) & (settled[i] != 0.0)
                if counts.size > VARIABLE_OUT + v:
                    counts[VARIABLE_OUT + v] += n_out
            if v == 0 and counts.size > TEMPERATURE_OUT:  # calibrated span and f's range
                n_temperature = 0.0
                for i in range(m):
                    n_temperature += ok[i] * settled[i]
                counts[TEMPERATURE_OUT] += n_settled - int(n_temperature)
        n_ok = 0.0
        n_rate_ok = 0.0
        for i in range(m):
            out_in_range[start + i] = ok[i] * rate_ok[i] * settled[i]
            n_ok += ok[i] * settled[i]
            n_rate_ok += rate_ok[i] * settled[i]
        counts[0] += n_settled - int(n_ok)
        counts[1] += n_settled - int(n_rate_ok)
        counts[3] += n_settling
        for v in range(min(nv, extremes.size // 2)):  # how far the settled samples went
            x = value[v]
            lo, hi = extremes[2 * v], extremes[2 * v + 1]
            for i in range(m):
                if settled[i] != 0.0:
                    lo = x[i] if x[i] < lo else lo
                    hi = x[i] if x[i] > hi else hi
            extremes[2 * v], extremes[2 * v + 1] = lo, hi


@njit(cache=True, nogil=True, error_model="numpy")
def advance_filter(time_s, restart, freq_hz, housing_c, filt, uses_housing,
                   state):  # pragma: no cover
    """Run only the rate filter over a block: ``state`` becomes the state at its end.

    The same operations as :func:`compensate_block`'s filter, so the state is the same
    bits; it lets the second half of a chunk start on another thread.
    """
    tau, ref_f, ref_h = filt[0], filt[3], filt[4]
    f_state = state[0:8]
    h_state = state[8:16]
    has_restart = restart.size > 0
    n = freq_hz.size
    scratch = np.empty(n)
    level = np.empty(n)
    for i in range(n):
        level[i] = freq_hz[i] - ref_f
    filter_run(level, time_s, tau, restart, f_state, scratch, scratch[:0])
    if uses_housing:
        for i in range(n):
            level[i] = housing_c[i] - ref_h
        filter_run(level, time_s, tau, restart, h_state, scratch, scratch[:0])
    origin = state[16]
    if origin != origin and n > 0:  # NaN: the run's first sample
        origin = time_s[0]
    for i in range(n):
        origin = time_s[i] if has_restart and restart[i] != 0 else origin
    state[16] = origin


#: Chunks of at least this many rows are split in two halves compensated on two threads.
PARALLEL_ROWS = 1 << 18


def run(block_plan: KernelPlan, state: np.ndarray, columns: tuple[np.ndarray | None, ...],
        out: dict[str, np.ndarray], counts: np.ndarray,
        extremes: np.ndarray | None = None, restart: np.ndarray | None = None) -> None:
    """Compensate a chunk with a plan's arrays (outputs in ``out``, ``state`` advanced).

    ``columns``: ``(time_s, freq_hz, rate_dph, housing_c)`` (``housing_c`` None when not
    read). ``restart``: a boolean mask of the rows where the filters restart at rest (segment
    starts of ``gaps="split"``), or None. A long chunk is cut in two: the filter alone
    runs over the first half to give the state at the cut, then both halves are
    compensated at once on two threads (the kernel releases the GIL). Results are the
    same bits as one call.
    """
    time_s, freq_hz, rate_dph, housing_c = columns
    housing = freq_hz if housing_c is None else housing_c
    mask = (np.zeros(0, dtype=np.int8) if restart is None
            else np.ascontiguousarray(restart, dtype=np.int8))
    extremes = new_extremes() if extremes is None else extremes
    n = freq_hz.size
    arrays = (time_s, mask, freq_hz, rate_dph, housing)
    if n < PARALLEL_ROWS or (os.cpu_count() or 1) < 2:
        _call(block_plan, state, arrays, out, counts, extremes, 0, n)
        return
    middle = n // 2
    second = state.copy()
    advance_filter(time_s[:middle], mask[:middle], freq_hz[:middle], housing[:middle],
                   block_plan.filter, block_plan.uses_housing, second)
    second_counts = np.zeros_like(counts)
    second_extremes = new_extremes()
    worker = threading.Thread(target=_call, args=(block_plan, second, arrays, out,
                                                  second_counts, second_extremes, middle, n))
    worker.start()
    try:
        _call(block_plan, state, arrays, out, counts, extremes, 0, middle)
    finally:
        worker.join()
    state[:] = second
    counts += second_counts
    extremes[0::2] = np.minimum(extremes[0::2], second_extremes[0::2])
    extremes[1::2] = np.maximum(extremes[1::2], second_extremes[1::2])


def _call(p: KernelPlan, state: np.ndarray, columns: tuple[np.ndarray, ...],
          out: dict[str, np.ndarray], counts: np.ndarray, extremes: np.ndarray, start: int,
          stop: int) -> None:
    """:func:`compensate_block` of the rows ``start:stop`` of ``columns`` into ``out``."""
    part = slice(start, stop)
    time_s, restart, freq_hz, rate_dph, housing_c = columns
    compensate_block(
        (time_s[part], restart[part] if restart.size else restart, freq_hz[part],
         rate_dph[part], housing_c[part]),
        DriftArrays(p.filter, p.uses_housing, p.uses_gradient, p.exponents, p.coefficients,
                    p.intercept, p.scales, p.tangent, p.low, p.high, p.flagged, p.d_factor,
                    p.d_exponents, p.d_constant),
        (p.thermometer, p.poly, p.slope, p.chebyshev, p.grid_t, p.grid_f), state,
        (out["rate_comp_dph"][part], out["bias_model_dph"][part],
         out["resonator_c_est"][part], out["in_range"][part]),
        counts, extremes,
    )
