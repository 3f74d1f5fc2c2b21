"""``dh``: the causal rate of h, by the same filter as df (its own state)."""

from __future__ import annotations

import numpy as np

from hrgtc.drift.variables.spec import ALL, DriftVariable, Inputs


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """Causal rate of h (the filter ``h``). [°C/s]"""
    return inputs.rate("h", inputs.settings.rate_tau_s, "h")


VARIABLE = DriftVariable(
    name="dh", unit="°C/s", sensor_unit="°C/s", kind="rate",
    description="causal rate of h (the same filter as df)",
    backends=ALL, columns=("housing_c",), compute=compute, order=3, rate_of=("h", "rate_tau_s"))
