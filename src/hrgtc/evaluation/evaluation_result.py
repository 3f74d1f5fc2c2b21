"""The result of evaluating a run: :class:`Evaluation`, its figures and its text.

:func:`hrgtc.evaluation.run_pass.run_pass` (one pass over a run, raw vs compensated)
returns it; ``hrgtc evaluate``, ``calibrate --validate``, the report and the demo render
it (:meth:`Evaluation.summary`, :meth:`Evaluation.to_dict`, :meth:`Evaluation.allan_csv`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cache
from typing import Annotated, Any

import numpy as np
from msgspec import Meta

from hrgtc.compensate.ranges import RangeReport, RangeReportRecord
from hrgtc.core import records
from hrgtc.core.accounting import Accounting, AccountingRecord
from hrgtc.core.records import Count, NonNegative, Positive, Record, Statistic
from hrgtc.core.summary import Summary
from hrgtc.evaluation.allan import ONE_SIGMA, AllanResult
from hrgtc.evaluation.burst_allan import BurstAllanRecord, BurstAllanResult
from hrgtc.evaluation.deviation_curves import DeviationCurveRecord, _curve
from hrgtc.evaluation.heating_cooling import DirectionStats, DirectionStatsRecord
from hrgtc.evaluation.metrics import StabilityTable, table_to_json
from hrgtc.evaluation.noise import NoiseTerms, NoiseTermsRecord
from hrgtc.evaluation.run_figures import run_figures
from hrgtc.settings.compensation import EvaluationSettings

__all__ = ["Evaluation", "EvaluationRecord", "evaluation_json_schema"]


@dataclass(frozen=True, eq=False)
class Evaluation:
    """One run compensated and measured (the result of :func:`run_pass`).

    Attributes
    ----------
    file, source, unit
        The run's name, where it came from, and the gyro named in its metadata.
    n_samples, sample_rate_hz, input_rate_dph
        Size and rate of the run and the known input rate subtracted. [-, Hz, °/h]
    bias_stability_dph
        ``{"raw"|"compensated"|"housing": {tau_s: 1σ of τ-second means}}``, NaN where
        fewer than two blocks fit (``"housing"`` only with a housing baseline and
        ``housing_c``). [s] -> [°/h]
    allan, noise
        Allan deviation (``deviation``, octave τ, with its ``confidence`` interval where
        SP 1065 gives one) and its noise terms (Allan deviations only), same keys (empty
        when not computed or when the series is too short; see ``notes``).
    out_of_range_fraction
        Share outside the calibrated temperatures or a level variable's training range
        (f, h, g, a_NAME); ``ranges`` gives each variable's own share.
    rate_out_of_range_fraction
        Share of samples whose df/dt (dh/dt, d2) is outside its training range.
    residual_rms_dph
        RMS of model bias minus true bias (simulated runs only). [°/h]
    block_s, blocks
        Plotting blocks (length [s] and block means of ``time_s``, ``raw_dph``,
        ``model_dph``, ``comp_dph``, ``temperature_c``, ``in_range`` and where recorded
        ``comp_housing_dph``, ``true_dph``, ``resonator_c``, ``housing_c``,
        ``chamber_c``, ``model_std_dph`` the 1σ of the model line from its coefficients'
        covariance, and the model's variables as ``var_f``, ``var_df``, ...), or None
        when the pass kept none.
    notes
        Why a figure is missing (e.g. a run too short for the Allan deviation).
    ranges
        Shares of samples beyond the trained temperature and df/dt, and how far. The
        figures leave out the first ``warmup_s`` of the run (the df/dt filter settling),
        as training does.
    bias_stability_interval_dph
        ``{series: {tau_s: (lower, upper)}}``: chi-squared interval of each bias
        stability with (blocks − 1) degrees of freedom at ``confidence``. [°/h]
    confidence
        Two-sided level of the intervals (0.683: 1σ).
    deviation
        Which deviation ``allan`` holds (a key of :data:`DEVIATIONS`).
    accounting
        Samples read, left out of the figures (the settling time) and flagged
        (outside the calibrated temperature range), see :class:`hrgtc.core.Accounting`.
    directions
        Heating and cooling apart (:mod:`hrgtc.evaluation.heating_cooling`).
    mean_dph, rms_dph
        ``{series: value}``: mean and root mean square of each series over the samples
        the bias stabilities use. A bias stability is blind to a constant offset; these
        are not (a +136 °/h mean residual is not a 36 °/h bias stability). [°/h]
    n_not_at_rest
        Samples left out of the figures because they were not at rest.
    bias_stability_blocks
        ``{series: {tau_s: N}}``: the τ-blocks behind each bias stability (partial blocks
        at gaps included); its interval has N − 1 degrees of freedom.
    burst_allan
        ``{series: result}``: the Allan deviation beyond a segment from burst means
        (:mod:`hrgtc.evaluation.burst_allan`), for recordings of regular bursts only.
    """

    file: str
    n_samples: int
    sample_rate_hz: float
    bias_stability_dph: dict[str, dict[float, float]]
    allan: dict[str, AllanResult]
    noise: dict[str, NoiseTerms]
    out_of_range_fraction: float
    rate_out_of_range_fraction: float
    residual_rms_dph: float | None = None
    source: str = ""
    unit: str = ""
    input_rate_dph: float = 0.0
    block_s: float | None = None
    blocks: dict[str, np.ndarray] | None = None
    notes: tuple[str, ...] = field(default=())
    ranges: RangeReport | None = None
    bias_stability_interval_dph: dict[str, dict[float, tuple[float, float]]] = field(
        default_factory=dict)
    confidence: float = ONE_SIGMA
    deviation: str = EvaluationSettings.deviation
    directions: DirectionStats | None = None
    mean_dph: dict[str, float] = field(default_factory=dict)
    rms_dph: dict[str, float] = field(default_factory=dict)
    n_not_at_rest: int = 0
    accounting: Accounting | None = None
    bias_stability_blocks: dict[str, dict[float, int]] = field(default_factory=dict)
    burst_allan: dict[str, BurstAllanResult] = field(default_factory=dict)

    @property
    def name(self) -> str:
        """The run's file name."""
        return self.file

    @property
    def duration_s(self) -> float:
        """Length of the run. [s]"""
        return self.n_samples / self.sample_rate_hz

    def stability(self, series: str, tau_s: float) -> float | None:
        """Bias stability of one series at one τ, None where it is not available. [°/h]"""
        value = self.bias_stability_dph.get(series, {}).get(float(tau_s), math.nan)
        return None if math.isnan(value) else value

    def stability_interval(self, series: str, tau_s: float) -> tuple[float, float] | None:
        """Confidence interval of one bias stability, None where not available. [°/h]"""
        bounds = self.bias_stability_interval_dph.get(series, {}).get(float(tau_s))
        return None if bounds is None or math.isnan(bounds[0]) else bounds

    def stability_text(self, series: str, tau_s: float, digits: int = 4) -> str:
        """A bias stability with its interval and N, e.g. ``0.957 (0.93–0.99, N 360)``;
        ``-`` if none."""
        value = self.stability(series, tau_s)
        if value is None:
            return "-"
        count = self.bias_stability_blocks.get(series, {}).get(float(tau_s))
        n = "" if count is None else f"N {count}"
        bounds = self.stability_interval(series, tau_s)
        if bounds is None:
            return f"{value:.{digits}g}" + (f" ({n})" if n else "")
        return (f"{value:.{digits}g} ({bounds[0]:.{digits - 1}g}–{bounds[1]:.{digits - 1}g}"
                + (f", {n})" if n else ")"))

    @property
    def prediction_std_dph(self) -> dict[str, float] | None:
        """Median and maximum over the run of the model line's 1σ (blocks kept only). [°/h]"""
        if self.blocks is None or "model_std_dph" not in self.blocks:
            return None
        std = self.blocks["model_std_dph"]
        std = std[np.isfinite(std)]
        if std.size == 0:
            return None
        return {"median": float(np.median(std)), "max": float(np.max(std))}

    def offset_text(self, series: str = "compensated") -> str:
        """Mean and RMS of a series, e.g. ``mean +0.12, RMS 0.64 °/h``; ``-`` if unknown."""
        mean = self.mean_dph.get(series, math.nan)
        rms = self.rms_dph.get(series, math.nan)
        if math.isnan(mean):
            return "-"
        return f"mean {mean:+.4g}, RMS {rms:.4g} °/h"

    @property
    def raw_10s(self) -> float:
        """10 s bias stability of the raw output. [°/h]"""
        return self.bias_stability_dph["raw"][10.0]

    @property
    def compensated_10s(self) -> float:
        """10 s bias stability of the compensated output. [°/h]"""
        return self.bias_stability_dph["compensated"][10.0]

    @property
    def improvement_10s(self) -> float:
        """raw / compensated 10 s bias stability."""
        return self.raw_10s / self.compensated_10s

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (:class:`EvaluationRecord`, the layout of ``hrgtc evaluate
        --json``; τ keys as text, what is not finite as null)."""
        table: dict[str, Any] = {k: table_to_json(v) for k, v in self.bias_stability_dph.items()}
        table.setdefault("housing", None)
        return records.dump(
            self, EvaluationRecord, bias_stability_dph=table,
            bias_stability_10s_dph={"raw": self.raw_10s, "compensated": self.compensated_10s},
            allan=self.noise, allan_curve={k: _curve(a) for k, a in self.allan.items()},
            bias_stability_interval_dph={
                k: {f"{t:g}": None if math.isnan(b[0]) else b for t, b in row.items()}
                for k, row in self.bias_stability_interval_dph.items()},
            bias_stability_n={k: {f"{t:g}": c for t, c in row.items()}
                              for k, row in self.bias_stability_blocks.items()},
            allan_burst_means=self.burst_allan,
            ranges=None if self.ranges is None else self.ranges.to_dict(),
            heating_cooling=None if self.directions is None else self.directions.to_dict(),
            accounting=None if self.accounting is None else self.accounting.to_dict())

    def allan_csv(self) -> str:
        """The deviation curves as CSV text: series, tau_s, deviation, lower, upper, n, edf.

        ``lower`` / ``upper`` are empty where the curve has no interval (mdev, hdev, tdev);
        ``edf`` is the equivalent degrees of freedom of the interval (pooled over the
        segments of a recording with gaps, :func:`hrgtc.evaluation.allan_segments.pooled_edf`),
        empty where there is none.
        """
        lines = ["series,tau_s,deviation,lower,upper,n,edf"]
        for key, curve in self.allan.items():
            for k, tau in enumerate(curve.taus_s):
                bounds = ("", "") if curve.lower is None or curve.upper is None else (
                    repr(float(curve.lower[k])), repr(float(curve.upper[k])))
                edf = "" if curve.edf is None else repr(float(curve.edf[k]))
                lines.append(f"{key},{float(tau)!r},{float(curve.deviation[k])!r},"
                             f"{bounds[0]},{bounds[1]},{int(curve.counts[k])},{edf}")
        return "\n".join(lines) + "\n"

    def range_warnings(self) -> list[str]:
        """Lines on samples beyond the trained temperature and df/dt (empty if none)."""
        return [] if self.ranges is None else self.ranges.warnings()

    def figures(self, key: str = "evaluation", sensor: bool = False,
                warnings: bool = True) -> Summary:
        """The figures as a structured summary: value, unit, interval (:mod:`run_figures`).

        ``sensor``: the thermometer is a temperature sensor (the labels say so);
        ``warnings``: the range warnings among its notes.
        """
        return run_figures(self, key, sensor=sensor, warnings=warnings)

    def summary(self, sensor: bool = False, warnings: bool = True) -> Summary:
        """The figures (:meth:`figures`: value, unit, interval); ``.text()`` the plain
        text, ``print_summary`` the CLI's tables, ``.html()`` the report's."""
        return self.figures(sensor=sensor, warnings=warnings)


#: A share of the samples.
Fraction = Annotated[float, Meta(ge=0, le=1)]


class TenSecondRecord(Record):
    """The 10 s bias stability of the raw and the compensated output. [°/h]"""

    raw: Statistic
    compensated: Statistic


class PredictionStdRecord(Record):
    """Median and maximum over a run of the model line's 1σ. [°/h]"""

    median: NonNegative
    max: NonNegative


class EvaluationRecord(Record):
    """The record of :class:`Evaluation` (its ``to_dict``: ``hrgtc evaluate --json``).

    Its fields are the evaluation's figures under their JSON names: ``allan`` holds the
    noise terms (:class:`NoiseTerms`) and ``allan_curve`` the deviation curves; a table
    keyed by τ has τ as text (``"10"``); ``bias_stability_dph`` always has ``housing``
    (null without a housing baseline).
    """

    file: str
    n_samples: Count
    sample_rate_hz: Positive
    bias_stability_dph: dict[str, StabilityTable | None]
    bias_stability_10s_dph: TenSecondRecord
    improvement_10s: Statistic
    mean_dph: dict[str, Statistic]
    rms_dph: dict[str, Statistic]
    n_not_at_rest: Count
    allan: dict[str, NoiseTermsRecord]
    deviation: str
    allan_curve: dict[str, DeviationCurveRecord]
    confidence: Annotated[float, Meta(gt=0, lt=1)]
    bias_stability_interval_dph: dict[str, dict[str, tuple[Statistic, Statistic] | None]]
    bias_stability_n: dict[str, dict[str, Count]]
    allan_burst_means: dict[str, BurstAllanRecord]
    prediction_std_dph: PredictionStdRecord | None
    out_of_range_fraction: Fraction
    rate_out_of_range_fraction: Fraction
    residual_rms_dph: Statistic
    ranges: RangeReportRecord | None
    notes: list[str]
    heating_cooling: DirectionStatsRecord | None
    accounting: AccountingRecord | None


@cache
def evaluation_json_schema() -> dict[str, Any]:
    """JSON Schema (Draft 2020-12) of :meth:`Evaluation.to_dict` (``hrgtc evaluate --json``
    of a single-axis model), generated from :class:`EvaluationRecord`."""
    return records.json_schema(EvaluationRecord, "hrgtc evaluation",
                               "https://hrgtc.invalid/schema/evaluation.json")
