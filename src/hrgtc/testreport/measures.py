"""The measurements behind the figures: turn-ons, temperature sensitivities, scale factor, noise.

Each function takes the runs' :class:`~hrgtc.testreport.series.RunSeries` of one role
and gives :class:`~hrgtc.testreport.figures.TestFigure` s (and the rows of the report's
tables); the definitions are those of :data:`hrgtc.testreport.figures.FIGURES`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.drift.scale_factor import fit_group
from hrgtc.evaluation.allan import AllanResult, allan_deviation
from hrgtc.evaluation.noise import noise_terms
from hrgtc.testreport.figures import TestFigure, measured, not_measured
from hrgtc.testreport.manifest import CampaignSettings
from hrgtc.testreport.series import RunSeries

__all__ = ["Plateau", "SoakPoint", "TurnOn", "coverage_probability", "line_fit",
           "noise_figures", "scale_factor_figures", "temperature_figures", "turn_on_figures",
           "turn_ons"]

#: Fewest samples at rest the Allan deviation is computed on (a shorter stretch gives no
#: noise figure, and says why).
MIN_ALLAN_SAMPLES = 100


def coverage_probability(k: float) -> float:
    """The two-sided probability of ±k σ of a normal distribution (k = 2: 0.9545)."""
    return math.erf(k / math.sqrt(2.0))


@dataclass(frozen=True)
class TurnOn:
    """One turn-on: its settled bias (raw, compensated), turn-on time and warm-up drift (NaN
    without a warm-up period)."""

    name: str
    day: str
    bias_dph: float
    bias_se_dph: float
    compensated_dph: float | None
    turn_on_time_s: float | None
    warm_up_drift_dph: float
    block_sigma_dph: float
    blocks: int


def _turn_on_time(series: RunSeries, settled: float, tolerance: float | None,
                  block_s: float) -> float | None:
    if tolerance is None:
        return None
    outside = np.flatnonzero(np.abs(series.bias_dph - settled) > tolerance)
    if outside.size == 0:
        return 0.0
    return float(series.time_s[outside[-1]] + block_s)


def turn_ons(runs: Sequence[RunSeries], settings: CampaignSettings) -> list[TurnOn]:
    """Each turn-on's settled bias (mean of its block means after ``settle_s``), turn-on
    time and warm-up drift."""
    out = []
    for series in runs:
        settle = series.settle_s(settings.settle_s)
        tail = series.after(settle)
        if tail.size < 2:
            raise InputError(f"{series.entry.path}: fewer than two {settings.block_s:g} s blocks "
                             f"after settle_s = {settle:g} s; the turn-on is too short for its "
                             "bias, or lower settle_s")
        settled = float(np.mean(tail))
        sigma = float(np.std(tail, ddof=1))
        warm = series.bias_dph[series.time_s < settle]
        comp = (None if series.compensated_dph is None
                else float(np.mean(series.after(settle, compensated=True))))
        out.append(TurnOn(
            series.entry.name, series.entry.day, settled, sigma / math.sqrt(tail.size), comp,
            _turn_on_time(series, settled, settings.turn_on_tolerance_dph, settings.block_s),
            float(np.max(np.abs(warm - settled))) if warm.size else math.nan, sigma,
            int(tail.size)))
    return out


def turn_on_figures(found: Sequence[TurnOn], settings: CampaignSettings,
                    compensated: bool) -> list[TestFigure]:
    """Turn-on time, warm-up drift, bias and bias repeatability (and after compensation)."""
    k = settings.coverage_k
    names = ["turn_on_time_s", "warm_up_drift_dph", "bias_dph", "bias_repeatability_dph"]
    if compensated:
        names.append("bias_repeatability_compensated_dph")
    if not found:
        return [not_measured(n, "no turn-on runs in the manifest", k) for n in names]
    out = []
    if settings.turn_on_tolerance_dph is None:
        out.append(not_measured("turn_on_time_s", "no turn_on_tolerance_dph in [settings]", k))
    else:
        worst = max(t.turn_on_time_s for t in found if t.turn_on_time_s is not None)
        out.append(measured("turn_on_time_s", worst, settings.block_s / math.sqrt(12.0), k,
                            basis=f"U = k·u, k = {k:g}; u: block_s/√12"))
    warming = [t for t in found if math.isfinite(t.warm_up_drift_dph)]
    if warming:
        worst = max(warming, key=lambda t: t.warm_up_drift_dph)
        out.append(measured("warm_up_drift_dph", worst.warm_up_drift_dph,
                            worst.block_sigma_dph, k))
    else:
        out.append(not_measured("warm_up_drift_dph", "settle_s = 0: no warm-up period", k))
    biases = np.array([t.bias_dph for t in found])
    n = biases.size
    if n < 2:
        out.append(measured("bias_dph", float(biases[0]), found[0].bias_se_dph, k,
                            basis=f"U = k·u, k = {k:g}; u: σ/√N of the one turn-on's block "
                            "means (optimistic where the noise is correlated)"))
        reason = "one turn-on; the repeatability needs two or more"
        out.extend(not_measured(name, reason, k) for name in names[3:])
        return out
    sigma = float(np.std(biases, ddof=1))
    out.append(measured("bias_dph", float(np.mean(biases)), sigma / math.sqrt(n), k, n - 1))
    out.append(measured("bias_repeatability_dph", sigma, sigma / math.sqrt(2.0 * (n - 1)), k,
                        n - 1))
    if compensated:
        comp = np.array([t.compensated_dph for t in found], dtype=np.float64)
        spread = float(np.std(comp, ddof=1))
        out.append(measured("bias_repeatability_compensated_dph", spread,
                            spread / math.sqrt(2.0 * (n - 1)), k, n - 1))
    return out


def line_fit(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Least squares ``y = X b`` with X's columns ``x`` (2-D, a column of ones first): the
    coefficients, their standard errors, the residuals and the degrees of freedom."""
    coefficients, *_ = np.linalg.lstsq(x, y, rcond=None)
    residuals = y - x @ coefficients
    dof = x.shape[0] - x.shape[1]
    if dof < 1:
        return coefficients, np.full(x.shape[1], math.nan), residuals, dof
    variance = float(residuals @ residuals) / dof
    covariance = variance * np.linalg.inv(x.T @ x)
    return coefficients, np.sqrt(np.diag(covariance)), residuals, dof


