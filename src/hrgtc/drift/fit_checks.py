"""What :func:`hrgtc.drift.drift_model.fit` checks and gathers around the regression.

Before it: whether the training data can identify a thermal model at all (the spans of
the temperature and of its rate), the options the drift variables read (their declared
options with defaults, ``rate_tau_s`` and the ``--aux`` columns) and the registry's entry
of each candidate variable. After it: what training read and left out (its accounting).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from hrgtc.core.accounting import Accounting
from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.drift.variables import DriftVariable
from hrgtc.drift.variables import variable as registered
from hrgtc.drift.windows import TrainingWindows
from hrgtc.settings.drift import VARIABLE_OPTIONS, DriftSettings
from hrgtc.thermometry import Thermometer

__all__ = ["MIN_RATE_SPAN_C_PER_H", "MIN_TEMPERATURE_SPAN_C", "check_excitation",
           "given_options", "registry_entries", "training_accounting"]

#: Smallest training spread of df/dt, as a resonator temperature rate, for a drift model. [°C/h]
MIN_RATE_SPAN_C_PER_H = 0.5
#: Smallest training spread of the resonator temperature for a drift model. [°C]
MIN_TEMPERATURE_SPAN_C = 1.0


def check_excitation(windows: TrainingWindows, thermometer: Thermometer,
                      variables: Sequence[str], run: int | None = None) -> None:
    """Refuse training data (all runs, or run ``run``) that cannot identify a thermal model."""
    slope = float(np.max(np.abs(thermometer.slope_hz_per_c(thermometer.temperature_range_c))))
    mask = slice(None) if run is None else windows.run == run
    what = "the drift runs" if run is None else f"drift run {windows.sources[run]}"
    sensor = thermometer.source == "sensor"  # f is T in °C: no frequency to quote
    if "f" in variables:
        f = windows.variables["f"][mask]
        span_c = (float(f.max()) - float(f.min())) / slope
        if span_c < MIN_TEMPERATURE_SPAN_C:
            raise CalibrationError(
                f"{what} spans only {span_c:.3g} °C of "
                + ("temperature" if sensor else
                   f"resonator temperature ({float(f.max() - f.min()):.3g} Hz)")
                + f"; a drift model needs a temperature change of at least "
                f"{MIN_TEMPERATURE_SPAN_C:g} °C: use a cool-down or warm-up run"
            )
    if "df" in variables:
        df = windows.variables["df"][mask]
        span_c_per_h = (float(df.max()) - float(df.min())) / slope * 3600.0
        if span_c_per_h < MIN_RATE_SPAN_C_PER_H:
            raise CalibrationError(
                f"{what} shows no "
                + ("dT/dt" if sensor else "df/dt")
                + f" variation (span {span_c_per_h:.3g} °C/h"
                + ("" if sensor else f", {float(df.max() - df.min()):.3g} Hz/s")
                + "); the rate terms cannot be identified: train on a ramp (cool-down or "
                "warm-up), not on a soak or constant temperature, or drop the df terms "
                "(--terms f,f^2,f^3)"
            )


def given_options(options: Mapping[str, Any] | None, rate_tau_s: float,
                   aux_columns: Mapping[str, str] | None) -> dict[str, Any]:
    """What the variables' ``derive`` read: the options they declare (defaults for those
    not given), ``rate_tau_s`` and ``aux_columns``."""
    given = dict(options or {})
    unknown = sorted(set(given) - set(VARIABLE_OPTIONS))
    if unknown:
        raise InputError(f"unknown drift variable option(s) {unknown}; the variables declare "
                         f"{', '.join(VARIABLE_OPTIONS) or 'none'}")
    return {**DriftSettings().variable_options(), **given, "rate_tau_s": rate_tau_s,
            "aux_columns": dict(aux_columns or {})}


def registry_entries(variables: Sequence[str]) -> list[tuple[DriftVariable, tuple[str, ...]]]:
    """The registry's entries of ``variables``, each with its names (``a_NAME``: every
    channel), in grammar order."""
    entries: dict[str, tuple[DriftVariable, list[str]]] = {}
    for name in variables:
        entry = registered(name)
        entries.setdefault(entry.name, (entry, []))[1].append(name)
    return [(entry, tuple(names)) for entry, names in
            sorted(entries.values(), key=lambda e: e[0].order)]


def training_accounting(windows: TrainingWindows) -> Accounting:
    """What training read and left out (warm-up, partial windows, ...)."""
    accounting = Accounting(read=windows.n_samples)
    for reason, count in windows.dropped.items():
        accounting.drop(reason, count)
    accounting.drop("motion", windows.n_not_at_rest)
    return accounting
