"""How far a compensated run went beyond what the model was trained on.

The drift model is a regression on the temperatures and df/dt of its training
runs. Beyond them it continues along its tangent (see
:func:`hrgtc.drift.features.tangent_extension`), which keeps a law linear in
df/dt exact but is a guess otherwise; samples beyond the trained temperature or
df/dt carry 2-3x the model error in held-out tests. :class:`RangeReport` gives
the share of such samples and how far they went, in units a user reads
(°C beyond the trained temperatures; df/dt as a multiple of the largest trained
one and as a resonator temperature rate in °C/h), and says it in one line per
kind for the command line (``--strict`` turns it into an exit status).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import ExtrapolationWarning
from hrgtc.core.records import Count, Statistic
from hrgtc.drift import DriftModel
from hrgtc.drift.variables import is_aux, unit, variable
from hrgtc.thermometry import Thermometer

#: (min, max) of a range; either may be null (not finite).
Pair = tuple[Statistic, Statistic]


@dataclass(frozen=True)
class VariableRange(records.Written):
    """How far one drift variable (beyond f and df) went beyond its training range.

    Attributes
    ----------
    name
        The variable (``h``, ``dh``, ``d2``, ``g``, ``a_NAME``; see
        :mod:`hrgtc.drift.variables`).
    unit
        Unit of ``trained`` and ``seen`` (rates of change per hour: °C/h or Hz/h...).
    fraction
        Share of the samples outside the training range.
    trained, seen
        (min, max) of the training samples (window means in models fitted before
        issue 20) and of the settled samples seen. [unit]
    """

    #: Its record (:data:`VariableRangeRecord`): the name written as ``variable``.
    file_names = (("name", "variable"),)

    name: str
    unit: str
    fraction: float
    trained: Pair
    seen: Pair

    @records.derived(default=None)
    def excess(self) -> Statistic:
        """Farthest seen value beyond the trained range (0 inside). [unit]"""
        low, high = self.trained
        beyond = [0.0, low - self.seen[0], self.seen[1] - high]
        return max(b for b in beyond if math.isfinite(b)) if self.fraction else 0.0

    def warning(self) -> str:
        """One line: the share, the variable, its trained and seen range, how far beyond."""
        described = variable(self.name).description.split(" (")[0]
        low, high = self.trained
        return (f"warning: {self.fraction:.1%} of samples beyond the trained range of "
                f"{self.name} ({described}) {low:.4g} to {high:.4g} {self.unit}, up to "
                f"{self.excess:.4g} {self.unit} beyond (seen {self.seen[0]:.4g} to "
                f"{self.seen[1]:.4g} {self.unit})")

#: The record of :class:`VariableRange`, generated from its fields and ``excess``.
VariableRangeRecord = records.record_of(
    VariableRange, doc="The record of :class:`VariableRange` (``excess`` written, not read "
    "back).")


@dataclass(frozen=True)
class RangeReport(records.Written):
    """Shares of samples beyond the trained ranges, and how far (one run).

    Attributes
    ----------
    samples
        Samples seen.
    temperature_fraction
        Share of the samples that are settled and outside the calibrated temperature
        range (thermometer and drift training); a settling sample is counted in
        ``settling_fraction`` only.
    rate_fraction
        Share of the samples that are settled and whose df/dt is outside its training
        range.
    settling_fraction
        Share in the filter's settling time at the start (flagged, left out of figures).
    trained_c, seen_c
        (min, max) trained and seen (settled samples) resonator temperature. [°C]
    trained_rate_c_per_h, seen_rate_c_per_h
        (min, max) trained and seen df/dt as a resonator temperature rate. [°C/h]
    variables
        The model's other variables with a training range (h, dh, d2, g, a_NAME), each
        with its own share and how far it went: a gradient ``g`` beyond its range is
        said as such, not as a temperature (``temperature_fraction`` counts only the
        calibrated frequencies and f's range, ``rate_fraction`` only df/dt's).
    """

    #: Its record (:data:`RangeReportRecord`): the excesses written, not read back.
    record_order = ("samples", "temperature_fraction", "rate_fraction", "settling_fraction",
                    "trained_c", "seen_c", "temperature_excess_c", "trained_rate_c_per_h",
                    "seen_rate_c_per_h", "rate_excess_ratio", "variables")

    samples: Count
    temperature_fraction: float
    rate_fraction: float
    settling_fraction: float
    trained_c: Pair
    seen_c: Pair
    trained_rate_c_per_h: Pair = (math.nan, math.nan)
    seen_rate_c_per_h: Pair = (math.nan, math.nan)
    variables: tuple[VariableRange, ...] = ()

    @records.derived(default=None)
    def temperature_excess_c(self) -> Statistic:
        """Farthest seen temperature beyond the trained range (0 inside). [°C]"""
        low, high = self.trained_c
        return max(0.0, low - self.seen_c[0], self.seen_c[1] - high)

    @records.derived(default=None)
    def rate_excess_ratio(self) -> Statistic:
        """Largest seen |df/dt| beyond the range over the trained one on its side (0 inside)."""
        low, high = self.trained_rate_c_per_h
        ratios = [0.0]
        if self.seen_rate_c_per_h[1] > high:
            ratios.append(self.seen_rate_c_per_h[1] / high if high > 0 else math.inf)
        if self.seen_rate_c_per_h[0] < low:
            ratios.append(self.seen_rate_c_per_h[0] / low if low < 0 else math.inf)
        return max(ratios)

    @property
    def beyond(self) -> bool:
        """Whether any sample after the settling time was beyond a trained range."""
        return (self.temperature_fraction > 0.0 or self.rate_fraction > 0.0
                or any(v.fraction > 0.0 for v in self.variables))

    def shares(self) -> dict[str, float]:
        """Share of samples beyond each trained range: ``temperature``, ``df/dt``, then
        every other variable by name."""
        out = {"temperature": self.temperature_fraction, "df/dt": self.rate_fraction}
        out.update((v.name, v.fraction) for v in self.variables)
        return out

    def shares_text(self) -> str:
        """``temperature 0.0%, df/dt 1.2%, g 72.5%``: one share per variable, for summaries."""
        return ", ".join(f"{name} {share:.1%}" for name, share in self.shares().items())

    def warnings(self) -> list[str]:
        """One line per kind of excursion (empty when the run stayed inside)."""
        lines = []
        if self.temperature_fraction > 0.0:
            low, high = self.trained_c
            lines.append(
                f"warning: {self.temperature_fraction:.1%} of samples beyond the trained "
                f"temperature {low:.2f} to {high:.2f} °C, up to {self.temperature_excess_c:.2f} "
                f"°C beyond (seen {self.seen_c[0]:.2f} to {self.seen_c[1]:.2f} °C)"
            )
        if self.rate_fraction > 0.0:
            low, high = self.trained_rate_c_per_h
            ratio = self.rate_excess_ratio
            how_far = "" if not math.isfinite(ratio) else f", up to {ratio:.2f}× the largest " \
                "trained on that side"
            lines.append(
                f"warning: {self.rate_fraction:.1%} of samples beyond the trained df/dt "
                f"{low:+.1f} to {high:+.1f} °C/h (seen {self.seen_rate_c_per_h[0]:+.1f} to "
                f"{self.seen_rate_c_per_h[1]:+.1f} °C/h{how_far}); train on runs this fast "
                "(calibrate --drift takes several)"
            )
        lines += [v.warning() for v in self.variables if v.fraction > 0.0]
        return lines

#: The record of :class:`RangeReport`, generated from its fields and the excesses.
RangeReportRecord = records.record_of(
    RangeReport, doc="The record of :class:`RangeReport` (the excesses written, not read "
    "back).")


def _temperature(thermometer: Thermometer, freq_hz: np.ndarray) -> np.ndarray:
    """T(f), continued linearly beyond the thermometer's extension (no NaN). [°C]"""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        t = np.asarray(thermometer.temperature(freq_hz, warn=False), dtype=float)
    low, high = thermometer.temperature_range_c
    f_low, f_high = thermometer.frequency(low), thermometer.frequency(high)
    slope = (f_high - f_low) / (high - low)
    lost = ~np.isfinite(t)
    t[lost] = low + (freq_hz[lost] - f_low) / slope
    return t


