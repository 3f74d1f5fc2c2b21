"""``dpos``: the heating part of df, a smooth switch between heating and cooling.

dpos = df·(1 + tanh(df/δ))/2 (δ: ``switch_hz_per_s``, set in training from the spread of
the training df/dt), so ``df`` + ``dpos`` give heating and cooling their own rate
coefficients (HRG drift differs between the two: Li et al., Sci. Rep. 13:6019, 2023).
The numpy reference only: the fused kernel hands such a model to numpy and the exports
refuse it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.drift.variables.spec import DriftVariable, FirstPass, Inputs

#: δ of ``dpos`` as a share of the std of the training windows' df/dt.
SWITCH_FRACTION = 0.1


def heating_part(rate: np.ndarray, switch: float) -> np.ndarray:
    """The smooth positive part rate·(1 + tanh(rate/δ))/2 of a rate. [unit of rate]

    Examples
    --------
    >>> [round(float(x), 4) for x in heating_part(np.array([-1.0, 0.0, 1.0]), 0.1)]
    [-0.0, 0.0, 1.0]
    """
    return rate * (1.0 + np.tanh(rate / switch)) / 2.0


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """dpos from df's filter (the same state as df). [Hz/s]"""
    s = inputs.settings
    return heating_part(inputs.rate("f", s.rate_tau_s, "f"), s.switch_hz_per_s)


def check(settings, thermometer, name: str) -> str | None:
    if not settings.switch_hz_per_s > 0.0:
        return ("the variable dpos needs switch_hz_per_s > 0 in the feature settings "
                "(drift.fit sets it from the training df/dt)")
    return None


def switch(names: tuple[str, ...], means: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """δ from the first pass: :data:`SWITCH_FRACTION` × the std of the training windows'
    df/dt (1 Hz/s when df/dt does not vary). [Hz/s]"""
    spread = float(np.std(means["df"]))
    return {"switch_hz_per_s": SWITCH_FRACTION * spread if spread > 0.0 else 1.0}


VARIABLE = DriftVariable(
    name="dpos", unit="Hz/s", sensor_unit="°C/s", kind="rate",
    description="heating/cooling switch: the heating part of df, df*(1 + tanh(df/delta))/2 "
                "(delta: switch_hz_per_s)",
    backends=frozenset({"numpy"}), columns=("freq_hz",), compute=compute, order=4,
    check=check, settings_fields=(("switch_hz_per_s", records.NonNegative, 0.0),),
    first_pass=FirstPass(reads=lambda names: ("df",), derive=switch))
