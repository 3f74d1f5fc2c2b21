"""Is a held-out gain beyond what the training residual's slow noise gives on its own?

On one monotonic ramp, the coldest and the hottest time blocks are also the first and the
last: a random walk in the bias (rate random walk, bias instability) moves their levels,
and a square or a df/dt term that follows the walk inside the run predicts them better
than the line, then runs away beyond the trained temperatures. The one-standard-error
rule of :func:`hrgtc.drift.cross_validation.prune_terms` cannot see this: within a block
the walk is one offset, not many independent errors.

Here the training windows give the slow noise: white window means of variance ``s²`` plus
a random walk of ``q`` per second ([2]: its variance grows linearly in time), estimated by
restricted maximum likelihood under the smaller model (:func:`slow_noise`; the null's
nuisance parameters estimated under the null, as a parametric bootstrap does). Under the
smaller model plus that noise the held-out residuals of both models are linear in the
noise alone (the smaller model's terms are in both), so the ratio of their held-out RMS
under the null is simulated exactly, on the same windows and folds. A term is kept only
if the observed ratio is rarer than :data:`SLOW_NOISE_LEVEL` under that null: curvature
must beat the slow noise.

[1] Docs: docs/real-loggers/motion.md (the guarded selection).
[2] IEEE Std 952-1997 Annex C (random walk: variance growing linearly in time).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

#: A richer model is kept when its held-out gain is rarer than this under the slow noise alone.
SLOW_NOISE_LEVEL = 0.05
#: Simulated noise records of the null (a fixed generator: the selection is reproducible).
NULL_DRAWS = 400
#: Most windows the noise estimate uses (an n³ eigendecomposition); longer runs are thinned.
MAX_WINDOWS = 600


@dataclass(frozen=True)
class SlowNoise:
    """White and random-walk parts of the window-mean residual.

    Attributes
    ----------
    white_dph
        Standard deviation of the white part of a window mean. [°/h]
    walk_dph2_per_s
        Variance the random walk adds per second. [(°/h)²/s]
    """

    white_dph: float
    walk_dph2_per_s: float

    def over(self, seconds: float) -> float:
        """Random-walk standard deviation over ``seconds``. [°/h]"""
        return math.sqrt(self.walk_dph2_per_s * max(seconds, 0.0))


def slow_noise(design: np.ndarray, bias_dph: np.ndarray, time_s: np.ndarray,
               max_windows: int = MAX_WINDOWS) -> SlowNoise:
    """White and random-walk parts of the noise of window means about a linear model.

    Restricted maximum likelihood (REML, Patterson and Thompson 1971) of
    ``y = design·β + e``, ``Cov(e) = s² I + q K``, ``K_ij = min(t_i, t_j)`` (a random walk
    from the first window): the likelihood of the residual contrasts, which the model's
    own terms cannot absorb, so a square that followed the walk does not hide it. One
    eigendecomposition, then a grid over ``q / s²`` (with ``s²`` profiled out). Longer
    runs are thinned to ``max_windows`` evenly spread windows.

    Parameters
    ----------
    design
        Regressors of the windows, the constant included, shape (windows, p).
    bias_dph
        Window means of the bias. [°/h]
    time_s
        Window centre times. [s]
    max_windows
        Most windows the estimate uses.
    """
    x = np.asarray(design, dtype=np.float64)
    y = np.asarray(bias_dph, dtype=np.float64)
    t = np.asarray(time_s, dtype=np.float64)
    rows = np.flatnonzero(np.isfinite(y) & np.isfinite(t) & np.all(np.isfinite(x), axis=1))
    if rows.size > max_windows:
        rows = rows[np.linspace(0, rows.size - 1, max_windows).round().astype(np.int64)]
    x, y, t = x[rows], y[rows], t[rows] - (float(np.min(t[rows])) if rows.size else 0.0)
    rank = np.linalg.matrix_rank(x) if x.size else 0
    free = y.size - rank
    if free < 3:
        residual = y - x @ np.linalg.lstsq(x, y, rcond=None)[0] if y.size else y
        return SlowNoise(float(np.sqrt(np.mean(residual ** 2))) if y.size else 0.0, 0.0)
    basis = np.linalg.qr(x, mode="complete")[0][:, rank:]  # the residual contrasts
    contrasts = basis.T @ y
    walk_cov = basis.T @ np.minimum.outer(t, t) @ basis
    eigen, vectors = np.linalg.eigh(0.5 * (walk_cov + walk_cov.T))
    eigen = np.clip(eigen, 0.0, None)
    energy = (vectors.T @ contrasts) ** 2
    span = float(np.ptp(t)) or 1.0
    ratios = np.r_[0.0, np.logspace(-6.0, 4.0, 201) / span]  # q / s² [1/s]

    def profile(ratio: float) -> tuple[float, float]:
        scale = 1.0 + ratio * eigen
        white = float(np.sum(energy / scale)) / free
        return -0.5 * (float(np.sum(np.log(scale))) + free * math.log(white)), white

    if not np.any(energy > 0.0):
        return SlowNoise(0.0, 0.0)
    values = [profile(r) for r in ratios]
    best = int(np.argmax([v[0] for v in values]))
    white = values[best][1]
    return SlowNoise(math.sqrt(white), float(ratios[best]) * white)


def _operators(x: np.ndarray, folds: np.ndarray, columns: Sequence[int]):
    """Per held-out fold: (test rows, train rows, the map of training noise to the fit's
    prediction on the test rows)."""
    design = np.column_stack([np.ones(x.shape[0]), x[:, list(columns)]])
    out = []
    for fold in np.unique(folds[folds >= 0]):
        test = folds == fold
        train = ~test
        if np.count_nonzero(train) <= design.shape[1] + 1:
            continue
        out.append((test, train, design[test] @ np.linalg.pinv(design[train])))
    return out


def _held_out_rms(operators, noise: np.ndarray) -> np.ndarray:
    """Held-out RMS (as :func:`~hrgtc.drift.cross_validation.held_out_rms`) of each column
    of ``noise``."""
    per_fold = [np.mean((noise[test] - prediction @ noise[train]) ** 2, axis=0)
                for test, train, prediction in operators]
    return np.sqrt(np.mean(per_fold, axis=0))


def null_ratios(x_scaled: np.ndarray, folds: np.ndarray, time_s: np.ndarray,
                columns_small: Sequence[int], columns_big: Sequence[int], noise: SlowNoise,
                draws: int = NULL_DRAWS, seed: int = 0) -> np.ndarray:
    """Held-out RMS of the bigger model over the smaller's when the truth is the smaller
    model plus ``noise``, ``draws`` times (windows in ``time_s`` order get the walk)."""
    small = _operators(x_scaled, folds, columns_small)
    big = _operators(x_scaled, folds, columns_big)
    if not small or len(small) != len(big):
        return np.empty(0)
    rng = np.random.default_rng(seed)
    t = np.asarray(time_s, dtype=np.float64)
    order = np.argsort(t, kind="stable")
    steps = np.sqrt(noise.walk_dph2_per_s * np.diff(t[order], prepend=t[order][0]))
    walk = np.empty((t.size, draws))
    walk[order] = np.cumsum(steps[:, None] * rng.standard_normal((t.size, draws)), axis=0)
    simulated = walk + noise.white_dph * rng.standard_normal((t.size, draws))
    below = _held_out_rms(small, simulated)
    with np.errstate(invalid="ignore", divide="ignore"):
        return _held_out_rms(big, simulated) / below


def beyond_slow_noise(x_scaled: np.ndarray, bias_dph: np.ndarray, folds: np.ndarray,
                      time_s: np.ndarray, columns_small: Sequence[int],
                      columns_big: Sequence[int], observed_ratio: float,
                      level: float = SLOW_NOISE_LEVEL) -> tuple[bool, float, SlowNoise]:
    """Does the bigger model's held-out gain beat the slow noise?

    The noise is estimated (:func:`slow_noise`) about the smaller model on all training
    windows; the chance of a held-out RMS ratio (bigger / smaller) at or below
    ``observed_ratio`` under the smaller model plus that noise is simulated
    (:func:`null_ratios`). Returns (chance below ``level``, the chance, the noise).
    """
    design = np.column_stack([np.ones(x_scaled.shape[0]), x_scaled[:, list(columns_small)]])
    noise = slow_noise(design, bias_dph, time_s)
    ratios = null_ratios(x_scaled, folds, time_s, columns_small, columns_big, noise)
    ratios = ratios[np.isfinite(ratios)]
    if not ratios.size or not math.isfinite(observed_ratio):
        return True, math.nan, noise
    chance = float(np.mean(ratios <= observed_ratio))
    return chance < level, chance, noise