def range_report(drift: DriftModel, thermometer: Thermometer, samples: int, counts: np.ndarray,
                 extremes: np.ndarray,
                 variables: Mapping[str, Any] | None = None) -> RangeReport:
    """A :class:`RangeReport` from the compensator's counts and extremes of f and df/dt.

    ``counts`` are (outside temperature, outside df/dt, -, settling) and ``extremes``
    (f min, f max, df min, df max) [Hz, Hz/s], as kept by the compensator;
    ``variables`` maps each other variable with a training range to (samples outside
    it, smallest, largest seen) in its own unit.
    """
    s = drift.settings
    f_ref = s.reference_freq_hz
    cal_low, cal_high = thermometer.temperature_range_c
    f_trained = drift.ranges.get("f", (-math.inf, math.inf))
    trained = _temperature(thermometer, np.array([max(f_trained[0], -1e300),
                                                  min(f_trained[1], 1e300)]) + f_ref)
    trained_c = (max(float(trained[0]), cal_low), min(float(trained[1]), cal_high))
    if samples and np.isfinite(extremes[:2]).all():
        seen = _temperature(thermometer, np.asarray(extremes[:2], dtype=float) + f_ref)
        seen_c = (float(seen[0]), float(seen[1]))
    else:
        seen_c = (math.nan, math.nan)
    reference_c = 0.5 * (trained_c[0] + trained_c[1])
    slope = float(thermometer.slope_hz_per_c(reference_c))  # Hz/°C

    def per_hour(values: tuple[float, float]) -> tuple[float, float]:
        low, high = sorted((values[0] / slope * 3600.0, values[1] / slope * 3600.0))
        return (low, high)

    others = []
    for name, (outside, low, high) in (variables or {}).items():
        if name in ("f", "df"):
            continue
        trained = drift.ranges[name]
        seen = (float(low), float(high)) if samples else (math.nan, math.nan)
        unit = variable_unit(name, thermometer.source, drift.settings.aux_columns)
        if variable(name).kind == "rate":  # per hour, as the df/dt line
            if unit.endswith("/s"):
                unit = unit[:-2] + "/h"
            trained = (trained[0] * 3600.0, trained[1] * 3600.0)
            seen = (seen[0] * 3600.0, seen[1] * 3600.0)
        others.append(VariableRange(name, unit, float(outside) / samples if samples else 0.0,
                                    (float(trained[0]), float(trained[1])), seen))

    df_trained = drift.ranges.get("df", (-math.inf, math.inf))
    share = (lambda k: counts[k] / samples if samples else 0.0)  # noqa: E731
    return RangeReport(
        samples=int(samples),
        temperature_fraction=float(share(0)),
        rate_fraction=float(share(1)),
        settling_fraction=float(share(3)),
        trained_c=trained_c,
        seen_c=seen_c,
        trained_rate_c_per_h=per_hour(df_trained),
        seen_rate_c_per_h=per_hour((float(extremes[2]), float(extremes[3]))),
        variables=tuple(others),
    )


def variable_unit(name: str, source: str, aux_columns: Mapping[str, str]) -> str:
    """A variable's unit for the range report (an extra channel: its column's)."""
    if is_aux(name):
        return f"(unit of {aux_columns.get(name[2:], name[2:])})"
    return unit(name, source)
