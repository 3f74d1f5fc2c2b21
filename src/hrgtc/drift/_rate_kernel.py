"""The rate filter's step over whole arrays, in C: what
:func:`hrgtc.drift.rate_filter.causal_rate` and its checks call.

The loops are the compiled module ``_rate_native`` (``_rate_native.c``, built by
``pip install -e .``): the statements of the numba :func:`hrgtc.drift._rate_numba.filter_run`
that the fused compensation kernel calls, in the same order, so the two compute the same
bits (``tests/drift/test_rate_native.py``). numba is not imported: its import and start
cost a command more than the pass (docs/architecture.md, "The native kernels"). When the
module is missing this raises ``ImportError`` saying how to build it.

See :mod:`hrgtc.drift.rate_filter` for the update and its derivation.
"""

from __future__ import annotations

import numpy as np

from hrgtc.core.native import native_module
from hrgtc.drift.rate_weights import DT_REL_TOLERANCE, SERIES_LIMIT, series_coefficients

_native = native_module("hrgtc.drift._rate_native", "df/dt filter")

#: The constants of the step: p's Taylor coefficients, the series' limit and the relative
#: change of Δt that keeps the cached (a, p).
_SERIES = (*series_coefficients(), SERIES_LIMIT, DT_REL_TOLERANCE)


def step_weights(dt_s: float, tau_s: float) -> tuple[float, float]:
    """(a, p) of one step of length ``dt_s``: a = 1 - exp(-r), p = 1 - a/r, r = dt/tau."""
    return _native.step_weights(dt_s, tau_s, _SERIES)


def rate_pass(x: np.ndarray, time_s: np.ndarray, tau_s: float, restart: np.ndarray,
              state: np.ndarray, out_rate: np.ndarray, out_lag: np.ndarray) -> None:
    """Advance ``state`` (the slots of :data:`hrgtc.drift.rate_filter.LAG`) over the samples
    ``x`` at ``time_s``, writing each rate (and, unless ``out_lag`` is empty, the lag
    x - y1 after the step); contiguous float64 arrays, ``restart`` int8 (or empty: none).

    ``restart``, or a state never started, puts the filter at rest on that sample (rate 0)
    with no cached step. A step of zero or negative Δt moves nothing but the previous
    input.
    """
    _native.rate_pass(x, time_s, tau_s, restart, state, out_rate, out_lag, _SERIES)


def first_time_problem(time_s: np.ndarray, t_prev: float, started: float) -> tuple[int, int]:
    """(kind, row) of the first time the filter cannot step to: kind 1 not finite, 2 a
    step back, 3 a step back from the previous chunk (``t_prev``); (0, -1) if none."""
    return _native.first_time_problem(time_s, t_prev, started)
