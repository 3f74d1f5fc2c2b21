"""The play variable's loop, compiled (numba): loaded by :func:`hrgtc.drift.variables.play.play_lag`
on first use, so importing the registry (and ``hrgtc.compensate``) loads no numba."""

from __future__ import annotations

from numba import njit


@njit(cache=True, nogil=True)
def play_run(x, half_width, restart, state, out):  # pragma: no cover - compiled
    """``out[i] = p[i] - x[i]`` from ``state`` (NaN: not started: p = the first finite x)."""
    has_restart = restart.size > 0
    p = state
    for i in range(x.size):
        xi = x[i]
        if (has_restart and restart[i]) or p != p:
            p = xi  # power-on (or restart): the state starts at the temperature
        elif xi == xi:
            if p < xi - half_width:
                p = xi - half_width
            elif p > xi + half_width:
                p = xi + half_width
        out[i] = p - xi
    return p
