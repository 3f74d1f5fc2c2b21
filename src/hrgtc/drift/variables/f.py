"""``f``: the frequency change freq_hz - f_ref, the paper's temperature variable (Eq. 21 of [1]).

f_ref is the thermometer's frequency at ``reference_c``. With the gyro's temperature
sensor as thermometer (``calibrate --thermometer sensor``) the sensor's reading takes the
frequency's place, so f is in °C. Its C code is the export's skeleton
(:mod:`hrgtc.export.c.source`), its kernel row the first of :mod:`hrgtc.compensate._kernel`.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import numpy as np

from hrgtc.drift.variables.spec import ALL, DriftVariable, Inputs


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """f = freq_hz - reference_freq_hz. [Hz]"""
    return inputs.chunk["freq_hz"] - inputs.settings.reference_freq_hz


VARIABLE = DriftVariable(
    name="f", unit="Hz", sensor_unit="°C", kind="level",
    description="frequency change freq_hz - f_ref (f_ref: the thermometer at reference_c)",
    backends=ALL, columns=("freq_hz",), compute=compute, order=0)
