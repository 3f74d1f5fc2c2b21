"""Constant offsets per run and per orientation: nuisance parameters of the drift fit.

A gyro's bias holds constants that no temperature term should absorb: the turn-on
offset of each run (a restart), and for each orientation of the unit the
g-sensitivity of a MEMS gyro or, for an HRG, the Earth-rate component along the
axis (up to ±15 °/h when the unit is turned, against a 0.5 °/h floor). If the
runs or orientations also differ in temperature, a single intercept lets the
temperature terms follow those constants, and the temperature coefficients are
biased. Here each such constant gets a dummy column that is always in the model
and never a stepwise candidate: the window means of the bias and of every
candidate term are projected off the dummy columns (Frisch–Waugh–Lovell), the
stepwise regression runs on what is left, and the offsets are recovered from the
group means afterwards. The temperature coefficients are those of the full
regression with the dummies; the stepwise F-tests' residual degrees of freedom
are one per group too many (negligible with hundreds of windows).

Orientation = a cluster of the mean accelerometer vector of the still windows
(:func:`hrgtc.recording.motion.orientation_labels`) when every run logs
``accel_x/y/z``, else the user's ``orientation`` label column. Three orientations
are three points: accelerometer terms are never stepwise candidates.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.recording.motion import orientation_labels

#: Offset modes of a drift fit (``--offsets``).
OFFSET_MODES = ("auto", "none", "run", "orientation", "run+orientation")
#: Two still windows whose accelerometer directions differ by more than this are two
#: orientations. [deg]
ORIENTATION_TOLERANCE_DEG = 10.0


@dataclass(frozen=True)
class OffsetGroups:
    """Which nuisance offsets a fit carries, and the window labels of each.

    Attributes
    ----------
    mode
        The resolved mode (``"none"``, ``"run"``, ``"orientation"``, ``"run+orientation"``).
    factors
        Factor name (``"run"``, ``"orientation"``) -> group index of each window.
    names
        Factor name -> the name of each group.
    orientations
        Unit vectors of the orientations (accelerometer clusters), else empty.
    """

    mode: str
    factors: dict[str, np.ndarray]
    names: dict[str, tuple[str, ...]]
    orientations: tuple[tuple[float, ...], ...] = ()

    @property
    def n_offsets(self) -> int:
        """Extra constants beyond the intercept."""
        return sum(len(n) - 1 for n in self.names.values())

    def dummies(self) -> np.ndarray:
        """The dummy columns (constant included), shape (windows, columns)."""
        columns = []
        for factor, labels in self.factors.items():
            for k in range(len(self.names[factor])):
                columns.append((labels == k).astype(np.float64))
        return np.column_stack(columns)


def offset_groups(mode: str, run: np.ndarray, sources: Sequence[str],
                  accel: np.ndarray | None = None, label: np.ndarray | None = None,
                  tolerance_deg: float = ORIENTATION_TOLERANCE_DEG) -> OffsetGroups:
    """The offset groups of training windows.

    Parameters
    ----------
    mode
        One of :data:`OFFSET_MODES`; ``"auto"`` is ``"orientation"`` when the windows
        carry accelerometer means or a label, else ``"none"``.
    run, sources
        Run index of each window and the runs' names.
    accel
        Window means of ``accel_x/y/z``, shape (windows, 3), or None.
    label
        Window means of the user's ``orientation`` column, or None.
    """
    if mode not in OFFSET_MODES:
        raise InputError(f"offsets {mode!r} is not known; use one of {', '.join(OFFSET_MODES)}"
                         " (--offsets)")
    has_orientation = accel is not None or label is not None
    if mode == "auto":
        mode = "orientation" if has_orientation else "none"
    if "orientation" in mode and not has_orientation:
        raise InputError("--offsets orientation needs accelerometer columns accel_x, accel_y, "
                         "accel_z (map them with --col accel_x=NAME ...) or an 'orientation' "
                         "label column in every training run; or use --offsets run")
    n = run.size
    factors: dict[str, np.ndarray] = {}
    names: dict[str, tuple[str, ...]] = {}
    centres: tuple[tuple[float, ...], ...] = ()
    if mode == "none":
        factors["const"] = np.zeros(n, dtype=np.int64)
        names["const"] = ("all",)
    if "run" in mode:
        present = np.unique(run)
        factors["run"] = np.searchsorted(present, run)
        names["run"] = tuple(sources[int(r)] for r in present)
    if "orientation" in mode:
        if accel is not None:
            labels, found = orientation_labels(accel, tolerance_deg)
            centres = tuple(tuple(float(x) for x in c) for c in found)
            factors["orientation"] = labels
            names["orientation"] = tuple(f"orientation {k}" for k in range(len(found)))
        else:
            assert label is not None
            rounded = np.round(label).astype(np.int64)
            present = np.unique(rounded)
            factors["orientation"] = np.searchsorted(present, rounded)
            names["orientation"] = tuple(f"orientation {int(v)}" for v in present)
    return OffsetGroups(mode, factors, names, centres)


def project_off(groups: OffsetGroups, *arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """Each array (a column or a matrix of columns) minus its projection on the dummies."""
    dummies = groups.dummies()
    out = []
    for a in arrays:
        solution = np.linalg.lstsq(dummies, a, rcond=None)[0]
        out.append(a - dummies @ solution)
    return tuple(out)


def recover_offsets(groups: OffsetGroups, bias: np.ndarray, x_scaled: np.ndarray,
                    params: np.ndarray) -> tuple[float, dict[str, float]]:
    """The intercept and each group's offset from it, given the terms' scaled coefficients.

    ``bias - x_scaled @ params`` is regressed on the dummies; the intercept is the
    mean of the fitted constants over the windows and each group's offset is the
    mean of the fitted constants over its windows minus the intercept. [°/h]
    """
    rest = bias - (x_scaled @ params if params.size else 0.0)
    dummies = groups.dummies()
    fitted = dummies @ np.linalg.lstsq(dummies, rest, rcond=None)[0]
    intercept = float(np.mean(fitted))
    offsets: dict[str, float] = {}
    if groups.mode == "none":
        return intercept, offsets
    for factor, labels in groups.factors.items():
        for k, name in enumerate(groups.names[factor]):
            key = name if factor == "orientation" else f"run {name}"
            offsets[key] = float(np.mean(fitted[labels == k])) - intercept
    return intercept, offsets


def orientation_offset(offsets: Mapping[str, float], orientations: Sequence[Sequence[float]],
                       accel: Any, tolerance_deg: float = ORIENTATION_TOLERANCE_DEG
                       ) -> float | None:
    """The trained offset of the orientation of a mean accelerometer vector, from the
    intercept. [°/h]

    None when the direction matches no orientation seen in training: an unknown
    offset is reported as unknown, never guessed.
    """
    if not orientations:
        return None
    labels, _ = orientation_labels(np.atleast_2d(accel), tolerance_deg, centres=orientations)
    label = int(labels[0])
    if label < 0:
        return None
    value = offsets.get(f"orientation {label}")
    return None if value is None or not math.isfinite(value) else float(value)


def fit_offsets(groups: OffsetGroups, bias: np.ndarray, x_full: np.ndarray,
                names: Sequence[str], selected: Sequence[str], params: np.ndarray,
                intercept: float) -> tuple[float, dict[str, float]]:
    """The intercept and the nuisance offsets of a fit whose selected terms have the scaled
    coefficients ``params[1:]`` (mode ``"none"``: the fit's own ``intercept``, no offsets)."""
    if groups.mode == "none":
        return intercept, {}
    columns = [list(names).index(t) for t in selected]
    return recover_offsets(groups, bias, x_full[:, columns], np.asarray(params[1:]))


def sample_offsets(offsets: Mapping[str, float], orientations: Sequence[Sequence[float]],
                   accel: np.ndarray, tolerance_deg: float = ORIENTATION_TOLERANCE_DEG
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Per sample: the trained offset of its orientation (from the intercept) and whether
    the orientation is unknown (offset 0 there: the intercept, the training mean).

    ``accel`` has shape (samples, 3). A direction within ``tolerance_deg`` of no trained
    orientation (or a zero vector) is unknown: its offset is not guessed. [°/h]
    """
    accel = np.asarray(accel, dtype=np.float64)
    centres = np.asarray(orientations, dtype=np.float64)
    norm = np.linalg.norm(accel, axis=1)
    unit = accel / np.where(norm > 0, norm, 1.0)[:, None]
    dots = unit @ centres.T
    best = np.argmax(dots, axis=1)
    known = (np.max(dots, axis=1) >= math.cos(math.radians(tolerance_deg))) & (norm > 0)
    table = np.array([offsets.get(f"orientation {k}", 0.0) for k in range(len(centres))])
    return np.where(known, table[best], 0.0), ~known


def label_offsets(offsets: Mapping[str, float], label: Any) -> tuple[np.ndarray, np.ndarray]:
    """Per sample: the trained offset of the user's orientation label (from the intercept)
    and whether the label was never seen in training (offset 0 there, not guessed). [°/h]"""
    rounded = np.round(np.asarray(label, dtype=np.float64))
    offset = np.zeros(rounded.size)
    unknown = np.ones(rounded.size, dtype=bool)
    for value in np.unique(rounded[np.isfinite(rounded)]):
        key = f"orientation {int(value)}"
        if key in offsets:
            at = rounded == value
            offset[at] = offsets[key]
            unknown[at] = False
    return offset, unknown
