"""Thermal network of a gyro in a chamber: chamber air -> housing -> resonator.

Two lumped first-order nodes in cascade (Section 1 and 3 of [1]: the resonator
sits in vacuum and exchanges heat with the housing only by radiation and
through its stem, so it lags the housing by hours):

    tau_h dT_h/dt = T_c - T_h          (housing, from the chamber air T_c)
    tau_r dT_r/dt = T_h - T_r          (resonator, from the housing)

The resonator's heat capacity is small against the housing's, so the coupling
is one way. The housing - resonator difference ``T_h - T_r = tau_r dT_r/dt``
is the thermal gradient that drives the rate-dependent bias.

Integration is exact for a chamber temperature that is linear between samples
(the chamber program of :mod:`hrgtc.simulate.profiles` is piecewise linear; at
a corner inside a sample period the error is below rate x period): the cascade
is split into its two modes (``T_h`` and ``z = T_r + tau_h/(tau_r - tau_h) T_h``,
each a first-order lag of the chamber temperature) and each mode is advanced
with its exact first-order-hold discretisation by :func:`scipy.signal.lfilter`,
carrying the filter state from chunk to chunk. No Python loop per sample.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.signal import lfilter

from hrgtc.core import records
from hrgtc.core.errors import InputError

__all__ = ["ThermalNetwork", "ThermalState", "first_order_hold_coefficients", "step_response"]


def first_order_hold_coefficients(tau_s: float, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact discretisation of ``tau dy/dt = u - y`` for ``u`` linear between samples.

    With ``a = exp(-dt/tau)`` and ``beta = tau (1 - a) / dt`` the exact update is
    ``y[k] = a y[k-1] + (1 - beta) u[k] + (beta - a) u[k-1]``.

    Parameters
    ----------
    tau_s
        Time constant. [s]
    dt_s
        Sample period. [s]

    Returns
    -------
    b, a : numpy.ndarray
        Numerator and denominator for :func:`scipy.signal.lfilter`.

    Examples
    --------
    >>> b, a = first_order_hold_coefficients(100.0, 1.0)
    >>> round(float(b.sum() / a.sum()), 12)   # unit gain at DC
    1.0
    """
    x = dt_s / tau_s
    decay = math.exp(-x)
    one_minus = -math.expm1(-x)
    beta = one_minus / x
    return np.array([1.0 - beta, beta - decay]), np.array([1.0, -decay])


@dataclass(frozen=True)
class ThermalState:
    """Values at the last sample of a chunk, carried to the next chunk.

    Parameters
    ----------
    chamber_c
        Chamber air temperature. [°C]
    housing_c
        Housing temperature. [°C]
    mode_c
        Slow mode ``z = T_r + tau_h / (tau_r - tau_h) T_h``. [°C]
    """

    chamber_c: float
    housing_c: float
    mode_c: float


