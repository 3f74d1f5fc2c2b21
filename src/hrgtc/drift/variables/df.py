"""``df``: the causal rate of f, the paper's df/dt (Eq. 21 of [1]).

Two first-order stages of time constant ``rate_tau_s``, each step exact over the sample's
own Δt (:func:`hrgtc.drift.rate_filter.causal_rate`); the filter runs in the numba kernel
and in the C export's skeleton as well.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import numpy as np

from hrgtc.drift.variables.spec import ALL, DriftVariable, Inputs


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """Causal rate of f (the filter ``f``, shared with dpos). [Hz/s]"""
    return inputs.rate("f", inputs.settings.rate_tau_s, "f")


VARIABLE = DriftVariable(
    name="df", unit="Hz/s", sensor_unit="°C/s", kind="rate",
    description="causal rate of f (two first-order stages of time constant rate_tau_s)",
    backends=ALL, columns=("freq_hz",), compute=compute, order=1, rate_of=("f", "rate_tau_s"))
