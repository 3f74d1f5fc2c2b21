"""The numbers the C export needs beyond the model's own, as one typed value.

:func:`plan_for` computes them exactly as the Python compensator does (the df/dt
filter's coefficients, the thermometer's inverse table and tolerance), so the C
code and :class:`hrgtc.compensate.Compensator` agree sample by sample.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.drift.features import is_aux, variable_key
from hrgtc.drift.rate_filter import check_tau
from hrgtc.drift.variables import refusal, supported, variable
from hrgtc.model import Model
from hrgtc.settings import export as settings_export

#: Points of the embedded table that starts the thermometer's Newton iteration.
TABLE_POINTS = 33


@dataclass(frozen=True, eq=False)
class CPlan:
    """What the C source is written from.

    Attributes
    ----------
    housing
        The drift terms use the housing thermistor (h, dh/dt).
    computed
        Variables the compensator computes: f and df, and h and dh where used.
    tau_s
        Time constant of each first-order stage of the causal df/dt filter; each step's
        weights come from it and the step's Δt (:mod:`hrgtc.drift.rate_filter`). [s]
    increasing
        f(T) increases with temperature.
    grid_t, grid_f
        The inverse's table: temperatures [°C] and frequencies [Hz], f increasing.
    th_coefficients, th_derivative
        The thermometer's scaled coefficients and those of its derivative.
    f_range
        Calibrated frequency range. [Hz]
    tolerance
        Newton tolerance of the inverse. [°C]
    extension
        Temperatures over which the inverse is defined. [°C]
    precision
        ``"double"`` (C double throughout) or ``"single"`` (float32, centred frequency).
    gradient
        The terms use the housing - resonator gradient g = housing_c - T(freq_hz).
    rate2, tau2_s
        The terms use the second df/dt filter ``d2``; its time constant. [s]
    aux
        Names of the user's extra channels the terms use (``a_NAME``), in grammar order:
        each is one more input of ``step()``.
    """

    housing: bool
    computed: list[str]
    tau_s: float
    increasing: bool
    grid_t: np.ndarray
    grid_f: np.ndarray
    th_coefficients: np.ndarray
    th_derivative: np.ndarray
    f_range: tuple[float, float]
    tolerance: float
    extension: tuple[float, float]
    precision: str = "double"
    gradient: bool = False
    rate2: bool = False
    tau2_s: float = 0.0
    aux: tuple[str, ...] = ()

    @property
    def housing_input(self) -> bool:
        """``step()`` takes ``housing_c`` (for h, dh or g)."""
        return self.housing or self.gradient


#: The precisions the export writes.
PRECISIONS = settings_export.PRECISIONS
#: The variables the float32 build computes (its filter and mirror know these).
SINGLE_VARIABLES = supported("c_float32")


def plan_for(model: Model, precision: str = "double") -> CPlan:
    """The numbers the C code needs beyond the model's own, computed as hrgtc computes them.

    Raises
    ------
    InputError
        An unknown precision, or a model with a variable the export does not compute
        (:mod:`hrgtc.drift.variables` says which: ``dpos``; ``d2`` in float32).
    CalibrationError
        A thermometer that is not monotonic over its calibrated range.
    """
    if precision not in PRECISIONS:
        raise InputError(f"precision {precision!r} is not one of {', '.join(PRECISIONS)}; "
                         "use 'double' (the default) or 'single' (float32 for FPU-only MCUs)")
    thermometer, drift = model.thermometer, model.drift
    if not thermometer.is_monotonic:
        t_low, t_high = thermometer.temperature_range_c
        raise CalibrationError(
            f"the thermometer's f(T) is not monotonic over {t_low:g} to {t_high:g} °C, so "
            "frequency cannot be turned into temperature; recalibrate with a lower order"
        )
    settings = drift.settings
    used = set(drift.variables)
    refused = refusal(sorted(used, key=variable_key), "c_double", drift.selected)
    if refused is None and precision == "single":
        refused = refusal(sorted(used, key=variable_key), "c_float32", drift.selected)
    if refused is not None:
        raise InputError(refused)
    housing = bool(used & {"h", "dh"})
    # The compensator computes f and df (and h, dh when the terms use them); in_range checks
    # the levels (f, h), rate_in_range the rates of change (df, dh), each where computed.
    computed = ["f", "df"] + [v for v in ("h", "dh") if v in used]
    # second rate filter, gradient and extra channels: levels (g, a_NAME) join in_range,
    # the rate d2 rate_in_range, as in the compensator
    computed += [v for v in variables_for_c(used) if v not in computed]
    tau = check_tau(settings.rate_tau_s)
    tau2 = check_tau(settings.rate_tau2_s) if "d2" in used else 0.0
    for v in used:
        if v not in settings.scales:
            raise InputError(f"the drift model has no scale for variable {v!r}; it is corrupt")
    # Thermometer inverse: same extension and tolerance as Thermometer.temperature.
    t_low, t_high = thermometer.temperature_range_c
    span = t_high - t_low
    lo, hi = thermometer.inverse_range_c
    grid_t = np.linspace(lo, hi, TABLE_POINTS)
    grid_f = thermometer.frequency(grid_t)
    increasing = bool(grid_f[-1] > grid_f[0])
    if not increasing:
        grid_t, grid_f = grid_t[::-1], grid_f[::-1]
    a = np.asarray(thermometer.scaled_coefficients, dtype=np.float64)
    derivative = a[1:] * np.arange(1, a.size)
    f_low, f_high = thermometer.frequency_range_hz
    return CPlan(
        housing=housing,
        computed=computed,
        tau_s=tau,
        increasing=increasing,
        grid_t=grid_t,
        grid_f=grid_f,
        th_coefficients=a,
        th_derivative=derivative,
        f_range=(f_low, f_high),
        tolerance=4 * np.finfo(np.float64).eps * max(abs(lo), abs(hi), span),
        extension=(lo, hi),
        precision=precision,
        gradient="g" in used,
        rate2="d2" in used,
        tau2_s=tau2,
        aux=tuple(v[2:] for v in variables_for_c(used) if is_aux(v)),
    )


def variables_for_c(used: set[str]) -> list[str]:
    """The variables beyond f, df, h, dh the C code computes, in grammar order: those whose
    module in :mod:`hrgtc.drift.variables` writes its C pieces (``c_code``)."""
    return [v for v in sorted(used, key=variable_key) if variable(v).c_code is not None]