def _lag1_widening(residuals: np.ndarray) -> float:
    """√((1 + ρ)/(1 − ρ)) of the residuals' lag-1 autocorrelation ρ (≥ 0; 1 if ρ ≤ 0): the
    factor by which correlated block means widen a slope's standard error."""
    r = residuals - residuals.mean()
    denominator = float(r @ r)
    rho = float(r[1:] @ r[:-1]) / denominator if denominator > 0 else 0.0
    rho = min(max(rho, 0.0), 0.98)
    return math.sqrt((1.0 + rho) / (1.0 - rho))


@dataclass(frozen=True)
class SoakPoint:
    """A soak's settled temperature and bias (raw, compensated)."""

    name: str
    temperature_c: float
    bias_dph: float
    compensated_dph: float | None


def _sensitivities(soaks: Sequence[RunSeries], sweeps: Sequence[RunSeries],
                   settings: CampaignSettings, compensated: bool, suffix: str
                   ) -> tuple[list[TestFigure], list[SoakPoint]]:
    k = settings.coverage_k
    temperature_name = f"bias_temperature_sensitivity{suffix}_dph_per_c"
    gradient_name = f"bias_gradient_sensitivity{suffix}_dph_per_c_per_min"
    points = []
    for s in soaks:
        settle = s.settle_s(settings.settle_s)
        if not np.any(s.time_s >= settle):
            raise InputError(f"{s.entry.path}: nothing left after settle_s = {settle:g} s; "
                             "the soak is too short, or lower its settle_s")
        points.append(SoakPoint(
            s.entry.name, float(np.mean(s.temperature_c[s.time_s >= settle])),
            float(np.mean(s.after(settle))), None if s.compensated_dph is None
            else float(np.mean(s.after(settle, compensated=True)))))
    out, slope = [], None
    if len(points) >= 3:
        t = np.array([p.temperature_c for p in points])
        y = np.array([p.compensated_dph if compensated else p.bias_dph for p in points])
        b, se, _, dof = line_fit(np.column_stack([np.ones_like(t), t]), y)
        slope = float(b[1])
        out.append(measured(temperature_name, slope, float(se[1]), k, dof,
                            f"U = k·u, k = {k:g}; u: OLS standard error over {len(points)} soaks"))
    blocks = [(s.temperature_c, np.gradient(s.temperature_c, s.sample_times_s() / 60.0),
               s.compensated_dph if compensated else s.bias_dph)
              for s in sweeps if s.time_s.size >= 4]
    if blocks:
        temperature = np.concatenate([b[0] for b in blocks])
        gradient = np.concatenate([b[1] for b in blocks])
        y = np.concatenate([b[2] for b in blocks])
        columns = [np.ones_like(y), gradient] if slope is not None else \
            [np.ones_like(y), temperature, gradient]
        target = y - slope * temperature if slope is not None else y
        b, se, residuals, dof = line_fit(np.column_stack(columns), target)
        widen = _lag1_widening(residuals)
        basis = f"U = k·u, k = {k:g}; u: OLS standard error × {widen:.3g} (lag-1 correlation)"
        if slope is None:
            out.append(measured(temperature_name, float(b[1]), float(se[1]) * widen, k, dof,
                                basis))
        out.append(measured(gradient_name, float(b[-1]), float(se[-1]) * widen, k, dof, basis))
    names = {f.name for f in out}
    if temperature_name not in names:
        out.append(not_measured(temperature_name, "needs soaks at three temperatures or more, "
                                "or a sweep", k))
    if gradient_name not in names:
        out.append(not_measured(gradient_name, "needs a sweep (a run of role sweep)", k))
    return out, points


