"""The causal rate filter of the drift model's df/dt (and dh/dt, d2), on the time axis.

The rate filter is the derivative of a twice low-passed signal,
D(s) = s / (tau s + 1)^2: y1 follows x through a first-order lag with time
constant tau, y2 follows y1 likewise, and the rate is (y1 - y2) / tau. Two state
variables per input, no differencing of noisy samples.

Each step is the **exact** solution of the first-order lag over that step's own
Δt for an input that moves linearly from the previous sample to this one (a
first-order hold). With r = Δt/tau, a = 1 - exp(-r) and p = 1 - a/r::

    y_n = y_{n-1} + a (x_{n-1} - y_{n-1}) + p (x_n - x_{n-1})

Derivation: over the step x(t) = x_{n-1} + m (t - t_{n-1}), m = (x_n - x_{n-1})/Δt,
and tau y' = x - y has the solution y(t) = x(t) - m tau + C exp(-(t - t_{n-1})/tau)
with C = y_{n-1} - x_{n-1} + m tau; at t_n this is the update above. For a ramp of
slope s the particular solution y = x - s tau holds at **every** step whatever its
Δt, and the second stage, whose input y1 = x - s tau is again a ramp of slope s,
gives y2 = y1 - s tau: (y1 - y2) / tau = s exactly, for uniform, jittered or
gapped sampling alike. (The sample-count filter this replaces, y += alpha (x_n - y)
with the gain alpha·fs/beta, was exact for uniform steps only; after a long gap it
read the temperature as having jumped at the gap's start.) Across a gap the step
is the gap's Δt: the temperature is taken to have moved in a straight line while
the logger slept ("bridge"); ``restart`` starts the filter at rest on a sample
instead (a "split" segment start, or a new run).

The state is kept as differences, which are small and carry the rate (no
cancellation of two levels): ``lag`` = x_{n-1} - y1 and ``difference`` = y1 - y2::

    c1 = a lag + p (x_n - x_{n-1});   lag <- lag + (x_n - x_{n-1}) - c1
    c2 = a difference + p c1;         difference <- difference + c1 - c2
    rate = difference / tau

The compiled step is :mod:`hrgtc.drift._rate_kernel`; the same statements run in the
numba kernel (:mod:`hrgtc.compensate._kernel`),
the streaming compensator and the C export (double and float32), so training and
deployment compute the same df/dt.

For r < :data:`SERIES_LIMIT`, p = r/2 - r^2/6 + r^3/24 - ... (its Taylor series, 9
terms: exact to rounding), since (r - a)/r cancels. a and p depend only on Δt,
so they are recomputed only when Δt moves by more than :data:`DT_REL_TOLERANCE`
of itself (a timing error of 1e-6 Δt; logger clocks are far coarser).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.drift.rate_weights import (  # noqa: F401  (re-exported: imported from here)
    DT_REL_TOLERANCE,
    SERIES_LIMIT,
    SERIES_TERMS,
    series_coefficients,
)

#: Slots of the filter state array: lag, difference, previous input, previous time,
#: started (0/1), and the cached step: its Δt, a and p.
LAG, DIFFERENCE, X_PREV, T_PREV, STARTED, DT, A, P = range(8)
STATE_SIZE = 8


def new_state() -> np.ndarray:
    """A filter that has seen nothing: it starts at rest on its first sample."""
    state = np.zeros(STATE_SIZE)
    state[DT] = -1.0  # no cached step yet
    return state


def check_tau(tau_s: float) -> float:
    """``tau_s`` if it is a positive finite time constant, else InputError. [s]"""
    if not (tau_s > 0 and np.isfinite(tau_s)):
        raise InputError(f"rate filter time constant must be positive, got {tau_s} s")
    return float(tau_s)


def rate_filter_coefficients(tau_s: float, sample_rate_hz: float) -> tuple[float, float]:
    """(a, p) of one step of 1/``sample_rate_hz`` (see the module docstring)."""
    check_tau(tau_s)
    if not (sample_rate_hz > 0 and np.isfinite(sample_rate_hz)):
        raise InputError(f"sample rate must be positive, got {sample_rate_hz} Hz")
    from hrgtc.drift._rate_kernel import step_weights  # numba: imported on use

    a, p = step_weights(1.0 / sample_rate_hz, float(tau_s))
    return float(a), float(p)


@dataclass
class RateFilterState:
    """State of :func:`causal_rate` for one signal (the array of :data:`LAG` slots)."""

    values: np.ndarray | None = None

    def copy(self) -> RateFilterState:
        return RateFilterState(None if self.values is None else self.values.copy())


def uniform_time(n: int, sample_rate_hz: float, state: RateFilterState | None = None) -> np.ndarray:
    """Times of ``n`` samples at ``sample_rate_hz`` continuing ``state``'s last time. [s]"""
    if not (sample_rate_hz > 0 and np.isfinite(sample_rate_hz)):
        raise InputError(f"sample rate must be positive, got {sample_rate_hz} Hz")
    start = 0.0
    if state is not None and state.values is not None and state.values[STARTED]:
        start = float(state.values[T_PREV]) + 1.0 / sample_rate_hz
    return start + np.arange(n) / sample_rate_hz


