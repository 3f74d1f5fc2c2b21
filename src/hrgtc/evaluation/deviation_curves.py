"""The deviation curve of an evaluation pass (``--deviation``), its confidence interval
and its JSON form."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from hrgtc.core.records import Count, Positive, Record, Statistic
from hrgtc.evaluation.allan import AllanResult
from hrgtc.evaluation.allan_segments import pooled_deviation
from hrgtc.evaluation.metrics import bias_stability_interval
from hrgtc.evaluation.series_stats import SeriesStatistics

#: ``--deviation`` names -> (kind of :func:`allan_deviation`, overlapping), after allantools.
DEVIATIONS = {"adev": ("allan", False), "oadev": ("allan", True), "mdev": ("modified", True),
              "hdev": ("hadamard", True), "tdev": ("time", True)}


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _curve(allan: AllanResult) -> dict[str, Any]:
    """One deviation curve as JSON lists (lower/upper None where no interval)."""
    def listed(values: np.ndarray | None) -> list[float | None]:
        if values is None:
            return [None] * allan.taus_s.size
        return [_finite(float(v)) for v in values]

    return {"tau_s": allan.taus_s.tolist(), "deviation": listed(allan.deviation),
            "lower": listed(allan.lower), "upper": listed(allan.upper),
            "n": allan.counts.tolist(), "kind": allan.kind, "overlapping": allan.overlapping}


class DeviationCurveRecord(Record):
    """One deviation curve of an evaluation (``allan_curve``: :func:`_curve`): τ, the
    deviation, its interval (null where the kind has none) and the terms behind each."""

    tau_s: list[Positive]
    deviation: list[Statistic]
    lower: list[Statistic]
    upper: list[Statistic]
    n: list[Count]
    kind: str
    overlapping: bool


def _deviation(values: np.ndarray, fs: float, deviation: str, confidence: float,
               breaks: list[int] | None = None) -> AllanResult:
    """The run's deviation curve, pooled within the segments that start at ``breaks``,
    with its confidence interval (SP 1065 Section 5.3; pooled edf)."""
    kind, overlapping = DEVIATIONS[deviation]
    return pooled_deviation(values, fs, breaks or [], "octave", overlapping, kind=kind,
                            confidence=confidence)


def stability_intervals(table: dict[float, float], blocks: dict[float, int],
                        confidence: float) -> dict[float, tuple[float, float]]:
    """The chi-squared interval of each bias stability from its own number of τ-blocks."""
    return {tau: bias_stability_interval(value, blocks.get(tau, 0), confidence)
            for tau, value in table.items()}


def segment_notes(key: str, series: SeriesStatistics, stability: dict[float, float],
                  allan: bool) -> list[str]:
    """What a recording of segments does to the figures of one series (none for one)."""
    if series.segments < 2:
        return []
    notes = []
    longest = series.longest_segment_s
    missing = [tau for tau, value in stability.items() if math.isnan(value) and tau > longest]
    if missing:
        notes.append(
            f"{key}: bias stability at τ = {', '.join(f'{t:g}' for t in missing)} s not "
            f"estimable: τ-means never span a gap and the longest of the "
            f"{series.segments} segments holds {longest:.6g} s (means of bursts across "
            "the gaps would carry the dead time's bias)")
    if allan:
        notes.append(
            f"{key}: deviation pooled within {series.segments} segments, no difference "
            f"across a gap (N: terms summed over the segments; interval from their pooled "
            f"edf); τ beyond {longest / 2:.6g} s (half the longest segment) not in the curve")
    return notes
