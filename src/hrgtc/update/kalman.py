"""The update's Kalman filter: the model's corrections and the runs' nuisance constants.

The state is ``x = (ΔB0?, Δk_f?, c_1, ..., c_R)``: the corrections of the offset (only with
a known input rate) and of the slope (only over a temperature span), then one nuisance
constant per recording (:mod:`hrgtc.update.observations`). Each still block is a scalar
measurement ``z = h·x + v``, ``h = (1, f, e_run)``, ``v ~ N(0, r)``, processed in time order
(the Joseph form of the covariance update).

Process noise, bounded: between two blocks Δt apart the model's corrections age as a
first-order process whose covariance relaxes towards a ceiling ``C`` (the prior's),

    P_mm ← φ² P_mm + (1 - φ²) C,   P_mc ← φ P_mc,   φ = exp(-Δt / τ),

so that P never exceeds its prior (a convex combination of two matrices ≤ C): 72 h at
constant temperature leave the covariance bounded, and the directions no block excites
stay at their prior. The estimate itself is held (the filter does not forget an ageing it
has seen); the nuisance constants do not age. ``τ = 0`` switches the process noise off:
the filter is then the batch weighted least squares with the same prior, exactly
(``tests/update/test_kalman.py`` compares them).

Random walk of the bias (:class:`Walk`): a gyro's bias wanders within a recording (its rate
random walk), so the blocks of one run are not independent: a day's still means share the
wander since the run began. Each run then has a second nuisance, a random walk that starts
at 0 at the run's first still block and whose variance grows by ``q`` per hour between the
run's blocks. Without it the filter takes the wander between the temperatures of a field
day for a change of slope, and is sure of it; with it, the slope is read from the steps
between neighbouring blocks, where the wander is small. ``q`` is chosen by the likelihood
of the filter's innovations (:func:`walk_rate`, ``docs/guide/update.md``). The filter is
still the batch generalised least squares with the walk's covariance ``q·min(t_i, t_j)``
(tested to 1e-9).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

__all__ = ["FilterRun", "Walk", "heldout_rms", "jump_statistic", "run_filter", "walk_rate"]

#: Rates of the random walk tried by :func:`walk_rate`: 0 and 10⁻⁴ … 1 (°/h)²/h, i.e. a
#: rate random walk of 0.01 … 1 °/h/√h.
WALK_RATES_PER_H = (0.0, *np.logspace(-4.0, 0.0, 17))


class Walk(NamedTuple):
    """The runs' random walks: ``state[k]``, the index in the state of block ``k``'s walk;
    ``start_h[j]``, the time walk state ``j`` starts from 0 [h]; ``q_per_h``, the variance
    it gains per hour [(°/h)²/h]."""

    state: np.ndarray
    start_h: np.ndarray
    q_per_h: float

    def subset(self, which: object) -> Walk:
        """The walk of the blocks ``which`` (an index or a slice of the blocks)."""
        return Walk(self.state[which], self.start_h, self.q_per_h)


@dataclass(frozen=True)
class FilterRun:
    """What :func:`run_filter` gives.

    Attributes
    ----------
    mean, covariance
        The posterior of the whole state (model corrections first, then the nuisances).
    traces
        Trace of the model corrections' covariance after each block (the process noise
        and the measurement included).
    log_likelihood
        Log-likelihood of the blocks under the filter's model (of its innovations).
    """

    mean: np.ndarray
    covariance: np.ndarray
    traces: np.ndarray
    log_likelihood: float = 0.0


def run_filter(mean: np.ndarray, covariance: np.ndarray, rows: np.ndarray, z: np.ndarray,
               r: np.ndarray, times_h: np.ndarray, n_model: int, tau_h: float,
               walk: Walk | None = None) -> FilterRun:
    """Filter the measurements ``z = rows · x + v`` (``v`` of variances ``r``) in order.

    Parameters
    ----------
    mean, covariance
        Prior of the state (``n_model`` model corrections, then the nuisances); the
        model block of ``covariance`` is also the process noise's ceiling.
    rows
        One measurement row per block, ``(n_blocks, n_state)``.
    z, r
        The blocks' residual means and their variances. [°/h, (°/h)²]
    times_h
        The blocks' times: the process noise acts over the time between two. [h]
    n_model
        How many leading states are model corrections (the others are nuisances).
    tau_h
        Time constant of the process noise (0: none). [h]
    walk
        The runs' random walks (none: the nuisances are constants).
    """
    x = np.array(mean, dtype=np.float64)
    p = np.array(covariance, dtype=np.float64)
    ceiling = p[:n_model, :n_model].copy()
    traces = np.empty(len(z))
    identity = np.eye(x.size)
    last = times_h[0] if len(times_h) else 0.0
    walked = None if walk is None or not walk.q_per_h > 0.0 else np.array(walk.start_h)
    log_likelihood = 0.0
    for k, (h, value, variance, time) in enumerate(zip(rows, z, r, times_h, strict=True)):
        if walked is not None:
            j = walk.state[k]
            p[j, j] += walk.q_per_h * max(time - walked[j], 0.0)
            walked[j] = max(time, walked[j])
        if tau_h > 0.0 and n_model:
            phi = math.exp(-max(time - last, 0.0) / tau_h)
            p[:n_model, :n_model] = phi * phi * p[:n_model, :n_model] + (1.0 - phi * phi) * ceiling
            p[:n_model, n_model:] *= phi
            p[n_model:, :n_model] *= phi
        last = time
        s = float(h @ p @ h) + float(variance)
        gain = p @ h / s
        innovation = float(value) - float(h @ x)
        log_likelihood -= 0.5 * (math.log(2.0 * math.pi * s) + innovation * innovation / s)
        x = x + gain * innovation
        a = identity - np.outer(gain, h)
        p = a @ p @ a.T + float(variance) * np.outer(gain, gain)
        p = 0.5 * (p + p.T)
        traces[k] = float(np.trace(p[:n_model, :n_model]))
    return FilterRun(x, p, traces, log_likelihood)


def walk_rate(solve: Callable[[float], FilterRun]) -> float:
    """The walk rate ``q`` of :data:`WALK_RATES_PER_H` under which the blocks are most
    likely (``solve(q)``: the filter run with that rate). [(°/h)²/h]"""
    return max(WALK_RATES_PER_H, key=lambda q: solve(float(q)).log_likelihood)


def jump_statistic(residuals: np.ndarray, stretches: np.ndarray, sigma: float,
                   side: int = 3) -> tuple[float, int]:
    """The largest step of the residuals within a stretch of consecutive still blocks, in
    standard errors, and the index of the first block after it (-1: no step tested).

    At each split of a stretch's blocks (time order) the difference of the means of the
    ``side`` blocks after and the ``side`` blocks before, over its standard error
    ``σ √(2 / side)``: local, so that the slow wander of a gyro's bias (its flicker) is not
    taken for a step while a step stands out of it.
    """
    best, where = 0.0, -1
    if not sigma > 0.0:
        return best, where
    error = sigma * math.sqrt(2.0 / side)
    for stretch in np.unique(stretches):
        index = np.flatnonzero(stretches == stretch)
        values = residuals[index]
        for m in range(side, values.size - side + 1):
            t = abs(values[m:m + side].mean() - values[m - side:m].mean()) / error
            if t > best:
                best, where = float(t), int(index[m])
    return best, where


def heldout_rms(residuals: np.ndarray, runs: np.ndarray, centred: bool) -> float:
    """Rms of held-out residuals; ``centred``: each run's mean removed first (the constant
    no still data can tell when the input rate is unknown). [°/h]"""
    values = np.array(residuals, dtype=np.float64)
    if centred:
        for run in np.unique(runs):
            values[runs == run] -= values[runs == run].mean()
    return float(np.sqrt(np.mean(values ** 2))) if values.size else math.nan


def bootstrap_rms(residuals: np.ndarray, runs: np.ndarray, centred: bool,
                  resamples: int = 1000, level: float = 0.95,
                  seed: int = 0) -> tuple[float, float]:
    """Percentile bootstrap interval of :func:`heldout_rms` over the held-out blocks. [°/h]"""
    rng = np.random.default_rng(seed)
    n = residuals.size
    values = [heldout_rms(residuals[i], runs[i], centred)
              for i in (rng.integers(0, n, n) for _ in range(resamples))]
    tail = 50.0 * (1.0 - level)
    low, high = np.percentile(values, [tail, 100.0 - tail])
    return float(low), float(high)


def split_heldout(count: int, every: int) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the fitted and the held-out blocks: every ``every``-th block (from the
    ``every``-th) is held out, so both sets cover the recording's temperatures."""
    index = np.arange(count)
    held = index % every == every - 1
    return index[~held], index[held]


def mahalanobis(step: Sequence[float], covariance: np.ndarray) -> float:
    """Length of ``step`` in the metric of ``covariance`` (√(δᵀ C⁻¹ δ))."""
    delta = np.asarray(step, dtype=np.float64)
    if not delta.size:
        return 0.0
    return float(math.sqrt(max(float(delta @ np.linalg.solve(covariance, delta)), 0.0)))