@dataclass(frozen=True)
class ThermalNetwork(records.Written):
    """Chamber -> housing -> resonator, two first-order lags in cascade.

    Parameters
    ----------
    tau_housing_s
        Time constant of the housing behind the chamber air. [s]
    tau_resonator_s
        Time constant of the resonator behind the housing (vacuum gap). [s]

    Examples
    --------
    >>> net = ThermalNetwork(720.0, 2400.0)
    >>> chamber = np.full(2000, -10.0)
    >>> housing, resonator, _ = net.response(chamber, 10.0, net.initial_state(-10.0))
    >>> float(resonator[-1])
    -10.0
    """

    forbid_unknown_fields = True  # a misspelt key of a hand-written input is refused

    tau_housing_s: records.Positive
    tau_resonator_s: records.Positive

    def __post_init__(self) -> None:
        for name in ("tau_housing_s", "tau_resonator_s"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(f"{name} must be finite and > 0 [s], got {value!r}")
            object.__setattr__(self, name, value)
        if abs(self.tau_resonator_s / self.tau_housing_s - 1.0) < 0.05:
            raise InputError(
                f"tau_housing_s={self.tau_housing_s:g} and tau_resonator_s="
                f"{self.tau_resonator_s:g} are within 5 % of each other; the modal "
                "integration needs distinct time constants, move one of them"
            )

    @property
    def _mode_gain(self) -> float:
        """DC gain of the slow mode z on the chamber input: tau_r / (tau_r - tau_h)."""
        return self.tau_resonator_s / (self.tau_resonator_s - self.tau_housing_s)

    @property
    def _housing_weight(self) -> float:
        """Weight w of T_r = z - w T_h: tau_h / (tau_r - tau_h)."""
        return self.tau_housing_s / (self.tau_resonator_s - self.tau_housing_s)

    def initial_state(self, temperature_c: float) -> ThermalState:
        """Chamber, housing and resonator in equilibrium at one temperature. [°C]"""
        temp = float(temperature_c)
        return ThermalState(chamber_c=temp, housing_c=temp, mode_c=temp * self._mode_gain)

    def resonator_c(self, state: ThermalState) -> float:
        """Resonator temperature of a state. [°C]"""
        return state.mode_c - self._housing_weight * state.housing_c

    def response(
        self, chamber_c: np.ndarray, dt_s: float, state: ThermalState
    ) -> tuple[np.ndarray, np.ndarray, ThermalState]:
        """Housing and resonator temperatures for one chunk of chamber temperatures.

        Parameters
        ----------
        chamber_c
            Chamber air temperature at the samples of this chunk; the chamber
            is taken as linear between the state's sample and the first one. [°C]
        dt_s
            Sample period. [s]
        state
            State at the sample before this chunk (:meth:`initial_state` for a
            unit in equilibrium: then the first sample should be at that
            temperature too).

        Returns
        -------
        housing_c, resonator_c : numpy.ndarray
            Housing and resonator temperatures at the samples. [°C]
        state : ThermalState
            State at the last sample, to pass with the next chunk.
        """
        chamber = np.asarray(chamber_c, dtype=np.float64)
        if chamber.size == 0:
            empty = np.empty(0)
            return empty, empty.copy(), state
        gain = self._mode_gain
        b_h, a_h = first_order_hold_coefficients(self.tau_housing_s, dt_s)
        b_z, a_z = first_order_hold_coefficients(self.tau_resonator_s, dt_s)
        b_z = b_z * gain
        # lfilter (transposed direct form II) state after a sample u -> y: b1 u - a1 y.
        zi_h = np.array([b_h[1] * state.chamber_c - a_h[1] * state.housing_c])
        zi_z = np.array([b_z[1] * state.chamber_c - a_z[1] * state.mode_c])
        housing, _ = lfilter(b_h, a_h, chamber, zi=zi_h)
        mode, _ = lfilter(b_z, a_z, chamber, zi=zi_z)
        resonator = mode - self._housing_weight * housing
        new_state = ThermalState(
            chamber_c=float(chamber[-1]), housing_c=float(housing[-1]), mode_c=float(mode[-1])
        )
        return housing, resonator, new_state


#: The record of :class:`ThermalNetwork` (nested in other records).
ThermalNetworkRecord = records.record_of(ThermalNetwork)


def step_response(network: ThermalNetwork, step_c: float, time_s: Any) -> np.ndarray:
    """Resonator response to an instantaneous chamber step, closed form. [°C]

    ``step_c * (1 - (tau_r e^(-t/tau_r) - tau_h e^(-t/tau_h)) / (tau_r - tau_h))``
    """
    t = np.asarray(time_s, dtype=np.float64)
    tau_h, tau_r = network.tau_housing_s, network.tau_resonator_s
    tail = (tau_r * np.exp(-t / tau_r) - tau_h * np.exp(-t / tau_h)) / (tau_r - tau_h)
    return step_c * (1.0 - tail)
