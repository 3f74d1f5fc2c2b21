"""The Allan noise terms of a gyro, read off its Allan deviation only where they show.

Angle random walk, bias instability and rate random walk are each the height of
one power law of the Allan deviation, IEEE Std 952-1997 Annex C [2]: σ ∝ τ^-½,
a flat minimum, σ ∝ τ^+½. :func:`noise_terms` reads a term only where the local
log-log slope of the curve is that law (within a tolerance); elsewhere the term
is None with the reason, e.g. a curve that rises as τ¹ after its minimum is a
thermal ramp, and reading a "rate random walk" off it would quote the ramp as
noise.

References
----------
[2] IEEE Std 952-1997, "IEEE Standard Specification Format Guide and Test
    Procedure for Single-Axis Interferometric Fiber Optic Gyros", Annex C
    (Allan variance method of fiber optic gyro data reduction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.records import Statistic
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.evaluation.allan import FLICKER_FLOOR_FACTOR, SECONDS_PER_HOUR, AllanResult

__all__ = ["RAMP_SLOPE", "NoiseTerms", "noise_terms"]

#: A rise after the minimum steeper than this (log-log slope, half-way between the
#: +½ of rate random walk and the +1 of a rate ramp) is read as a ramp.
RAMP_SLOPE = 0.75


@dataclass(frozen=True)
class NoiseTerms(records.Written):
    """Allan noise terms of a gyro, IEEE Std 952-1997 Annex C conventions [2].

    Attributes
    ----------
    arw_deg_per_rt_h
        Angle random walk N: the −½-slope line σ(τ) = N/√τ read at τ = 1 h, or None
        where the curve has no −½ region (``arw_reason`` says why). [°/√h]
    bias_instability_dph
        Bias instability B = σ_min / 0.664 at a flat minimum of the deviation, or None
        where the minimum is not flat (e.g. still falling at the longest usable τ). [°/h]
    rrw_dph_per_rt_h
        Rate random walk K: the +½-slope line σ(τ) = K·√(τ/3) read at τ = 3 h, or None
        where the curve does not rise as τ^+½ (``rrw_reason``). [°/h/√h]
    arw_taus_s, rrw_taus_s
        First and last τ of the points each line was fitted to, or None. [s]
    bias_instability_tau_s
        τ of the minimum of the usable curve. [s]
    floor_reached
        False if the minimum is the longest usable τ, i.e. the deviation was
        still falling there.
    minimum_dph
        The smallest usable deviation σ_min (an upper bound of 0.664·B). [°/h]
    arw_reason, bias_instability_reason, rrw_reason
        Why a term is None (None when it was read).
    arw_interval, bias_instability_interval, rrw_interval
        Confidence interval of each term read, where the deviation carries one: the
        bias instability's is the interval of σ_min over 0.664; a fitted line's is the
        fit's weighted mean of its points' log-interval half-widths (the points share
        their data, so treating them as fully correlated is the conservative choice).
    arw_n, bias_instability_n, rrw_n
        Terms behind each (the fewest among a line's points).
    """

    arw_deg_per_rt_h: float | None
    bias_instability_dph: float | None
    rrw_dph_per_rt_h: float | None
    arw_taus_s: tuple[float, float] | None
    bias_instability_tau_s: Statistic
    rrw_taus_s: tuple[float, float] | None
    floor_reached: bool
    minimum_dph: Statistic = math.nan
    arw_reason: str | None = None
    bias_instability_reason: str | None = None
    rrw_reason: str | None = None
    arw_interval: tuple[Statistic, Statistic] | None = None
    bias_instability_interval: tuple[Statistic, Statistic] | None = None
    rrw_interval: tuple[Statistic, Statistic] | None = None
    arw_n: int | None = None
    bias_instability_n: int | None = None
    rrw_n: int | None = None

    def text(self, term: str, digits: int = 4) -> str:
        """One term as text: the number, or the reason it is missing.

        ``term`` is ``"arw"``, ``"bias_instability"`` or ``"rrw"``.
        """
        value = {"arw": self.arw_deg_per_rt_h, "bias_instability": self.bias_instability_dph,
                 "rrw": self.rrw_dph_per_rt_h}[term]
        if value is None:
            return getattr(self, f"{term}_reason") or "n/a"
        bounds, n = getattr(self, f"{term}_interval"), getattr(self, f"{term}_n")
        if bounds is None:
            return f"{value:.{digits}g}"
        return (f"{value:.{digits}g} ({bounds[0]:.{digits - 1}g}–{bounds[1]:.{digits - 1}g}"
                f", N {n})")

    def summary(self) -> Summary:
        """The three noise terms, each with the τ range (or the minimum) it was read from,
        or why it is missing (its text: three lines)."""
        figures, lines = [], []
        for key, label, value, taus, unit, reason in (
                ("arw_deg_per_rt_h", "angle random walk", self.arw_deg_per_rt_h,
                 self.arw_taus_s, "deg/rt-h", self.arw_reason),
                ("rrw_dph_per_rt_h", "rate random walk", self.rrw_dph_per_rt_h,
                 self.rrw_taus_s, "deg/h/rt-h", self.rrw_reason)):
            if value is None or taus is None:
                lines.append(escape(f"n/a ({reason})"))
                continue
            figures += [Figure(key, label, value, unit, digits=4,
                               definition=f"The {label} read off the Allan deviation's slope "
                               f"over τ {taus[0]:g}-{taus[1]:g} s."),
                        Figure(key.split("_")[0] + "_taus_s", f"{label}: τ range",
                               taus[1] - taus[0], "s", (taus[0], taus[1]), "range")]
            lines.append(f"{{{key}:.4g}} {unit}  (fit over tau {taus[0]:g}-{taus[1]:g} s)")
        if self.bias_instability_dph is None:
            bias = escape(f"n/a ({self.bias_instability_reason})")
        else:
            figures += [Figure("bias_instability_dph", "bias instability",
                               self.bias_instability_dph, "deg/h", digits=4,
                               definition="The flat minimum of the Allan deviation over "
                               "0.664."),
                        Figure("bias_instability_tau_s", "bias instability: τ",
                               self.bias_instability_tau_s, "s")]
            bias = "{bias_instability_dph:.4g} deg/h  (minimum at tau {bias_instability_tau_s:g} s)"
        return Summary("noise terms", (("noise terms", tuple(figures)),), layout=(
            "angle random walk  " + lines[0], f"bias instability   {bias}",
            "rate random walk   " + lines[1]))


#: The record of :class:`NoiseTerms` (nested in other records).
NoiseTermsRecord = records.record_of(NoiseTerms)


def _law(slope: float) -> str:
    """A local log-log slope as a power of τ, e.g. ``τ^1.0``."""
    return f"τ^{slope:+.2g}".replace("+", "")


def noise_terms(
    allan: AllanResult,
    *,
    slope_tolerance: float = 0.15,
    min_blocks: int = 8,
    min_points: int = 2,
) -> NoiseTerms:
    """Angle random walk, bias instability and rate random walk, IEEE 952 Annex C [2].

    The Allan deviation of a rate in °/h against τ in s is read with the
    conventions of Annex C of [2], each term only where its law shows:

    - ARW: σ(τ) = N/√τ. A line of slope −½ is fitted (in log-log, weighted by
      the number of τ-blocks) to the points left of the minimum whose local
      slope is within ``slope_tolerance`` of −½, and read at τ = 1 h:
      ``ARW [°/√h] = σ(3600 s) = N[°/h·√s] / 60``.
    - Bias instability: ``B = σ_min / 0.664`` (0.664 ≈ √(2 ln 2 / π), flicker floor),
      only where the minimum is inside the usable τ and the local slope there is
      within the tolerance of 0.
    - RRW: σ(τ) = K·√(τ/3). A line of slope +½ is fitted to the points right of
      the minimum with local slope within the tolerance of +½ and read at
      τ = 3 h: ``K [°/h/√h] = σ(10800 s)``; not when the rising part after the
      minimum (points of local slope ≥ ½ − tolerance) has a fitted slope above
      :data:`RAMP_SLOPE` (a ramp, σ ∝ τ, dominates the long τ there).

    Only τ with at least ``min_blocks`` whole τ-blocks in the record are used
    (longer τ are too uncertain). A term is None with a reason when fewer than
    ``min_points`` points qualify, e.g. RRW on a record too short to show the
    +½ region.

    Parameters
    ----------
    allan
        Allan deviation of a rate in °/h, from :func:`~hrgtc.evaluation.allan.allan_deviation`.
    slope_tolerance
        Accepted distance of the local log-log slope from −½, 0 and +½.
    min_blocks
        Minimum number of non-overlapping τ-blocks for a τ to be used.
    min_points
        Minimum number of points for the ARW and RRW lines.

    Returns
    -------
    NoiseTerms
        The three terms (or why not) and the τ ranges they were read from.

    Raises
    ------
    InputError
        If fewer than 3 usable τ remain or the deviation is not positive.
    """
    c = _curve(allan, min_blocks)
    arw = _arw(c, slope_tolerance, min_points)
    bias = _bias(c, slope_tolerance)
    rrw = _rrw(c, slope_tolerance, min_points)
    return NoiseTerms(
        arw_deg_per_rt_h=arw.value,
        bias_instability_dph=bias.value,
        rrw_dph_per_rt_h=rrw.value,
        arw_taus_s=arw.taus,
        bias_instability_tau_s=float(c.taus[c.i_min]),
        rrw_taus_s=rrw.taus,
        floor_reached=c.floor,
        minimum_dph=float(c.dev[c.i_min]),
        arw_reason=arw.reason,
        bias_instability_reason=bias.reason,
        rrw_reason=rrw.reason,
        arw_interval=arw.interval, bias_instability_interval=bias.interval,
        rrw_interval=rrw.interval,
        arw_n=arw.n, bias_instability_n=bias.n, rrw_n=rrw.n,
    )


@dataclass(frozen=True)
class _Curve:
    """The usable part of an Allan deviation, as :func:`noise_terms` reads it.

    ``taus``, ``dev``, ``counts`` and ``weights`` (the τ-blocks) at the τ with enough
    blocks, their logs, the local log-log ``slope``, the index ``i_min`` of the minimum
    and whether it is inside the usable τ (``floor``); ``log_low`` and ``log_high`` the log
    half-widths of each point's interval (None without intervals).
    """

    taus: np.ndarray
    dev: np.ndarray
    counts: np.ndarray
    weights: np.ndarray
    log_tau: np.ndarray
    log_dev: np.ndarray
    slope: np.ndarray
    i_min: int
    floor: bool
    log_low: np.ndarray | None
    log_high: np.ndarray | None

    @property
    def index(self) -> np.ndarray:
        return np.arange(self.taus.size)


@dataclass(frozen=True)
class _Term:
    """One noise term: its value (None with a ``reason``), the τ range it was read from,
    its interval and the smallest number of terms behind it."""

    value: float | None = None
    taus: Any = None
    reason: str | None = None
    interval: tuple[Statistic, Statistic] | None = None
    n: int | None = None


def _curve(allan: AllanResult, min_blocks: int) -> _Curve:
    """The usable τ of ``allan`` (at least ``min_blocks`` blocks), refused when fewer than
    3 or not all positive."""
    usable = allan.blocks >= min_blocks
    taus = allan.taus_s[usable]
    dev = allan.deviation[usable]
    counts = allan.counts[usable]
    log_low = log_high = None
    if allan.lower is not None and allan.upper is not None:  # log half-widths of each interval
        log_low = np.log(allan.lower[usable] / dev)
        log_high = np.log(allan.upper[usable] / dev)
    if taus.size < 3:
        raise InputError(
            f"noise terms need at least 3 averaging times with >= {min_blocks} blocks each, "
            f"got {taus.size} (record of {allan.n_samples} samples); use a longer record "
            "or more taus"
        )
    if not np.all(dev > 0.0):
        raise InputError(
            "the Allan deviation has zero values (constant rate?); noise terms need a noisy record"
        )
    log_tau, log_dev = np.log(taus), np.log(dev)
    i_min = int(np.argmin(dev))
    return _Curve(taus, dev, counts, allan.blocks[usable].astype(np.float64), log_tau,
                  log_dev, np.gradient(log_dev, log_tau), i_min, i_min < taus.size - 1,
                  log_low, log_high)


def _arw(c: _Curve, tol: float, min_points: int) -> _Term:
    """ARW: the line of slope −½ left of the minimum, read at τ = 1 h. [°/√h]"""
    taus, slope, weights, i_min = c.taus, c.slope, c.weights, c.i_min
    pick = (c.index <= i_min) & (np.abs(slope + 0.5) <= tol)
    if pick.sum() >= min_points:
        log_n = np.average(c.log_dev[pick] + 0.5 * c.log_tau[pick], weights=weights[pick])
        # weighted least squares of ln σ = ln N − ½ ln τ; ARW = σ(1 h) = N/60
        arw = math.exp(log_n) / math.sqrt(SECONDS_PER_HOUR)
        arw_taus = (float(taus[pick][0]), float(taus[pick][-1]))
        if c.log_low is None or c.log_high is None:
            return _Term(arw, arw_taus)
        return _Term(arw, arw_taus, None, _line_interval(arw, c.log_low, c.log_high, weights,
                                                         pick), int(c.counts[pick].min()))
    if i_min == 0:
        return _Term(reason=f"no −½ slope: the curve does not fall from its first τ "
                            f"({taus[0]:g} s; it goes as {_law(slope[0])})")
    return _Term(reason=f"no −½ slope: {int(pick.sum())} point(s) left of the minimum within "
                        f"±{tol:g} of −½ (needs {min_points}); the curve goes as "
                        f"{_law(float(np.median(slope[: i_min + 1])))} there")


def _bias(c: _Curve, tol: float) -> _Term:
    """Bias instability: the flat minimum over 0.664. [°/h]"""
    taus, dev, slope, i_min = c.taus, c.dev, c.slope, c.i_min
    last = taus.size - 1
    if not c.floor:
        bound = dev[last] / FLICKER_FLOOR_FACTOR
        return _Term(reason=f"no flat minimum: the curve still falls as {_law(slope[last])} "
                            f"at the longest usable τ ({taus[last]:g} s); B < {bound:.4g} °/h")
    if i_min == 0:
        return _Term(reason=f"no flat minimum: the curve rises from its first τ ({taus[0]:g} s)")
    if abs(slope[i_min]) > tol:
        return _Term(reason=f"no flat minimum: the curve goes as {_law(slope[i_min])} at its "
                            "minimum")
    bias = float(dev[i_min]) / FLICKER_FLOOR_FACTOR
    if c.log_low is None or c.log_high is None:
        return _Term(bias)
    return _Term(bias, None, None, (bias * math.exp(float(c.log_low[i_min])),
                                    bias * math.exp(float(c.log_high[i_min]))),
                 int(c.counts[i_min]))


def _rrw(c: _Curve, tol: float, min_points: int) -> _Term:
    """RRW: the line of slope +½ right of the minimum, read at τ = 3 h, unless a ramp
    dominates there. [°/h/√h]"""
    taus, slope, weights, i_min = c.taus, c.slope, c.weights, c.i_min
    last = taus.size - 1
    pick = (c.index > i_min) & (np.abs(slope - 0.5) <= tol)
    rising = (c.index > i_min) & (slope >= 0.5 - tol)
    rise = (float(np.polyfit(c.log_tau[rising], c.log_dev[rising], 1)[0])
            if rising.sum() >= 2 else math.nan)
    if c.floor and rise > RAMP_SLOPE:
        return _Term(reason=f"no +½ slope: the curve rises as {_law(rise)} after its minimum "
                            f"(up to τ = {taus[last]:g} s) — a thermal ramp, not rate random "
                            "walk")
    if not c.floor:
        return _Term(reason=f"no +½ slope: the curve does not rise within the usable τ "
                            f"(up to {taus[last]:g} s)")
    if pick.sum() < min_points:
        return _Term(reason=f"no +½ slope: {int(pick.sum())} point(s) right of the minimum "
                            f"within ±{tol:g} of +½ (needs {min_points}); the curve goes as "
                            f"{_law(float(np.median(slope[i_min + 1:])))} there")
    # ln σ = ln(K_s/√3) + ½ ln τ, K in °/h/√s; σ at τ = 3 h equals K_s·60.
    log_k = np.average(c.log_dev[pick] - 0.5 * c.log_tau[pick], weights=weights[pick])
    rrw = math.exp(log_k) * math.sqrt(3.0 * SECONDS_PER_HOUR)
    rrw_taus = (float(taus[pick][0]), float(taus[pick][-1]))
    if c.log_low is None or c.log_high is None:
        return _Term(rrw, rrw_taus)
    return _Term(rrw, rrw_taus, None, _line_interval(rrw, c.log_low, c.log_high, weights,
                                                     pick), int(c.counts[pick].min()))


def _line_interval(value: float, log_low: np.ndarray, log_high: np.ndarray,
                   weights: np.ndarray, pick: np.ndarray) -> tuple[float, float]:
    """A fitted line's interval: its points' log half-widths averaged with the fit's weights
    (the points share their data: as if fully correlated, the conservative choice)."""
    low = float(np.average(log_low[pick], weights=weights[pick]))
    high = float(np.average(log_high[pick], weights=weights[pick]))
    return value * math.exp(low), value * math.exp(high)
