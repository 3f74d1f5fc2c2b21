"""The deviation curve of an evaluation pass (``--deviation``), its confidence interval
and its JSON form."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from hrgtc.evaluation.allan import (
    AllanResult,
    allan_deviation,
    confidence_interval,
    equivalent_degrees_of_freedom,
)

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


def _with_interval(result: AllanResult, n_samples: int, confidence: float) -> AllanResult:
    """The overlapping Allan deviation with its chi-squared interval (SP 1065 simple edf)."""
    m = np.rint(result.taus_s * result.sample_rate_hz).astype(np.int64)
    edf = np.array([equivalent_degrees_of_freedom(n_samples + 1, int(k)) for k in m])
    lower, upper = confidence_interval(result.deviation, edf, confidence)
    return replace(result, lower=lower, upper=upper, confidence=float(confidence))


def _deviation(values: np.ndarray, fs: float, deviation: str, confidence: float) -> AllanResult:
    """The run's deviation curve with its confidence interval (SP 1065 Section 5.3)."""
    kind, overlapping = DEVIATIONS[deviation]
    return allan_deviation(values, fs, taus="octave", kind=kind, overlapping=overlapping,
                           confidence=confidence)
