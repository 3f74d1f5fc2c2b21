"""The causal rate filter of the drift model's df/dt (and dh/dt, d2).

The rate filter is the derivative of a twice low-passed signal,
D(s) = s / (tau s + 1)^2: y1 follows x through the exact one-step update of a
first-order lag with time constant tau, y2 follows y1 likewise, and the rate is
(y1 - y2) divided by the stages' ramp lag (tau in the continuous limit). Two state
variables per input, no differencing of noisy samples; the steady response to a
ramp is exactly its slope. :mod:`hrgtc.drift.features` uses it for ``df``, ``dh``
and ``d2`` (the same filter with its own time constant).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hrgtc.errors import InputError


def rate_filter_coefficients(tau_s: float, sample_rate_hz: float) -> tuple[float, float]:
    """(alpha, beta) of one exact first-order low-pass step y += alpha (x - y)."""
    if not (tau_s > 0 and np.isfinite(tau_s)):
        raise InputError(f"rate filter time constant must be positive, got {tau_s} s")
    if not (sample_rate_hz > 0 and np.isfinite(sample_rate_hz)):
        raise InputError(f"sample rate must be positive, got {sample_rate_hz} Hz")
    alpha = -math.expm1(-1.0 / (tau_s * sample_rate_hz))
    return alpha, 1.0 - alpha


@dataclass
class RateFilterState:
    """State of :func:`causal_rate` for one signal: the two low-pass outputs."""

    y1: float | None = None
    y2: float | None = None


def causal_rate(
    x: np.ndarray, tau_s: float, sample_rate_hz: float, state: RateFilterState | None = None
) -> tuple[np.ndarray, np.ndarray, RateFilterState]:
    """Causal rate of ``x`` by a twice low-passed exact derivative, D(s) = s/(tau s + 1)^2.

    Parameters
    ----------
    x
        Signal sampled at ``sample_rate_hz``. [unit]
    tau_s
        Time constant of each low-pass stage. [s]
    sample_rate_hz
        Sample rate. [Hz]
    state
        Filter state from the previous chunk; ``None`` starts at rest on the
        first sample (rate 0).

    Returns
    -------
    rate, smoothed, state
        The rate [unit/s], the once-smoothed signal y1 [unit] and the new state.
    """
    from scipy import signal  # imported on use: it costs the CLI's start half a second

    x = np.asarray(x, dtype=np.float64)
    state = RateFilterState() if state is None else RateFilterState(state.y1, state.y2)
    if x.size == 0:
        return np.empty(0), np.empty(0), state
    alpha, beta = rate_filter_coefficients(tau_s, sample_rate_hz)
    if state.y1 is None or state.y2 is None:
        state.y1 = state.y2 = float(x[0])
    b, a = [alpha], [1.0, -beta]
    y1, _ = signal.lfilter(b, a, x, zi=[beta * state.y1])
    y2, _ = signal.lfilter(b, a, y1, zi=[beta * state.y2])
    # For a ramp of slope s the discrete stages lag by s·dt·beta/alpha (= s·tau in the
    # continuous limit), so this gain makes the steady ramp response exactly s.
    rate = (y1 - y2) * (alpha * sample_rate_hz / beta)
    state.y1, state.y2 = float(y1[-1]), float(y2[-1])
    return rate, y1, state
