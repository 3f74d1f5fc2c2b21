"""The published numbers of [1] and their reproduction.

Every constant carries its place in the paper. :func:`reproduce` refits
Table 1 with :func:`hrgtc.thermometry.fit` and inverts the fit at Table 2's
frequencies, so the paper's Eq. (18) and Table 2 are recomputed, not copied.

[1] X. Wang et al., "Temperature Drift Compensation for Hemispherical Resonator
    Gyro Based on Natural Frequency", Sensors 12(5), 6434-6446, 2012.
    doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.thermometry import Thermometer, fit

# Table 1 of [1]: chamber set-point and settled natural frequency of each soak.
TABLE1_TEMPERATURE_C = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0])
TABLE1_FREQUENCY_HZ = np.array([4416.97, 4421.05, 4424.90, 4428.56, 4432.07, 4435.56, 4439.20])
# Decimals Table 1 of [1] prints each frequency with.
TABLE1_FREQUENCY_DECIMALS = 2

# Eq. (18) of [1] as printed, highest power first: T^3, T^2, T, 1.
EQ18_PRINTED_HIGH_FIRST = (1.528e-5, -9.702e-4, 0.3716, 4424.901)
# Significant digits of each printed coefficient of Eq. (18), same order.
EQ18_PRINTED_SIGNIFICANT_DIGITS = (4, 4, 4, 7)

# Table 2 of [1]: frequency, actual temperature, calculated temperature, error.
TABLE2_FREQUENCY_HZ = TABLE1_FREQUENCY_HZ
TABLE2_ACTUAL_C = TABLE1_TEMPERATURE_C
TABLE2_CALCULATED_C = np.array([-19.976, -10.058, -0.0026, 10.070, 20.011, 29.924, 40.031])
# Decimals Table 2 of [1] prints each calculated temperature with (10.070: three).
TABLE2_CALCULATED_DECIMALS = (3, 3, 4, 3, 3, 3, 3)
TABLE2_ERROR_C = np.array([-0.024, 0.0578, 0.0026, -0.070, -0.011, 0.076, -0.031])

# Eq. (22) of [1]: the terms stepwise regression kept.
EQ22_TERMS = ("f", "f^2", "f^3", "df", "df^2", "df^3", "f*df")

# Section 4.2 of [1]: 1-sigma bias stability of the cool-down run (room
# temperature to -20 C) before and after compensation. [deg/h]
BIAS_STABILITY_RAW_DPH = 3.0143
BIAS_STABILITY_COMPENSATED_DPH = 0.5848

# Section 3 of [1]: soaks of 4-5 h; the resonator settles after ~15,000 s; 200 Hz data.
SOAK_HOURS = (4.0, 5.0)
SETTLING_TIME_S = 15_000.0
SAMPLE_RATE_HZ = 200.0


@dataclass(frozen=True)
class Reproduction:
    """The paper's Table 1 -> Eq. (18) -> Table 2 chain, recomputed.

    Attributes
    ----------
    thermometer
        Cubic fitted to Table 1.
    coefficients_high_first
        Fitted coefficients of T^3, T^2, T, 1 at full precision.
    rounded_high_first
        The same, rounded to the significant digits Eq. (18) prints.
    table2_computed_c
        Temperatures from inverting the fit at Table 2's frequencies. [°C]
    """

    thermometer: Thermometer
    coefficients_high_first: tuple[float, ...]
    rounded_high_first: tuple[float, ...]
    table2_computed_c: tuple[float, ...]

    def to_dict(self) -> dict[str, Any]:
        """The layout of ``hrgtc paper --json`` (:class:`ReproductionRecord`): Eq. (18) as
        fitted, rounded and printed, and Table 2 published beside recomputed."""
        rows = zip(TABLE2_FREQUENCY_HZ, TABLE2_ACTUAL_C, TABLE2_CALCULATED_C,
                   self.table2_computed_c, strict=True)
        return records.dump(self, ReproductionRecord, eq18=self, table2=[
            {"frequency_hz": f, "actual_c": t, "published_c": p, "computed_c": c}
            for f, t, p, c in rows])


class Eq18Record(records.Record, kw_only=True):
    """Eq. (18) of [1]: coefficients of T^3, T^2, T, 1 fitted, rounded as printed, printed."""

    coefficients_high_first: tuple[float, ...]
    rounded_high_first: tuple[float, ...]
    published_high_first: tuple[float, ...] = EQ18_PRINTED_HIGH_FIRST


class Table2RowRecord(records.Record, kw_only=True):
    """A row of Table 2 of [1]: frequency, actual, published and recomputed temperature."""

    frequency_hz: float
    actual_c: float
    published_c: float
    computed_c: records.Statistic


class ReproductionRecord(records.Record, kw_only=True):
    """A :class:`Reproduction` in ``hrgtc paper --json`` (written only)."""

    eq18: Eq18Record
    table2: tuple[Table2RowRecord, ...]


def round_significant(value: float, digits: int) -> float:
    """``value`` rounded to ``digits`` significant digits."""
    if value == 0.0:
        return 0.0
    return float(f"{value:.{digits - 1}e}")


def reproduce() -> Reproduction:
    """Refit Table 1 and invert at Table 2's frequencies (Eq. 17-18, Tables 1-2 of [1]).

    Examples
    --------
    >>> r = reproduce()
    >>> r.rounded_high_first
    (1.528e-05, -0.0009702, 0.3716, 4424.901)
    """
    thermometer = fit(TABLE1_TEMPERATURE_C, TABLE1_FREQUENCY_HZ, order=3)
    high_first = tuple(float(c) for c in thermometer.coefficients[::-1])
    rounded = tuple(
        round_significant(c, d)
        for c, d in zip(high_first, EQ18_PRINTED_SIGNIFICANT_DIGITS, strict=True)
    )
    # 4439.20 Hz lies 0.03 °C above the fit at 40 °C, as in the paper: no warning here.
    computed = tuple(
        float(t) for t in thermometer.temperature(TABLE2_FREQUENCY_HZ, warn=False)
    )
    return Reproduction(thermometer, high_first, rounded, computed)