def temperature_figures(soaks: Sequence[RunSeries], sweeps: Sequence[RunSeries],
                        settings: CampaignSettings, compensated: bool
                        ) -> tuple[list[TestFigure], list[SoakPoint]]:
    """Bias temperature and temperature-gradient sensitivity, raw and (with a model)
    compensated, and the soaks' settled points."""
    figures, points = _sensitivities(soaks, sweeps, settings, False, "")
    if compensated:
        figures += _sensitivities(soaks, sweeps, settings, True, "_compensated")[0]
    return figures, points


@dataclass(frozen=True)
class Plateau:
    """One temperature plateau of a rate table: its temperature and scale-factor error."""

    temperature_c: float
    k_ppm: float
    k_se_ppm: float
    holds: int


def scale_factor_figures(tables: Sequence[RunSeries], settings: CampaignSettings
                         ) -> tuple[list[TestFigure], list[Plateau]]:
    """Scale-factor error at ``reference_c`` and its temperature sensitivity from the holds,
    grouped by temperature (a hold whose temperature spans more than 2 ``plateau_tolerance_c``
    is left out; a plateau is the holds within 2 ``plateau_tolerance_c`` of its coldest);
    "not measured" without a rate table."""
    k = settings.coverage_k
    names = ("scale_factor_error_ppm", "scale_factor_temperature_sensitivity_ppm_per_c")
    if not tables:
        return [not_measured(n, "no rate-table run in the manifest", k) for n in names], []
    tolerance = settings.plateau_tolerance_c
    holds = sorted(((t, s) for series in tables
                    for s, t, span in zip(series.segments, series.segment_temperature_c,
                                          series.segment_span_c, strict=True)
                    if span <= 2.0 * tolerance), key=lambda pair: pair[0])
    if not holds:
        return [not_measured(n, f"no rate-table hold at one temperature (within ± {tolerance:g} "
                             "°C): let the plateaus settle", k) for n in names], []
    groups: list[list[tuple[float, Any]]] = []
    for pair in holds:
        if groups and pair[0] - groups[-1][0][0] <= 2.0 * tolerance:
            groups[-1].append(pair)
        else:
            groups.append([pair])
    plateaus = []
    for number, group in enumerate(groups):
        fitted = fit_group([s for _, s in group], number)
        plateaus.append(Plateau(float(np.mean([t for t, _ in group])), fitted.k_ppm,
                                fitted.k_se_ppm, fitted.n))
    nearest = min(plateaus, key=lambda p: abs(p.temperature_c - settings.reference_c))
    out = [measured(names[0], nearest.k_ppm, nearest.k_se_ppm, k, nearest.holds - 2)]
    if len(plateaus) < 2:
        out.append(not_measured(names[1], "rate-table holds at one temperature only", k))
        return out, plateaus
    t = np.array([p.temperature_c for p in plateaus])
    y = np.array([p.k_ppm for p in plateaus])
    b, se, _, dof = line_fit(np.column_stack([np.ones_like(t), t]), y)
    u = float(se[1])
    if len(plateaus) == 2:
        u = math.hypot(plateaus[0].k_se_ppm, plateaus[1].k_se_ppm) / abs(t[1] - t[0])
    out.append(measured(names[1], float(b[1]), u, k, dof if dof > 0 else None))
    return out, plateaus


