"""The figures of a test report: what each is, the clause it follows, and its uncertainty.

:data:`FIGURES` is the catalogue: a figure's name (the key of ``spec.toml`` and of the
JSON), its label, unit, the clause of the IEEE inertial-sensor standards it follows and
its definition, written once. A measured figure is a :class:`TestFigure`: its value, its
standard uncertainty u, the coverage factor k and the expanded uncertainty (U⁻, U⁺) (k·u
on both sides, or the χ² interval's sides for the Allan figures), its degrees of freedom
and, once judged (:func:`hrgtc.testreport.spec.decide`), its limit and verdict. A figure
the runs cannot give has no value and a reason: "not measured", never a fail.

The clauses are those of IEEE Std 952-2020 (single-axis interferometric fibre optic
gyros), whose test methods list (6.6) is followed by IEEE Std 1431-2004 for Coriolis
vibratory gyros (the HRG is one); the Allan noise terms follow IEEE Std 952-1997 Annex C,
and the analysis of the records IEEE Std 1554-2005 (inertial sensor test practice).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

from hrgtc.core.summary import Figure
from hrgtc.testreport.spec import Limit, decide

__all__ = ["FIGURES", "FigureInfo", "TestFigure", "measured", "not_measured"]

_952 = "IEEE Std 952-2020"


@dataclass(frozen=True)
class FigureInfo:
    """What a figure is: its label, unit, clause and definition."""

    label: str
    unit: str
    clause: str
    definition: str
    section: str


#: name -> what the figure is. The names are the keys of spec.toml and of the JSON.
FIGURES: dict[str, FigureInfo] = {name: FigureInfo(*info) for name, info in {
    "turn_on_time_s": (
        "turn-on time", "s", f"{_952}, 6.6.5 turn-on time",
        "Longest over the turn-ons of the time from the first sample until every later block "
        "mean stays within ± turn_on_tolerance_dph of that turn-on's settled bias; u: the "
        "block length's resolution, block_s/√12.", "turn-on"),
    "warm_up_drift_dph": (
        "warm-up drift", "°/h", f"{_952}, 6.6.6 warm-up time",
        "Largest over the turn-ons of |block mean − settled bias| during the first settle_s; "
        "u: the 1σ of the settled block means (one block's noise).", "turn-on"),
    "bias_dph": (
        "bias", "°/h", f"{_952}, 6.6.11 drift rate test series (bias)",
        "Mean of the turn-on biases, each the mean output after settle_s less the Earth-rate "
        "component; u: their 1σ over √n.", "turn-on"),
    "bias_repeatability_dph": (
        "bias repeatability", "°/h", f"{_952}, 6.6.11 drift rate test series (bias "
        "repeatability, turn-on to turn-on)",
        "1σ (n − 1) of the turn-on biases, on separate turn-ons and days; u: σ/√(2(n − 1)).",
        "turn-on"),
    "bias_repeatability_compensated_dph": (
        "bias repeatability, compensated", "°/h", f"{_952}, 6.6.11 (bias repeatability)",
        "1σ (n − 1) of the turn-on biases after compensation; u: σ/√(2(n − 1)).", "turn-on"),
    "bias_temperature_sensitivity_dph_per_c": (
        "bias temperature sensitivity", "°/h/°C", f"{_952}, 6.6.11 drift rate test series "
        "(bias temperature sensitivity)",
        "Least-squares slope of the soaks' settled biases against their temperatures (with "
        "no soaks, of a sweep's block means against temperature and its rate of change); "
        "u: the slope's standard error.", "temperature"),
    "bias_temperature_sensitivity_compensated_dph_per_c": (
        "bias temperature sensitivity, compensated", "°/h/°C", f"{_952}, 6.6.11",
        "The bias temperature sensitivity of the compensated output (the residual the model "
        "leaves).", "temperature"),
    "bias_gradient_sensitivity_dph_per_c_per_min": (
        "bias temperature-gradient sensitivity", "°/h/(°C/min)", f"{_952}, 6.6.11 drift "
        "rate test series (bias temperature-gradient sensitivity)",
        "Least-squares slope of the sweeps' block means, less the temperature sensitivity "
        "times temperature, against the temperature's rate of change; u: the slope's "
        "standard error, widened for the block means' lag-1 autocorrelation (the "
        "temperature sensitivity's own uncertainty is not propagated).",
        "temperature"),
    "bias_gradient_sensitivity_compensated_dph_per_c_per_min": (
        "bias temperature-gradient sensitivity, compensated", "°/h/(°C/min)",
        f"{_952}, 6.6.11", "The gradient sensitivity of the compensated output.",
        "temperature"),
    "scale_factor_error_ppm": (
        "scale-factor error", "ppm", f"{_952}, 6.6.9 gyro scale factor test series",
        "Slope k of (output − Ω) = b + k·Ω over the rate-table holds of the plateau nearest "
        "reference_c; u: its standard error.", "scale factor"),
    "scale_factor_temperature_sensitivity_ppm_per_c": (
        "scale-factor temperature sensitivity", "ppm/°C", f"{_952}, 6.6.9 (gyro scale "
        "factor sensitivities)",
        "Least-squares slope of the plateaus' scale-factor errors against their temperatures; "
        "u: the slope's standard error (from the plateaus' own with two plateaus).",
        "scale factor"),
    "angle_random_walk_deg_per_rt_h": (
        "angle random walk", "°/√h", "IEEE Std 952-1997, Annex C",
        "The −½-slope line of the overlapping Allan deviation read at τ = 1 h, on the "
        "longest stretch at rest of the longest turn-on after settle_s; U: its χ² interval "
        "at k's coverage.", "noise"),
    "bias_instability_dph": (
        "bias instability", "°/h", "IEEE Std 952-1997, Annex C",
        "The flat minimum of the Allan deviation over 0.664; U: its χ² interval at k's "
        "coverage.", "noise"),
    "rate_random_walk_dph_per_rt_h": (
        "rate random walk", "°/h/√h", "IEEE Std 952-1997, Annex C",
        "The +½-slope line of the Allan deviation read at τ = 3 h; U: its χ² interval.",
        "noise"),
    "bias_instability_compensated_dph": (
        "bias instability, compensated", "°/h", "IEEE Std 952-1997, Annex C",
        "The bias instability of the compensated output.", "noise"),
}.items()}


@dataclass(frozen=True)
class TestFigure:
    """One figure of the report, measured or not, and its verdict.

    Attributes
    ----------
    name
        Its key of :data:`FIGURES`.
    value
        The number, or None: not measured (``reason`` says why).
    u
        Standard uncertainty, or None where only an interval is known.
    expanded
        (U⁻, U⁺): expanded uncertainty below and above the value.
    k
        Coverage factor.
    dof
        Degrees of freedom behind u, where known.
    basis
        What the uncertainty is (``"k·u"``, ``"χ² interval, 95.4 %"``).
    reason
        Why a figure is not measured.
    limit, verdict
        The spec's limit (None: none) and the decision (:mod:`hrgtc.testreport.spec`).
    """

    name: str
    value: float | None
    u: float | None = None
    expanded: tuple[float, float] | None = None
    k: float = 2.0
    dof: float | None = None
    basis: str = ""
    reason: str = ""
    limit: Limit | None = None
    verdict: str = ""

    __test__ = False  # not a pytest class

    @property
    def info(self) -> FigureInfo:
        """Its label, unit, clause and definition."""
        return FIGURES[self.name]

    @property
    def interval(self) -> tuple[float, float] | None:
        """(value − U⁻, value + U⁺), or None."""
        if self.value is None or self.expanded is None:
            return None
        return (self.value - self.expanded[0], self.value + self.expanded[1])

    def judged(self, limit: Limit | None) -> TestFigure:
        """The figure with ``limit`` and its verdict."""
        return replace(self, limit=limit, verdict=decide(self.value, self.expanded, limit))

    def summary_figure(self) -> Figure:
        """As a :class:`~hrgtc.core.summary.Figure` (NaN when not measured)."""
        info = self.info
        kind = f"U, k = {self.k:g}" if self.expanded is not None else ""
        return Figure(self.name, info.label, math.nan if self.value is None else self.value,
                      info.unit, self.interval, kind, digits=4,
                      definition=f"{info.definition} ({info.clause})")

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (what is not finite: null)."""
        def clean(v: float | None) -> float | None:
            return None if v is None or not math.isfinite(v) else float(v)

        info = self.info
        return {
            "name": self.name, "label": info.label, "unit": info.unit, "value": clean(self.value),
            "standard_uncertainty": clean(self.u), "coverage_factor": self.k,
            "expanded_uncertainty": (None if self.expanded is None
                                     else [clean(e) for e in self.expanded]),
            "interval": None if self.interval is None else [clean(e) for e in self.interval],
            "degrees_of_freedom": clean(self.dof), "uncertainty_basis": self.basis,
            "clause": info.clause, "definition": info.definition,
            "limit": (None if self.limit is None else
                      {"min": self.limit.min, "max": self.limit.max}),
            "verdict": self.verdict, "reason": self.reason or None}


def measured(name: str, value: float, u: float, k: float, dof: float | None = None,
             basis: str = "") -> TestFigure:
    """A figure with a symmetric expanded uncertainty U = k·u."""
    expanded = (k * u, k * u) if math.isfinite(u) else None
    return TestFigure(name, float(value), float(u), expanded, k,
                      None if dof is None else float(dof), basis or f"U = k·u, k = {k:g}")


def not_measured(name: str, reason: str, k: float = 2.0) -> TestFigure:
    """A figure the runs cannot give, and why."""
    return TestFigure(name, None, k=k, reason=reason)
