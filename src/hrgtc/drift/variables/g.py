"""``g``: the housing - resonator gradient housing_c - T(freq_hz), T the thermometer's inverse.

Needs the unit's thermometer (Eq. 18 of [1] inverted) and a housing thermistor. The fused
kernel computes it after its thermometer inverse; in C ``step()`` takes ``housing_c`` and
subtracts the C inverse's temperature (NaN beyond the inverse, as in numpy).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from hrgtc.drift.variables.spec import ALL, DriftVariable, Inputs, Put


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """g = housing_c - T(freq_hz). [°C]"""
    resonator = inputs.thermometer.temperature(inputs.chunk["freq_hz"], warn=False)
    return inputs.chunk["housing_c"] - resonator


def check(settings: Any, thermometer: Any, name: str) -> str | None:
    if thermometer is None:
        return ("the variable g (housing - resonator gradient) needs the unit's thermometer "
                "for T(f)")
    return None


class CCode:
    """g's C: ``housing_c`` minus the temperature ``step()`` computed; ``bias_dph(..., g)``."""

    def pieces(self, ctype: Any, double: Any, name: str, settings: Any, prefix: str,
               comment: Callable[[Any], str]) -> dict[str, str]:
        return {
            "constants": "", "state": "", "reset": "", "start": "", "rate": "",
            "values": f"    {ctype.name} g_value;\n",
            "gradient": "    g_value = housing_c - temperature;  /* NaN beyond the inverse */\n",
            "bias": ", g_value",
        }

    def inputs(self, name: str) -> tuple[str, ...]:
        return ("housing_c",)

    def parameter(self, name: str) -> str:
        return "g_c"

    def readme(self, name: str, settings: Any) -> str:
        return "  g  = housing_c - resonator_c_est, the housing - resonator gradient   [degC]"

    def firmware_value(self, value: np.ndarray, name: str, settings: Any) -> np.ndarray:
        # the float mirror replaces it by float32(housing_c) - T32(f): both inverses
        # (hrgtc.export.c.float32's gradient inputs)
        return np.asarray(value).astype(np.float32)


def params(names: tuple[str, ...], settings: Any, put: Put) -> None:
    """g's key of the parameter file: the flag (housing_c becomes an input)."""
    put("uses_gradient", 1, "1: the terms use g = housing_c - T(freq_hz); housing_c is "
        "an input.")


VARIABLE = DriftVariable(
    name="g", unit="°C", sensor_unit="°C", kind="level",
    description="housing - resonator gradient housing_c - T(freq_hz), T the thermometer's "
                "inverse",
    backends=ALL, columns=("freq_hz", "housing_c"), compute=compute, order=6, check=check,
    c_code=CCode(), params=params)