def noise_figures(series: RunSeries | None, settings: CampaignSettings
                  ) -> tuple[list[TestFigure], dict[str, AllanResult]]:
    """ARW, bias instability and RRW from the overlapping Allan deviation of one run after
    ``settle_s`` (χ² intervals at k's coverage), raw, and the bias instability compensated."""
    k = settings.coverage_k
    names = ("angle_random_walk_deg_per_rt_h", "bias_instability_dph",
             "rate_random_walk_dph_per_rt_h", "bias_instability_compensated_dph")
    if series is None or series.samples_dph is None:
        return [not_measured(n, "no turn-on or soak run for the Allan deviation", k)
                for n in names], {}
    fs = series.sample_rate_hz
    settled = round(series.settle_s(settings.settle_s) * fs)
    start, stop = series.still_stretch(settled)
    if stop - start < MIN_ALLAN_SAMPLES:
        return [not_measured(n, f"no stretch at rest of {MIN_ALLAN_SAMPLES} samples after the "
                             f"settling in {series.entry.name} (the motion detector's verdict; "
                             "--motion keep uses every sample)", k) for n in names], {}
    probability = coverage_probability(k)
    curves = {"raw": allan_deviation(series.samples_dph[start:stop], fs,
                                      confidence=probability)}
    if series.compensated_samples_dph is not None:
        curves["compensated"] = allan_deviation(series.compensated_samples_dph[start:stop], fs,
                                                confidence=probability)
    out = []
    basis = f"χ² interval at {probability:.4g} (k = {k:g})"
    if stop - start < series.samples_dph.size - settled:
        basis += (f"; the longest stretch at rest after the settling, {(stop - start) / fs:g} s "
                  f"of {(series.samples_dph.size - settled) / fs:g} s")
    for key, terms in (("raw", ("arw", "bias_instability", "rrw")),
                       ("compensated", ("bias_instability",))):
        if key not in curves:
            out.append(not_measured(names[3], "no model in the manifest", k))
            continue
        found = noise_terms(curves[key])
        for term in terms:
            name = {"arw": names[0], "rrw": names[2],
                    "bias_instability": names[1] if key == "raw" else names[3]}[term]
            value = getattr(found, {"arw": "arw_deg_per_rt_h", "rrw": "rrw_dph_per_rt_h",
                                    "bias_instability": "bias_instability_dph"}[term])
            interval = getattr(found, f"{term}_interval")
            if value is None:
                out.append(not_measured(name, getattr(found, f"{term}_reason") or "n/a", k))
            elif interval is None:
                out.append(TestFigure(name, float(value), k=k, basis="no interval"))
            else:
                out.append(TestFigure(name, float(value), None,
                                      (float(value - interval[0]), float(interval[1] - value)),
                                      k, None, basis))
    return out, curves
