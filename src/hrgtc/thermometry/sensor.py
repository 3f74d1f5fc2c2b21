"""The thermometer of a gyro without a frequency output: its temperature sensor.

``--thermometer sensor`` reads the gyro's temperature sensor (``temperature_c``)
in the place of the resonator frequency; :func:`identity` is its thermometer, f = T
exactly, so that every later stage (drift terms, range flags, exports) runs
unchanged in T and dT/dt.
"""

from __future__ import annotations

import math

from hrgtc.core.errors import InputError
from hrgtc.thermometry.thermometer import Thermometer

__all__ = ["identity"]


def identity(temperature_range_c: tuple[float, float]) -> Thermometer:
    """The thermometer of a gyro without a frequency output: f = T exactly.

    Its temperature sensor is read in the place of the frequency (``--thermometer
    sensor``), so the drift model's terms in f and df/dt are in °C and °C/s, and the
    rest of the pipeline (stepwise selection, range flags, C export) is unchanged.

    Parameters
    ----------
    temperature_range_c
        (min, max) of the training runs' sensor temperatures: the range flags of
        compensation compare against it. [°C]

    Examples
    --------
    >>> th = identity((-10.0, 50.0))
    >>> th.coefficients, float(th.temperature(23.5)), th.source
    ((0.0, 1.0), 23.5, 'sensor')
    """
    low, high = (float(v) for v in temperature_range_c)
    if not (math.isfinite(low) and math.isfinite(high) and low < high):
        raise InputError(
            f"sensor temperature range ({low!r}, {high!r}) °C is not an ordered finite range; "
            "the training runs must span more than one temperature"
        )
    centre, scale = 0.5 * (low + high), 0.5 * (high - low)
    return Thermometer(
        coefficients=(0.0, 1.0),
        standard_errors=(0.0, 0.0),
        residual_std_hz=0.0,
        rsquared=1.0,
        temperature_range_c=(low, high),
        order=1,
        n_points=2,
        centre_c=centre,
        scale_c=scale,
        scaled_coefficients=(centre, scale),
        scaled_covariance=None,
        source="sensor",
    )
