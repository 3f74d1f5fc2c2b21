"""Held-out blocks of one run judged as compensation applies a model beyond its range.

Compensation continues a drift model along its tangent beyond the ranges it was trained
on (:func:`hrgtc.drift.features.tangent_extension`): a cubic in T does not run away on a
colder day, but neither does its curvature carry on. The guarded selection of a single
run leaves out its coldest and its hottest time block and predicts each from the other
windows (:func:`hrgtc.drift.cross_validation.folds_of`); a held-out block reaches beyond
the temperatures of the windows it is predicted from, as the held-out part of a recording
reaches beyond the trained ones. Judged with the polynomial itself there, a square or a
cube that bends towards the block's level wins, then loses on the day the model is used,
where the tangent takes over a few degrees further on (a VN-100's x axis, flat in T:
docs/real-loggers/corpus.md).

Here each held-out block is predicted the way compensation would predict it: the model
fitted on the other windows, held at the edge of their ranges (the window means' extremes
of every variable: f, df, ...) and continued along its tangent beyond. The prediction
stays linear in the coefficients, so the held-out design of a block is the plain one plus
a correction, nonzero only for its windows beyond the ranges (:func:`tangent_corrections`);
the held-out scores of :mod:`hrgtc.drift.cross_validation` and the slow-noise test of
:mod:`hrgtc.drift.slow_noise` take it. A law linear in the variables is continued exactly,
so the line in T is judged as before; a curvature earns its place only where the
compensation will carry it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from hrgtc.drift.features import Term, design_matrix, tangent_extension


def tangent_corrections(terms: Sequence[Term], variables: Mapping[str, np.ndarray],
                        scales: Mapping[str, float], folds: np.ndarray,
                        ) -> dict[int, np.ndarray]:
    """Per held-out fold: what the tangent continuation adds to the scaled candidate columns.

    For the windows of fold ``k``, each variable's range is that of the other windows
    (every fold but ``k``, fold -1 included); a window beyond it gets, per candidate, the
    term continued along its tangent at the edge (:func:`~hrgtc.drift.features.
    tangent_extension` with a unit coefficient) less the term itself, both of the window's
    mean variables. Added to the held-out windows' columns, the fold's prediction is the
    compensation's.

    Parameters
    ----------
    terms
        The candidate terms, in column order.
    variables
        Window means of every variable with a trained range (f [Hz or °C], df, ...).
    scales
        Each variable's scale (the columns are terms of scaled variables).
    folds
        Fold of each window (-1: never left out).

    Returns
    -------
    dict
        Fold -> correction of shape (windows, terms), zero outside the fold's windows
        beyond the ranges; folds with no window beyond them are left out.
    """
    folds = np.asarray(folds)
    names = tuple(v for v in variables if any(v in t.variables for t in terms))
    if not names or not terms:
        return {}
    plain = None
    out = {}
    for fold in np.unique(folds[folds >= 0]):
        test = folds == fold
        train = ~test
        if not train.any():
            continue
        ranges = {v: (float(np.min(variables[v][train])), float(np.max(variables[v][train])))
                  for v in names}
        beyond = np.zeros(folds.size, dtype=bool)
        for v in names:
            low, high = ranges[v]
            beyond |= test & ((variables[v] < low) | (variables[v] > high))
        if not beyond.any():
            continue
        if plain is None:
            plain = design_matrix(terms, {v: np.asarray(variables[v]) for v in names}, scales)
        values = {v: np.asarray(variables[v])[beyond] for v in names}
        continued = np.column_stack([
            tangent_extension([t], [1.0], values, scales, ranges) for t in terms])
        correction = np.zeros(plain.shape)
        correction[beyond] = continued - plain[beyond]
        out[int(fold)] = correction
    return out


@dataclass(frozen=True)
class Continuation:
    """What :func:`tangent_corrections` needs beside the folds: the candidate terms, the
    window means of the variables and their scales (from :func:`hrgtc.drift.fit`)."""

    terms: Sequence[Term]
    variables: Mapping[str, np.ndarray]
    scales: Mapping[str, float]

    def corrections(self, folds: np.ndarray) -> dict[int, np.ndarray]:
        """:func:`tangent_corrections` of these folds."""
        return tangent_corrections(self.terms, self.variables, self.scales, folds)