def causal_rate(
    x: np.ndarray, tau_s: float, sample_rate_hz: float | None = None,
    state: RateFilterState | None = None, *, time_s: np.ndarray | None = None,
    restart: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, RateFilterState]:
    """Causal rate of ``x`` by a twice low-passed exact derivative, D(s) = s/(tau s + 1)^2.

    Parameters
    ----------
    x
        Signal. [unit]
    tau_s
        Time constant of each low-pass stage. [s]
    sample_rate_hz
        Sample rate, used only when ``time_s`` is not given (uniform steps). [Hz]
    state
        Filter state from the previous chunk; ``None`` starts at rest on the
        first sample (rate 0).
    time_s
        Time of each sample (non-decreasing, also across ``state``): each step uses
        its own Δt, a gap is bridged with the gap's Δt. [s]
    restart
        Boolean mask: the filter restarts at rest on these samples (segment starts
        of ``--gaps split``, new runs).

    Returns
    -------
    rate, smoothed, state
        The rate [unit/s], the once-smoothed signal y1 [unit] and the new state.
    """
    from hrgtc.drift._rate_kernel import rate_pass  # numba: imported on use (CLI start)

    x = np.ascontiguousarray(x, dtype=np.float64)
    tau = check_tau(tau_s)
    values = new_state() if state is None or state.values is None else state.values.copy()
    if time_s is None:
        if sample_rate_hz is None:
            raise InputError("causal_rate needs time_s or sample_rate_hz")
        time = uniform_time(x.size, sample_rate_hz, RateFilterState(values))
    else:
        time = np.ascontiguousarray(time_s, dtype=np.float64)
        if time.shape != x.shape:
            raise InputError(f"time_s has {time.size} samples, the signal {x.size}")
        check_time(time, values)
    mask = np.zeros(0, dtype=np.int8)
    if restart is not None:
        mask = np.ascontiguousarray(restart, dtype=np.int8)
        if mask.shape != x.shape:
            raise InputError(f"restart mask has {mask.size} samples, the signal {x.size}")
    rate = np.empty(x.size)
    lag = np.empty(x.size)
    if x.size:
        rate_pass(x, time, tau, mask, values, rate, lag)
    # lag after a step is x_n - y1_n (the state's "previous input" is x_n)
    return rate, x - lag, RateFilterState(values)


def check_time(time_s: np.ndarray, state: np.ndarray | None = None) -> None:
    """Raise when times go backwards or are not finite (the filter steps forward only)."""
    from hrgtc.drift._rate_kernel import first_time_problem  # one compiled pass

    if not time_s.size:
        return
    started = 0.0 if state is None else float(state[STARTED])
    t_prev = 0.0 if state is None else float(state[T_PREV])
    kind, row = first_time_problem(np.ascontiguousarray(time_s, dtype=np.float64), t_prev,
                                   started)
    if kind == 1:
        raise InputError(f"time_s is not finite at row {row}; the df/dt filter needs each "
                         "sample's time")
    if kind == 2:
        raise InputError(f"time_s goes backwards at row {row} ({time_s[row - 1]!r} -> "
                         f"{time_s[row]!r} s); the df/dt filter steps forward in time")
    if kind == 3 and state is not None:
        raise InputError(f"time_s goes backwards between chunks ({float(state[T_PREV])!r} -> "
                         f"{float(time_s[0])!r} s); the df/dt filter steps forward in time")


def restart_mask(n: int, rows: np.ndarray | list[int]) -> np.ndarray:
    """Boolean mask of ``n`` samples, True at ``rows`` (segment starts, new runs)."""
    mask = np.zeros(n, dtype=bool)
    rows = np.asarray(rows, dtype=np.int64)
    mask[rows[(rows >= 0) & (rows < n)]] = True
    return mask
