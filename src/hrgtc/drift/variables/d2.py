"""``d2``: the causal rate of f through a second filter, of time constant ``rate_tau2_s``.

The rate filter of ``df`` with its own time constant and state, so a fit can mix a fast
and a slow rate (a thermal lag between the resonator and the part of the gyro whose
temperature drives the bias). In C the same ``rate_update`` as df's filter, its own state
``f2_filter`` and constant ``RATE2_TAU_S``, so the rounding is hrgtc's; the float32 build
runs the float filter of df (differences, compensated sums) with ``RATE2_TAU``.

Its command-line option, ``--rate-tau2-s``, is declared with the other variables' in
:mod:`hrgtc.settings.drift_variables` (``D2Options``), which ``hrgtc --help`` reads without
loading numpy; :func:`derive` gives it its value.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.drift.variables.spec import DriftVariable, Inputs, Put
from hrgtc.settings.drift_variables import TAU2_FACTOR


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """Causal rate of f by the second filter ``f2``. [Hz/s]"""
    return inputs.rate("f", inputs.settings.rate_tau2_s, "f2")


def check(settings: Any, thermometer: Any, name: str) -> str | None:
    if not settings.rate_tau2_s > 0.0:
        return ("the variable d2 needs rate_tau2_s > 0 in the feature settings "
                "(the second df/dt filter's time constant, --rate-tau2-s)")
    return None


class CCode:
    """d2's C: the second filter's constant, state, start, update; ``bias_dph(..., d2)``."""

    def pieces(self, ctype: Any, double: Any, name: str, settings: Any, prefix: str,
               comment: Callable[[Any], str]) -> dict[str, str]:
        from hrgtc.drift.rate_filter import check_tau

        tau = check_tau(settings.rate_tau2_s)
        constant = ("/* time constant of each stage of the second df/dt filter (d2) [s] */\n"
                    f"static const double RATE2_TAU_S = {double.literal(tau, 'rate_tau2_s')};\n")
        update = "rate_update(&state->f2_filter, f_value, dt_s, RATE2_TAU_S"
        if ctype.name == "float":  # the float filter takes tau in double (weights) and float
            constant += f"static const float RATE2_TAU = {ctype.literal(tau, 'rate_tau2_s')};\n"
            update += ", RATE2_TAU"
        zero = ctype.literal(0.0, "zero")
        return {
            "constants": constant,
            "state": f"    {prefix}_rate_filter f2_filter;  /* second df/dt filter of f (d2) "
                     "[Hz] */\n",
            "reset": f"    rate_start(&state->f2_filter, {zero});\n",
            "start": "        rate_start(&state->f2_filter, f_value);\n",
            "values": f"    {ctype.name} d2_value = {zero};\n",
            "rate": f"        d2_value = {update});\n",
            "gradient": "",
            "bias": ", d2_value",
        }

    def inputs(self, name: str) -> tuple[str, ...]:
        return ()

    def parameter(self, name: str) -> str:
        return "d2_hz_per_s"

    def readme(self, name: str, settings: Any) -> str:
        return (f"  d2 = df/dt by the same filter with tau2 = {settings.rate_tau2_s:g} s "
                "(its own state)   [Hz/s]")

    def firmware_value(self, value: np.ndarray, name: str, settings: Any) -> np.ndarray:
        return np.asarray(value).astype(np.float32)


def derive(names: tuple[str, ...], given: Mapping[str, Any]) -> dict[str, Any]:
    """The second filter's time constant: ``--rate-tau2-s``, else :data:`TAU2_FACTOR` ×
    ``--rate-tau-s``. [s]"""
    tau2 = given["rate_tau2_s"]
    return {"rate_tau2_s": TAU2_FACTOR * given["rate_tau_s"] if tau2 is None else float(tau2)}


def params(names: tuple[str, ...], settings: Any, put: Put) -> None:
    """d2's keys of the parameter file: the flag and the second filter's time constant."""
    put("uses_rate2", 1, "1: the terms use d2, the rate of f by the second filter.")
    put("rate_tau2_s", settings.rate_tau2_s,
        "Time constant of each of the two stages of the second df/dt filter. [s]")


VARIABLE = DriftVariable(
    name="d2", unit="Hz/s", sensor_unit="°C/s", kind="rate",
    description="causal rate of f through a second filter of time constant rate_tau2_s",
    backends=frozenset({"numpy", "c_double", "c_float32", "params"}), columns=("freq_hz",),
    compute=compute, order=5, check=check,
    settings_fields=(("rate_tau2_s", records.NonNegative, 0.0),), c_code=CCode(),
    rate_of=("f", "rate_tau2_s"), params=params, derive=derive)
