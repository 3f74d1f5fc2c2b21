"""``h``: the housing temperature change housing_c - reference_c (a housing thermistor).

Its C code is the export's skeleton (``step()`` then takes ``housing_c``).
"""

from __future__ import annotations

import numpy as np

from hrgtc.drift.variables.spec import ALL, DriftVariable, Inputs


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """h = housing_c - reference_c. [°C]"""
    return inputs.chunk["housing_c"] - inputs.settings.reference_c


VARIABLE = DriftVariable(
    name="h", unit="°C", sensor_unit="°C", kind="level",
    description="housing temperature change housing_c - reference_c",
    backends=ALL, columns=("housing_c",), compute=compute, order=2)
