"""What an in-field update gives: the updated model, each axis's figures, the lineage."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core.summary import Figure, Summary
from hrgtc.update.lineage import Lineage

__all__ = ["AxisUpdate", "FilterProblem", "UpdateResult"]

#: Units of the updated terms in the summary (f is a frequency, or a temperature for a
#: gyro whose thermometer is its temperature sensor).
_TERM_UNITS = {"const": "°/h", "f": "°/h per unit of f"}


@dataclass(frozen=True)
class FilterProblem:
    """The filter's inputs, kept so that a second method can be held to it: the prior
    (``mean``, ``covariance``; the first ``n_model`` states are the model's corrections),
    one measurement row per still block (``rows``), the blocks' residuals ``z`` [°/h],
    their variances ``r`` [(°/h)²] and times [h], and the runs' random walks (``walk``,
    :class:`hrgtc.update.kalman.Walk`, its rate chosen by likelihood)."""

    mean: np.ndarray
    covariance: np.ndarray
    rows: np.ndarray
    z: np.ndarray
    r: np.ndarray
    times_h: np.ndarray
    n_model: int
    tau_h: float
    walk: Any = None


@dataclass(frozen=True)
class AxisUpdate:
    """One axis's update.

    Attributes
    ----------
    terms
        The updated coefficients: ``"const"`` (B0) and/or ``"f"`` (the slope).
    before, after
        Their values before and after. [°/h, °/h per unit of f]
    covariance_before, covariance_after
        Their covariance: the prior (the calibration's, plus the ageing allowance) and
        the filter's posterior.
    n_blocks, n_fit, n_heldout
        Still blocks used, fitted on, held out.
    heldout_before_dph, heldout_after_dph
        Rms of the held-out blocks' residuals with the parent model and with the update
        fitted on the other blocks (each run's mean removed when the offset is not
        updated). [°/h]
    heldout_before_interval, heldout_after_interval
        Their 95 % bootstrap intervals (over the held-out blocks). [°/h]
    mahalanobis
        Length of the step from the prior in the prior's metric.
    jump_sigma
        Largest step of the residuals within a run, in standard errors.
    span_c
        Temperature span of the still blocks. [°C]
    block_noise_dph
        1σ of one block's mean (from the data). [°/h]
    problem
        The filter's inputs (:class:`FilterProblem`).
    traces
        Trace of the corrections' covariance after each block.
    """

    terms: tuple[str, ...]
    before: tuple[float, ...]
    after: tuple[float, ...]
    covariance_before: np.ndarray
    covariance_after: np.ndarray
    n_blocks: int
    n_fit: int
    n_heldout: int
    heldout_before_dph: float
    heldout_after_dph: float
    heldout_before_interval: tuple[float, float]
    heldout_after_interval: tuple[float, float]
    mahalanobis: float
    jump_sigma: float
    span_c: float
    block_noise_dph: float
    problem: FilterProblem
    traces: np.ndarray


@dataclass(frozen=True)
class UpdateResult:
    """An in-field update (:func:`hrgtc.update.update_model`, :meth:`hrgtc.model.Model.update`).

    Attributes
    ----------
    model
        The updated model (its ``lineage`` set), or None when nothing changed.
    applied
        Whether the recordings changed the model.
    reason
        Why nothing changed (no still period, nothing observable), empty when applied.
    axes
        Axis name -> :class:`AxisUpdate` (``""`` for a single-axis model).
    lineage
        The lineage written into the updated model (None when nothing changed).
    notes
        What the reader should know (what was not updated and why).
    triad
        A triad's offsets updated from the magnitude of the Earth rate
        (:class:`hrgtc.update.triad.TriadUpdate`), or None.
    """

    model: Any
    applied: bool
    reason: str = ""
    axes: dict[str, AxisUpdate] = field(default_factory=dict)
    lineage: Lineage | None = None
    notes: tuple[str, ...] = ()
    triad: Any = None

    def summary(self) -> Summary:
        """The updated coefficients with ±1σ (before and after), the held-out still residual
        before and after with its 95 % bootstrap interval, the step and jump statistics."""
        sections = []
        for axis, part in self.axes.items():
            prefix = f"axes.{axis}." if axis else ""
            where = f" ({axis})" if axis else ""
            figures = []
            for k, term in enumerate(part.terms):
                unit = _TERM_UNITS.get(term, "")
                figures.append(Figure.with_error(
                    f"{prefix}before.{term}", f"{term} before", part.before[k],
                    math.sqrt(part.covariance_before[k, k]), unit,
                    definition="The parent's coefficient, ±1σ of the prior (calibration "
                    "covariance plus the ageing allowance)."))
                figures.append(Figure.with_error(
                    f"{prefix}after.{term}", f"{term} after", part.after[k],
                    math.sqrt(part.covariance_after[k, k]), unit,
                    definition="The updated coefficient, ±1σ of the filter's posterior."))
            sections.append((f"updated coefficients{where}", tuple(figures)))
            sections.append((f"held-out still residual{where}", (
                Figure(f"{prefix}heldout_before_dph", "rms before", part.heldout_before_dph,
                       "°/h", part.heldout_before_interval, "95 % bootstrap", 4,
                       definition="Rms of the held-out still blocks' residuals with the "
                       "parent model."),
                Figure(f"{prefix}heldout_after_dph", "rms after", part.heldout_after_dph,
                       "°/h", part.heldout_after_interval, "95 % bootstrap", 4,
                       definition="The same with the update fitted on the other blocks."),
                Figure(f"{prefix}n_heldout", "held-out blocks", part.n_heldout),
                Figure(f"{prefix}n_blocks", "still blocks", part.n_blocks),
                Figure(f"{prefix}span_c", "temperature span", part.span_c, "°C", digits=3),
                Figure(f"{prefix}mahalanobis", "step from the prior", part.mahalanobis, "σ",
                       digits=3, definition="Mahalanobis length of the update's step in "
                       "the prior's metric."),
                Figure(f"{prefix}jump_sigma", "largest step within a run",
                       part.jump_sigma, "σ", digits=3),
                Figure(f"{prefix}walk_dph_per_sqrt_h", "bias wander (random walk)",
                       math.sqrt(part.problem.walk.q_per_h if part.problem.walk else 0.0),
                       "°/h/√h", digits=3, definition="The random walk of each recording's "
                       "bias the filter allows for, the rate under which the blocks are "
                       "most likely (docs/guide/update.md)."))))
        if self.triad is not None:
            sections += _triad_sections(self.triad)
        notes = (*((self.reason,) if self.reason else ()), *self.notes)
        title = "in-field update" + ("" if self.applied else ": nothing changed")
        return Summary(title, tuple(sections), notes)


def _triad_sections(triad: Any) -> list[tuple[str, tuple[Figure, ...]]]:
    """The offsets of a triad from |Ω|: each before and after with ±1σ, and the figures
    that judge them."""
    figures = []
    for k, axis in enumerate(triad.axes):
        figures += [Figure.with_error(
                        f"triad.before.{axis}", f"offset {axis} before", triad.before[k],
                        math.sqrt(triad.covariance_before[k, k]), "°/h",
                        definition="The parent's intercept B0, ±1σ of the prior (calibration, "
                        "ageing allowance, turn-on shift)."),
                    Figure.with_error(
                        f"triad.after.{axis}", f"offset {axis} after", triad.after[k],
                        math.sqrt(triad.covariance_after[k, k]), "°/h",
                        definition="The updated intercept, ±1σ of the posterior.")]
    judged = (
        Figure("triad.rate_norm_dph", "|Ω| used", triad.rate_norm_dph, "°/h", digits=6),
        Figure("triad.n_orientations", "orientations", triad.n_orientations),
        Figure("triad.n_periods", "still periods", triad.n_periods),
        Figure("triad.condition", "condition number", triad.condition, digits=3,
               definition="Of the still periods' information about the three offsets."),
        Figure("triad.heldout_before_dph", "held-out rms of |m| - |Ω| before",
               triad.heldout_before_dph, "°/h", digits=4),
        Figure("triad.heldout_after_dph", "held-out rms of |m| - |Ω| after",
               triad.heldout_after_dph, "°/h", digits=4),
        Figure("triad.n_heldout", "held-out blocks", triad.n_heldout),
        Figure("triad.mahalanobis", "step from the prior", triad.mahalanobis, "σ", digits=3))
    return [("offsets of the triad from |Ω| (updated coefficients)", tuple(figures)),
            ("offsets of the triad: how they are known", judged)]
