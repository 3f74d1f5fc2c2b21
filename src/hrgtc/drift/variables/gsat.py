"""``gsat``: the saturating gradient tanh(g / G_s), g the housing - resonator gradient.

A heating/cooling difference that grows with the gradient and then stops growing (the
simulator's ``h tanh(G/G_h)`` of ``unit-b``, a lag that saturates, not a memory:
docs/history.md). ``G_s`` is ``gradient_saturation_c`` (``--gradient-saturation-c``,
1 °C by default). The numpy reference only: the fused kernel hands such a model to numpy
and the exports refuse it (docs/architecture.md, "Adding a drift variable").
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.drift.variables.spec import DriftVariable, Inputs

#: G_s when ``--gradient-saturation-c`` is not given. [°C]
DEFAULT_SATURATION_C = 1.0


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """gsat = tanh(g / G_s) (g: :mod:`hrgtc.drift.variables.g`). [1]"""
    return np.tanh(inputs.value("g") / inputs.settings.gradient_saturation_c)


def check(settings: Any, thermometer: Any, name: str) -> str | None:
    if thermometer is None:
        return ("the variable gsat (saturating gradient) needs the unit's thermometer for "
                "the gradient g = housing_c - T(freq_hz)")
    if not settings.gradient_saturation_c > 0.0:
        return ("the variable gsat needs gradient_saturation_c > 0 in the feature settings "
                "(--gradient-saturation-c)")
    return None


def derive(names: tuple[str, ...], given: Mapping[str, Any]) -> dict[str, Any]:
    """G_s: ``--gradient-saturation-c``, else :data:`DEFAULT_SATURATION_C`. [°C]"""
    value = given["gradient_saturation_c"]
    return {"gradient_saturation_c": DEFAULT_SATURATION_C if value is None else float(value)}


VARIABLE = DriftVariable(
    name="gsat", unit="1", sensor_unit="1", kind="level",
    description="saturating housing - resonator gradient tanh(g/G_s) "
                "(G_s: gradient_saturation_c)",
    backends=frozenset({"numpy"}), columns=("freq_hz", "housing_c"), compute=compute,
    order=7, check=check,
    settings_fields=(("gradient_saturation_c", records.NonNegative, 0.0),), derive=derive,
    omit_default_settings=True)
