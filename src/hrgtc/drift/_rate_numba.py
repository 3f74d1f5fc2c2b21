"""The rate filter's step, compiled by numba: what the fused compensation kernel
(:mod:`hrgtc.compensate._kernel`, numba) calls inside its loop.

:func:`hrgtc.drift.rate_filter.causal_rate` runs the same statements in C
(:mod:`hrgtc.drift._rate_kernel`, ``_rate_native.c``), so the command path imports no
numba; ``tests/drift/test_rate_native.py`` checks the two compute the same bits. See
:mod:`hrgtc.drift.rate_filter` for the update and its derivation.
"""

from __future__ import annotations

import math

from numba import njit

from hrgtc.drift.rate_weights import DT_REL_TOLERANCE, SERIES_LIMIT, series_coefficients

_S1, _S2, _S3, _S4, _S5, _S6, _S7, _S8, _S9 = series_coefficients()  # compiled in as constants
_LIMIT = SERIES_LIMIT
_TOLERANCE = DT_REL_TOLERANCE


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def step_weights(dt_s, tau_s):  # pragma: no cover - compiled
    """(a, p) of one step of length ``dt_s``: a = 1 - exp(-r), p = 1 - a/r, r = dt/tau."""
    r = dt_s / tau_s
    a = -math.expm1(-r)
    if r < _LIMIT:  # Taylor series of p, Horner, highest power first
        p = _S9
        p = p * r + _S8
        p = p * r + _S7
        p = p * r + _S6
        p = p * r + _S5
        p = p * r + _S4
        p = p * r + _S3
        p = p * r + _S2
        p = p * r + _S1
        p = p * r
    else:
        p = (r - a) / r
    return a, p


@njit(cache=True, nogil=True, error_model="numpy")
def filter_run(x, time_s, tau_s, restart, state, out_rate, out_lag):  # pragma: no cover
    """Advance ``state`` (the slots of :data:`hrgtc.drift.rate_filter.LAG`) over the samples
    ``x`` at ``time_s``, writing each rate (and, unless ``out_lag`` is empty, the lag
    x - y1 after the step).

    ``restart`` (int8 per sample, or empty: none), or a state never started, puts the
    filter at rest on that sample (rate 0) with no cached step. A step of zero or
    negative Δt moves nothing but the previous input. The state is held in locals over
    the loop (registers), written back at the end.
    """
    has_restart = restart.size > 0
    keep_lag = out_lag.size > 0
    lag, difference, previous, t_prev = state[0], state[1], state[2], state[3]
    started, dt_c, a, p = state[4], state[5], state[6], state[7]
    for i in range(x.size):
        xi = x[i]
        ti = time_s[i]
        if (has_restart and restart[i] != 0) or started == 0.0:
            lag = 0.0
            difference = 0.0
            previous = xi
            t_prev = ti
            started = 1.0
            dt_c = -1.0  # no cached step: a restarted filter is a new one
            a = 0.0
            p = 0.0
            out_rate[i] = 0.0
        else:
            dt = ti - t_prev
            dt = 0.0 if not dt > 0.0 else dt
            if not abs(dt - dt_c) <= _TOLERANCE * dt_c:
                a, p = step_weights(dt, tau_s)
                dt_c = dt
            delta = xi - previous
            c1 = a * lag
            c1 = c1 + p * delta
            lag = lag + delta
            lag = lag - c1
            c2 = a * difference
            c2 = c2 + p * c1
            difference = difference + c1
            difference = difference - c2
            previous = xi
            t_prev = ti
            out_rate[i] = difference / tau_s
        if keep_lag:
            out_lag[i] = lag
    state[0], state[1], state[2], state[3] = lag, difference, previous, t_prev
    state[4], state[5], state[6], state[7] = started, dt_c, a, p
