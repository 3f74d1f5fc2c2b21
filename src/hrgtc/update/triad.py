"""The offsets of a triad from the magnitude of the Earth rate (issue 29, item 4).

A still period of a three-axis instrument whose axes are orthogonal measures, per axis, the
residual (rate - the model's bias) ``m = Δb + Ω`` with ``Δb`` the offsets' change (and the
recording's turn-on shift) and ``Ω`` the Earth rate in the body frame: its direction
depends on the orientation and is not known, its magnitude is, ``|Ω| = Ω_E`` = 15.041 °/h.
Still periods in several orientations put the ``m_k`` on a sphere of radius ``Ω_E``
centred on ``Δb``, which fixes ``Δb``:

    minimise  Σ_k ((|m_k - Δb| - Ω_E) / σ_k)²  +  Δbᵀ P⁻¹ Δb

by nonlinear least squares (:func:`scipy.optimize.least_squares`), ``P`` the prior (the
calibration's intercept covariance plus the ageing allowance and the turn-on shift);
the posterior covariance is the inverse Gauss-Newton Hessian at the solution. The data's
information about ``Δb`` is ``Σ_k u_k u_kᵀ / σ_k²`` with ``u_k`` the unit vector of the
Earth rate in orientation ``k``: one orientation, or several about one direction, leave
a direction unexcited. The offsets are updated only when the still periods hold at least
``triad_min_orientations`` distinct orientations (the directions ``u_k`` at least
:data:`ORIENTATION_ANGLE_DEG` apart) and that information's condition number is at most
``triad_max_condition``; otherwise nothing is changed and the note says why. The mirror
solution (three points on a sphere also fit the centre reflected through their plane) is
an Earth-rate diameter away from the prior and is never reached from it.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import UpdateRefusedError
from hrgtc.settings.update import EARTH_RATE_DPH, UpdateSettings
from hrgtc.update.kalman import mahalanobis, split_heldout
from hrgtc.update.observations import StillBlock, block_noise_dph

__all__ = ["EARTH_RATE_DPH", "ORIENTATION_ANGLE_DEG", "TRIAD_CHANGE", "TriadUpdate",
           "orientation_groups", "triad_axes", "triad_offsets"]

#: Two still periods whose Earth-rate directions are closer are one orientation. [°]
ORIENTATION_ANGLE_DEG = 20.0
#: The ``axis`` of the lineage's change that holds the triad's offsets.
TRIAD_CHANGE = "triad"


@dataclass(frozen=True)
class TriadUpdate:
    """The offsets of a triad updated from ``|Ω|``.

    Attributes
    ----------
    axes
        The three axes, in the order of the vectors below.
    before, after
        The intercepts B0 before and after. [°/h]
    covariance_before, covariance_after
        The prior (calibration, ageing allowance, turn-on shift) and the posterior.
    rate_norm_dph
        The magnitude of the input rate used (the Earth rate). [°/h]
    n_periods, n_orientations
        Still periods used and the distinct orientations among them.
    condition
        Condition number of the still periods' information about the offsets.
    mahalanobis
        Length of the step in the prior's metric.
    heldout_before_dph, heldout_after_dph
        Rms of ``|m| - Ω_E`` over the held-out still blocks with the parent's offsets and
        with the updated ones. [°/h]
    n_heldout
        Held-out blocks.
    """

    axes: tuple[str, ...]
    before: tuple[float, ...]
    after: tuple[float, ...]
    covariance_before: np.ndarray
    covariance_after: np.ndarray
    rate_norm_dph: float
    n_periods: int
    n_orientations: int
    condition: float
    mahalanobis: float
    heldout_before_dph: float
    heldout_after_dph: float
    n_heldout: int


def triad_axes(model: Any, settings: UpdateSettings) -> tuple[str, ...] | None:
    """The three axes of a model whose offsets come from ``|Ω|`` (None: not that case:
    not three axes, a known input rate given, or ``triad_rate_norm_dph`` 0)."""
    axes = tuple(model.axes)
    if len(axes) != 3 or "" in axes or settings.input_rate_dph is not None:
        return None
    return axes if settings.triad_rate_norm_dph > 0.0 else None


def _joint(blocks: dict[str, list[StillBlock]]) -> list[tuple[StillBlock, np.ndarray]]:
    """The blocks every axis has (same run, period and start), each with its residual
    vector, in time order."""
    keyed = [{(b.run, b.period, b.start_s): b for b in axis} for axis in blocks.values()]
    common = sorted(set.intersection(*(set(k) for k in keyed)))
    return [(keyed[0][key], np.array([k[key].residual_dph for k in keyed])) for key in common]


def orientation_groups(vectors: Sequence[np.ndarray],
                       angle_deg: float = ORIENTATION_ANGLE_DEG) -> list[int]:
    """A group number per vector: vectors whose directions are within ``angle_deg`` of a
    group's first vector join it (greedy, in order)."""
    leaders: list[np.ndarray] = []
    out = []
    limit = math.cos(math.radians(angle_deg))
    for vector in vectors:
        u = np.asarray(vector, dtype=np.float64) / max(float(np.linalg.norm(vector)), 1e-300)
        match = next((k for k, lead in enumerate(leaders) if float(u @ lead) >= limit), None)
        if match is None:
            leaders.append(u)
            match = len(leaders) - 1
        out.append(match)
    return out


