"""The rate filter's step, compiled (numba): what :func:`hrgtc.drift.rate_filter.causal_rate`
and the fused compensation kernel both call, so they compute the same bits.

See :mod:`hrgtc.drift.rate_filter` for the update and its derivation.
"""

from __future__ import annotations

import math

from numba import njit

from hrgtc.drift.rate_filter import DT_REL_TOLERANCE, SERIES_LIMIT, series_coefficients

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



@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def filter_step(state, x, t, tau_s, restart):  # pragma: no cover - compiled
    """Advance ``state`` (see :data:`LAG`) by one sample (x at time t); return the rate.

    ``restart`` (or a state never started) puts the filter at rest on this sample
    (rate 0). A step of zero or negative Δt moves nothing but the previous input.
    """
    if restart or state[4] == 0.0:
        state[0] = 0.0
        state[1] = 0.0
        state[2] = x
        state[3] = t
        state[4] = 1.0
        state[5] = -1.0  # no cached step: a restarted filter is a new one
        state[6] = 0.0
        state[7] = 0.0
        return 0.0
    dt = t - state[3]
    dt = 0.0 if not dt > 0.0 else dt
    if not abs(dt - state[5]) <= _TOLERANCE * state[5]:
        a, p = step_weights(dt, tau_s)
        state[5] = dt
        state[6] = a
        state[7] = p
    a = state[6]
    p = state[7]
    delta = x - state[2]
    c1 = a * state[0]
    c1 = c1 + p * delta
    lag = state[0] + delta
    state[0] = lag - c1
    c2 = a * state[1]
    c2 = c2 + p * c1
    difference = state[1] + c1
    state[1] = difference - c2
    state[2] = x
    state[3] = t
    return state[1] / tau_s


@njit(cache=True, nogil=True, error_model="numpy")
def rate_pass(x, time_s, tau_s, restart, state, out_rate, out_lag):  # pragma: no cover
    """:func:`filter_step` over arrays; ``restart`` an int8 mask (or empty: none)."""
    has_restart = restart.size > 0
    for i in range(x.size):
        out_rate[i] = filter_step(state, x[i], time_s[i], tau_s,
                                  has_restart and restart[i] != 0)
        out_lag[i] = state[0]
