"""Allan deviation at τ longer than a burst, from burst means, with its dead-time bias named.

A duty-cycled logger (5 s bursts every 300 s) holds no τ-block longer than a burst, so
the pooled deviation (:mod:`hrgtc.evaluation.allan_segments`) ends at half a burst. The
means of the bursts, one every period T, each averaging τ_b seconds, are a frequency
series with dead time: r = T/τ_b > 1. Their overlapping Allan variance at τ = M·T (M
bursts averaged) is Barnes' σ²(2, M, T, τ_b) [6], and its expectation differs from
the Allan variance σ²_y(M·T) of the continuous record by a factor that depends on the
noise type (Barnes' bias functions B2 for M = 1 and B3 beyond, SP 1065 Section 5.15
[3]). :func:`dead_time_bias` computes that factor exactly for a power law of
σ²_y(τ) ∝ τ^μ from the phase structure function D(t) ∝ |t|^(μ+2) (t² ln|t| for
μ = 0): for any estimator Σ c_i x(t_i) that cancels a constant and a linear phase,
E[(Σ c_i x(t_i))²] = −½ Σ_ij c_i c_j D(t_i − t_j).

What :func:`burst_mean_allan` reports, at τ = M·T:

* ``raw_deviation``: the Allan deviation of the burst means, uncorrected;
* ``deviation``: that divided by √r, the correction exact for white rate noise
  (angle random walk, μ = −1), whose bias factor is r at every M: each burst mean
  averages only τ_b of every T;
* ``bias_flicker`` and ``bias_random_walk``: the ratio of the expected corrected
  deviation to the true σ_y(M·T) for flicker rate noise (bias instability, μ = 0) and
  random-walk rate noise (RRW, μ = 1). Both are below 1 (the correction overshoots
  them): a corrected curve is a lower bound of σ_y where those dominate, and the noise
  terms are never read off it.
* N (terms) and the chi-squared interval with the white-noise edf of the burst means
  (SP 1065 Table 5, as for a record of that many samples), exact for white rate noise.

The burst starts must keep one period: a burst shorter than half the median burst (cut
by the settling time, say) is left out, and a start-to-start step more than
:data:`PERIOD_TOLERANCE` off the median period (a missing burst, a pause) starts a new
run of bursts, and the deviation is pooled within those runs (no difference across a
missing burst). With fewer than three regular bursts the τ beyond a burst are not
estimable (an :class:`~hrgtc.core.errors.InputError` saying why).

[3] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008,
    Section 5.15 (dead time).
[6] J. A. Barnes, "Tables of bias functions, B1 and B2, for variances based on finite
    samples of processes with power law spectral densities", NBS Technical Note 375,
    1969; J. A. Barnes and D. W. Allan, "Variances based on data with dead time
    between the measurements", NIST Technical Note 1318, 1990.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.records import Count, Positive, Statistic
from hrgtc.evaluation._allan_edf import ONE_SIGMA
from hrgtc.evaluation.allan_segments import pooled_deviation

__all__ = ["PERIOD_TOLERANCE", "BurstAllanRecord", "BurstAllanResult", "burst_mean_allan",
           "dead_time_bias"]

#: A burst start more than this share of the period off the median period breaks the run.
PERIOD_TOLERANCE = 0.1
#: Power laws of σ²_y(τ) ∝ τ^μ named in the bias statement: μ by the noise it is.
NOISE_MU = {"white": -1, "flicker": 0, "random_walk": 1}


def _structure(t: np.ndarray, mu: int) -> np.ndarray:
    """Phase structure function D(t) of σ²_y ∝ τ^μ, up to a constant (sign included)."""
    a = np.abs(t)
    if mu == 0:  # flicker FM: t² ln|t| (the t² part cancels in every estimator)
        out = np.zeros_like(a)
        np.multiply(a * a, np.log(a, where=a > 0, out=np.zeros_like(a)), out=out, where=a > 0)
        return out
    return np.where(a > 0, a, 1.0) ** (mu + 2) * (a > 0)  # D(0) = 0 (also for μ = −2)


def dead_time_bias(averaged: int, ratio: float, mu: int) -> float:
    """E[Allan variance of burst means at τ = M·T] / σ²_y(M·T) for σ²_y(τ) ∝ τ^μ.

    Bursts of τ_b = T/r every T; M = ``averaged`` consecutive burst means averaged. For
    M = 1 this is Barnes' B2(r, μ)·r^(−μ) (B2 is relative to σ²_y(τ_b) [6]); white rate
    noise (μ = −1) gives r at every M.

    Parameters
    ----------
    averaged
        M, burst means averaged per τ (τ = M·T).
    ratio
        Dead-time ratio r = T/τ_b ≥ 1.
    mu
        Exponent μ of σ²_y(τ) ∝ τ^μ: −1 white, 0 flicker, 1 random-walk rate noise
        (−2 white or flicker phase noise).
    """
    m, r = int(averaged), float(ratio)
    if m < 1 or not r >= 1.0:
        raise InputError(f"dead_time_bias needs M >= 1 and r >= 1, got M={averaged}, r={ratio}")
    tau_b = 1.0 / r  # T = 1
    # the two groups of M bursts: weights w_k on (x(k + τ_b) − x(k)) / τ_b
    weights = np.r_[np.full(m, -1.0), np.full(m, 1.0)] / (m * tau_b)
    lags = np.arange(-(2 * m - 1), 2 * m, dtype=np.float64)
    pairs = np.correlate(weights, weights, mode="full")  # Σ_k w_k w_{k+L}
    # covariance of two burst increments L periods apart: ½[D(L+τ_b) + D(L−τ_b) − 2D(L)]
    h = 0.5 * (_structure(lags + tau_b, mu) + _structure(lags - tau_b, mu)
               - 2.0 * _structure(lags, mu))
    burst = float(np.dot(pairs, h))
    points = np.array([0.0, m, 2.0 * m])
    c = np.array([1.0, -2.0, 1.0]) / m  # (x(2MT) − 2x(MT) + x(0)) / (MT)
    true = -0.5 * float(c @ _structure(np.subtract.outer(points, points), mu) @ c)
    return burst / true


@dataclass(frozen=True, eq=False)
class BurstAllanResult(records.Written):
    """Allan deviation of burst means at τ = M·T (module docstring).

    Attributes
    ----------
    taus_s
        τ = M·T, M = 1, 2, 4, ... [s]
    deviation, lower, upper
        Corrected for white rate noise (raw / √r) and its chi-squared interval. [rate unit]
    raw_deviation
        Allan deviation of the burst means, uncorrected. [rate unit]
    counts, edf
        Terms (burst-mean differences) summed and the edf behind the interval.
    confidence
        Level of the interval.
    period_s, burst_s, dead_time_ratio
        T (median start-to-start step), τ_b (harmonic mean of the burst durations) and
        r = T/τ_b. [s, s, -]
    bursts, runs
        Burst means used and the runs of regular bursts they were pooled within.
    bias_flicker, bias_random_walk
        Expected corrected deviation over the true σ_y(τ) for flicker and random-walk
        rate noise at each τ (1 for white rate noise).
    """

    taus_s: records.Array[Positive]
    deviation: records.Array[Statistic]
    raw_deviation: records.Array[Statistic]
    lower: records.Array[Statistic]
    upper: records.Array[Statistic]
    counts: records.Array[Count]
    edf: records.Array[Statistic]
    confidence: Annotated[float, Meta(gt=0, lt=1)]
    period_s: Positive
    burst_s: Positive
    dead_time_ratio: Annotated[float, Meta(ge=1)]
    bursts: Count
    runs: Annotated[int, Meta(ge=1)]
    bias_flicker: records.Array[Statistic]
    bias_random_walk: records.Array[Statistic]

    def lines(self, unit: str = "°/h") -> list[str]:
        """One line per τ: value, interval, N and the bias statement."""
        head = (f"burst means ({self.bursts} bursts of {self.burst_s:.4g} s every "
                f"{self.period_s:.4g} s, dead-time ratio r = {self.dead_time_ratio:.4g}"
                + (f", pooled within {self.runs} runs" if self.runs > 1 else "")
                + "): Allan deviation corrected for white rate noise (÷√r, exact for angle "
                "random walk); the dead time biases it for other noise: it would read the true "
                "σ times the factor given for flicker (bias instability) and random-walk rate "
                "noise; the true σ lies between the corrected and the uncorrected value")
        out = [head]
        for k, tau in enumerate(self.taus_s):
            out.append(
                f"  τ = {tau:g} s: {self.deviation[k]:.4g} {unit} "
                f"({self.lower[k]:.3g}–{self.upper[k]:.3g}, {self.confidence:.3g}), "
                f"N = {int(self.counts[k])}, uncorrected {self.raw_deviation[k]:.4g}; "
                f"×{self.bias_flicker[k]:.3g} if flicker, ×{self.bias_random_walk[k]:.3g} "
                "if random walk")
        return out


#: The record of :class:`BurstAllanResult` (nested in other records).
BurstAllanRecord = records.record_of(BurstAllanResult, "BurstAllanRecord")


def burst_mean_allan(means: Any, durations_s: Any, starts_s: Any, *,
                     confidence: float = ONE_SIGMA,
                     tolerance: float = PERIOD_TOLERANCE) -> BurstAllanResult:
    """Overlapping Allan deviation of burst means at τ = M·T with its dead-time bias.

    Parameters
    ----------
    means
        Mean rate of each burst, in time order. [°/h] (any unit)
    durations_s
        Averaging time of each mean: samples × sample period. [s]
    starts_s
        Time of each burst's first sample. [s]
    confidence
        Level of the chi-squared interval.
    tolerance
        Accepted relative distance of a start-to-start step from the median period.

    Raises
    ------
    InputError
        τ beyond a burst is not estimable: fewer than three bursts in runs of a regular
        period, or bursts as long as the period (no dead time: not a burst record).
    """
    y = np.asarray(means, dtype=np.float64)
    durations = np.asarray(durations_s, dtype=np.float64)
    starts = np.asarray(starts_s, dtype=np.float64)
    if not (y.size == durations.size == starts.size):
        raise InputError("means, durations_s and starts_s must have one value per burst")
    if y.size < 3 or not np.all(np.isfinite(starts)):
        raise InputError(f"{y.size} bursts with known start times; burst means need at "
                         "least 3 at a regular period")
    full = durations >= 0.5 * float(np.median(durations))  # a burst cut short (settling):
    y, durations, starts = y[full], durations[full], starts[full]  # left out, breaks the run
    if y.size < 3:
        raise InputError(f"{y.size} bursts of at least half the median length; burst means "
                         "need at least 3 at a regular period")
    steps = np.diff(starts)
    period = float(np.median(steps))
    regular = np.abs(steps / period - 1.0) <= tolerance
    if np.count_nonzero(regular) < 2:
        raise InputError(f"the {y.size} segments do not start at a regular period (median "
                         f"{period:.4g} s, {np.count_nonzero(regular)} steps within "
                         f"±{tolerance:.0%}): burst means are not a series in time")
    burst = 1.0 / float(np.mean(1.0 / durations))
    if burst >= (1.0 - tolerance) * period:
        raise InputError(f"bursts of {burst:.4g} s every {period:.4g} s leave no dead time; "
                         "the pooled deviation covers these τ")
    ratio = period / burst
    breaks = (np.flatnonzero(~regular) + 1).tolist()
    curve = pooled_deviation(y, 1.0 / period, breaks, "octave", confidence=confidence)
    if curve.edf is None or curve.lower is None or curve.upper is None:  # confidence given
        raise InputError("no interval")
    m = np.rint(curve.taus_s / period).astype(np.int64)
    correction = 1.0 / math.sqrt(ratio)
    flicker = np.array([math.sqrt(dead_time_bias(int(k), ratio, 0) / ratio) for k in m])
    walk = np.array([math.sqrt(dead_time_bias(int(k), ratio, 1) / ratio) for k in m])
    return BurstAllanResult(
        taus_s=curve.taus_s, deviation=curve.deviation * correction,
        raw_deviation=curve.deviation, lower=curve.lower * correction,
        upper=curve.upper * correction, counts=curve.counts, edf=curve.edf,
        confidence=float(confidence), period_s=period, burst_s=burst, dead_time_ratio=ratio,
        bursts=int(y.size), runs=len(breaks) + 1, bias_flicker=flicker,
        bias_random_walk=walk)