def _stations(joint: list[tuple[StillBlock, np.ndarray]], fit: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """Mean residual vector and mean temperature of each still period (run, period), over
    its fitted blocks. [°/h], [°C]"""
    sums: dict[tuple[int, int], list[Any]] = {}
    for k in fit:
        block, vector = joint[k]
        entry = sums.setdefault((block.run, block.period), [np.zeros(3), 0.0, 0])
        entry[0] = entry[0] + vector
        entry[1] += block.temperature_c
        entry[2] += 1
    means = np.array([total / count for total, _, count in sums.values()])
    temperatures = np.array([t / count for _, t, count in sums.values()], dtype=np.float64)
    return means.reshape(-1, 3), temperatures


def _prior(model: Any, axes: tuple[str, ...], settings: UpdateSettings
           ) -> tuple[np.ndarray, np.ndarray]:
    """The intercepts and their prior covariance: the last triad update's posterior, else
    the calibration's variances, plus the ageing allowance and the turn-on shift."""
    values = np.array([model.axes[a].drift.intercept_dph for a in axes], dtype=np.float64)
    kept = [c for c in (model.lineage.changes if model.lineage else ())
            if c.axis == TRIAD_CHANGE]
    if kept:
        covariance = np.array(kept[0].covariance_after, dtype=np.float64)
    else:
        covariance = np.diag([float(model.axes[a].drift.coefficient_prior()[2][0, 0])
                              for a in axes])
    allowance = settings.ageing_offset_dph ** 2 + settings.turn_on_dph ** 2
    return values, covariance + np.eye(3) * allowance


def triad_offsets(model: Any, blocks: dict[str, list[StillBlock]], settings: UpdateSettings,
                  labels: Sequence[str]) -> tuple[TriadUpdate | None, str]:
    """The triad's offsets from ``blocks`` (each axis's settled still blocks), or None and
    why they are not updated.

    Raises
    ------
    UpdateRefusedError
        A step further than ``max_step_sigma`` from the prior, or no gain on the held-out
        still blocks.
    """
    axes = tuple(blocks)
    joint = _joint(blocks)
    fit, held = split_heldout(len(joint), settings.holdout_every)
    norm = float(settings.triad_rate_norm_dph)
    if fit.size < 1 or held.size < 2:
        return None, (f"offsets not updated: {len(joint)} still block(s) shared by the three "
                      f"axes, too few to fit and judge them (at least "
                      f"{2 * settings.holdout_every})")
    means, temperatures = _stations(joint, fit)
    groups = orientation_groups(means)
    found = max(groups) + 1
    if found < settings.triad_min_orientations:
        return None, (f"offsets not updated: the still periods hold {found} distinct "
                      f"orientation(s), at least {settings.triad_min_orientations} are "
                      "needed (only |Ω| is known, not its direction: turn the unit between "
                      "still periods, or give the input rate)")
    sigma = _station_sigma(blocks, means, temperatures, model, axes, settings)
    values, prior = _prior(model, axes, settings)
    condition = _condition(means, sigma)
    if not condition <= settings.triad_max_condition:
        return None, (f"offsets not updated: the {found} orientations leave the offsets "
                      f"poorly determined (condition number {condition:.3g} of their "
                      f"information, limit {settings.triad_max_condition:g}): turn the unit "
                      "about another axis")
    step, covariance = _solve(means, sigma, prior, norm)
    distance = mahalanobis(step, prior)
    where = ", ".join(labels)
    if distance > settings.max_step_sigma:
        raise UpdateRefusedError(
            f"{where}: the update would move the offsets of {', '.join(axes)} by "
            f"{distance:.3g} σ of the prior (limit max_step_sigma "
            f"{settings.max_step_sigma:g}): further than ageing goes; check the unit or "
            "recalibrate")
    vectors = np.array([joint[k][1] for k in held])
    before = _rms(np.linalg.norm(vectors, axis=1) - norm)
    after = _rms(np.linalg.norm(vectors - step, axis=1) - norm)
    if not after < before:
        raise UpdateRefusedError(
            f"{where}: no gain on the held-out still blocks for the offsets (rms of |m| - "
            f"|Ω| {before:.4g} °/h before, {after:.4g} °/h after): the update is not applied")
    return TriadUpdate(axes, tuple(float(v) for v in values),
                       tuple(float(v) for v in values + step), prior, covariance, norm,
                       int(means.shape[0]), found, condition, distance, before, after,
                       int(held.size)), ""


def _station_sigma(blocks: dict[str, list[StillBlock]], means: np.ndarray,
                   temperatures: np.ndarray, model: Any, axes: tuple[str, ...],
                   settings: UpdateSettings) -> np.ndarray:
    """1σ of the norm residual of each still period: per axis, the blocks' noise (see
    below) and the slope's ageing allowance times the period's distance from the periods'
    mean temperature (still periods at several temperatures see a slope's error as offsets
    that differ between orientations), projected on the period's Earth-rate direction.
    [°/h]"""
    noise = []
    for axis in axes:
        drift = model.axes[axis].drift
        fallback = drift.residual_std_dph * math.sqrt(drift.window_s / settings.block_s)
        white = max(b.white_sigma_dph for b in blocks[axis])
        noise.append(max(block_noise_dph(blocks[axis], fallback if math.isfinite(fallback)
                                         else 0.0), white, _wander_dph(blocks[axis])))
    # a block's noise beyond white is mostly the bias's flicker and random walk, which a
    # longer mean does not average down: a period's mean is given a block's noise, not
    # that over the square root of its blocks (which would state intervals several times
    # too narrow; bench/update_triad.py measures how honest they are)
    slope = settings.ageing_slope_dph_per_c * np.abs(temperatures - np.nanmean(temperatures))
    per_axis = np.sqrt(np.square(np.array(noise))[None, :] + np.square(slope)[:, None])
    u = means / np.linalg.norm(means, axis=1)[:, None]
    return np.sqrt(np.sum((u * per_axis) ** 2, axis=1))


def _wander_dph(blocks: list[StillBlock]) -> float:
    """How far a still period's mean wanders from the data: the rms over the periods of
    the difference between the means of its second and its first half (a random walk of
    the bias moves a period's mean by about that; white noise by far less). [°/h]"""
    periods: dict[tuple[int, int], list[float]] = {}
    for b in blocks:
        periods.setdefault((b.run, b.period), []).append(b.residual_dph)
    steps = [np.mean(v[len(v) // 2:]) - np.mean(v[:len(v) // 2])
             for v in periods.values() if len(v) >= 4]
    return float(np.sqrt(np.mean(np.square(steps)))) if steps else 0.0


def _condition(means: np.ndarray, sigma: np.ndarray) -> float:
    """Condition number of ``Σ u uᵀ / σ²`` (inf when singular)."""
    u = means / np.linalg.norm(means, axis=1)[:, None] / sigma[:, None]
    eigen = np.linalg.eigvalsh(u.T @ u)
    return float(eigen[-1] / eigen[0]) if eigen[0] > eigen[-1] * 1e-15 else math.inf


def _solve(means: np.ndarray, sigma: np.ndarray, prior: np.ndarray,
           norm: float) -> tuple[np.ndarray, np.ndarray]:
    """The offsets' correction and its posterior covariance (see the module)."""
    from scipy.optimize import least_squares

    whiten = np.linalg.inv(np.linalg.cholesky(prior))

    def residuals(x: np.ndarray) -> np.ndarray:
        return np.concatenate([(np.linalg.norm(means - x, axis=1) - norm) / sigma, whiten @ x])

    def jacobian(x: np.ndarray) -> np.ndarray:
        d = means - x
        return np.vstack([-d / np.linalg.norm(d, axis=1)[:, None] / sigma[:, None], whiten])

    found = least_squares(residuals, np.zeros(3), jac=jacobian, method="lm", xtol=1e-12,
                          ftol=1e-12, gtol=1e-12)
    j = jacobian(found.x)
    return found.x, np.linalg.inv(j.T @ j)


def _rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values)))) if values.size else math.nan


def by_orientation(blocks: dict[str, list[StillBlock]], labels: Sequence[str]
                   ) -> tuple[dict[str, list[StillBlock]], list[str]]:
    """The blocks with their ``run`` made one per (recording, orientation), and the label
    of each: a triad turned between still periods sees another Earth-rate projection on
    every axis in each orientation, so the per-axis filter's nuisance constant is one per
    orientation of each recording, not one per recording."""
    from dataclasses import replace

    joint = _joint(blocks)
    stations: dict[tuple[int, int], list[np.ndarray]] = {}
    for block, vector in joint:
        stations.setdefault((block.run, block.period), []).append(vector)
    keys = list(stations)
    groups = orientation_groups([np.mean(stations[k], axis=0) for k in keys])
    group = dict(zip(keys, groups, strict=True))
    index: dict[tuple[int, int], int] = {}
    out: dict[str, list[StillBlock]] = {}
    for axis, items in blocks.items():
        out[axis] = []
        for b in items:
            key = (b.run, group.get((b.run, b.period), -1 - b.period))
            out[axis].append(replace(b, run=index.setdefault(key, len(index))))
    names = [""] * len(index)
    for (run, _), k in index.items():
        names[k] = labels[run]
    return out, names
