"""Stepwise regression on sufficient statistics, Section 4.1 of [1].

Stepwise selection follows MATLAB's ``stepwisefit``: the constant is always in;
each step adds the excluded term with the smallest partial-F p-value if it is
below ``penter``, otherwise removes the included term with the largest p-value
if it is above ``premove``; it stops when neither applies. Every candidate fit
is a small QR of the columns it uses of the triangular factor R of [1, X, y]
held by :class:`~hrgtc.drift.regression.GramAccumulator` (re-exported here with
:func:`ols`), so the selection never touches the rows and never forms normal
equations. On rows held in memory, :func:`stepwise` then refines the
coefficients of the selected model in extended precision
(:func:`hrgtc.drift.regression.refine`); :func:`stepwise_from_accumulator` has no rows
and reports the fit of the factor.

``variance_inflation`` (default 1, i.e. ``stepwisefit`` exactly) divides every
F statistic by a factor c >= 1 and multiplies the standard errors by sqrt(c):
the correction for autocorrelated residuals, whose long-run variance is c
times their variance (see :func:`hrgtc.drift.fit`).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import HrgtcWarning, InputError, RankDeficientError
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.drift.qr_accumulator import _check_names, _resolve_terms, _solve
from hrgtc.drift.regression import (
    COLLINEARITY_TOL,
    GramAccumulator,
    OLSResult,
    ols,
    ols_from_accumulator,
    refine,
)
from hrgtc.settings.drift import PENTER, PREMOVE_FLOOR

__all__ = [
    "COLLINEARITY_TOL",
    "GramAccumulator",
    "OLSResult",
    "Step",
    "StepwiseResult",
    "ols",
    "ols_from_accumulator",
    "stepwise",
    "stepwise_from_accumulator",
]


# --------------------------------------------------------------------------- stepwise
@dataclass(frozen=True)
class Step(records.Written):
    """One step of a stepwise regression.

    ``fstat`` is the partial F statistic of the term (the square of its t statistic
    in the larger of the two models) and ``pvalue`` its p-value F(1, df_resid).
    """

    action: Literal["added", "removed"]
    term: str
    fstat: records.Statistic
    pvalue: records.Statistic


@dataclass(frozen=True, eq=False)
class StepwiseResult(records.Written):
    """Outcome of :func:`stepwise`, Section 4.1 of [1].

    Attributes
    ----------
    history
        The steps taken, in order.
    selected
        Terms in the final model, in column order.
    result
        Final fit: intercept first, then ``selected``.
    candidates
        All candidate terms, in column order.
    excluded_pvalues
        For each term not selected (column order): the p-value it would have if
        added to the final model (NaN if collinear with it), as MATLAB reports.
    penter, premove
        Thresholds used.
    stop_reason
        ``"converged"``, ``"max_steps"`` or ``"cycle"``.
    """

    history: tuple[Step, ...]
    selected: tuple[str, ...]
    result: OLSResult
    candidates: tuple[str, ...]
    excluded_pvalues: tuple[records.Statistic, ...]
    penter: float
    premove: float
    stop_reason: Literal["converged", "max_steps", "cycle"]
    variance_inflation: records.Statistic = 1.0

    def summary(self) -> Summary:
        """The steps (term, F, p), the excluded terms' p-values and the final fit
        (:meth:`OLSResult.summary`, its figures after ``result.``)."""
        steps = step_figures(self.history)
        excluded = [c for c in self.candidates if c not in self.selected]
        left = tuple(Figure(f"excluded_pvalues[{k}]", f"p of {c} if added", p, digits=3,
                            definition=f"The p-value {c} would have if added to the final "
                            "model (NaN: collinear with it).")
                     for k, (c, p) in enumerate(zip(excluded, self.excluded_pvalues,
                                                    strict=True)))
        title = (f"Stepwise regression (penter={self.penter:g}, premove={self.premove:g}), "
                 f"{len(self.history)} steps, stopped: {self.stop_reason}")
        layout = [escape(title)]
        layout += [f"  {n:>3}. {{history[{n - 1}].action:<8}}{{history[{n - 1}].term:<14}}"
                   f"F = {{history[{n - 1}].fstat:.6g}}, p = {{history[{n - 1}].pvalue:.6g}}"
                   for n in range(1, len(self.history) + 1)]
        if excluded:
            layout.append("Excluded (p-value if added): " + ", ".join(
                f"{escape(c)} {{excluded_pvalues[{k}]:.3g}}" for k, c in enumerate(excluded)))
        fit = self.result.summary().renamed("result.")
        return Summary(title, (("steps", steps), ("excluded", left), *fit.sections),
                       layout=(*layout, *fit.lines()))


#: The record of :class:`Step` (nested in other records).
StepRecord = records.record_of(Step)


#: The record of :class:`StepwiseResult` (nested in other records).
StepwiseRecord = records.record_of(StepwiseResult, "StepwiseRecord")


@dataclass(frozen=True)
class StepwiseRules:
    """The rules of a stepwise search (one settings object, passed whole).

    Attributes
    ----------
    penter
        A term enters if its partial-F p-value is below this.
    premove
        A term leaves if its p-value is above this; default ``max(penter, 0.10)``.
    initial
        Terms in the starting model (names, column indices or a boolean mask);
        default none.
    max_steps
        Most steps to take; default no limit. A step that would return to a
        model already visited stops the search (``stop_reason == "cycle"``, with
        an :class:`~hrgtc.core.errors.HrgtcWarning`), so it always ends.
    tol
        Collinearity tolerance; a candidate collinear with the current model is
        not eligible to enter.
    variance_inflation
        Factor c >= 1 by which every F statistic is divided (standard errors
        multiplied by sqrt(c)): the ratio of the long-run to the plain variance
        of autocorrelated residuals. 1 gives ``stepwisefit`` exactly.
    parents
        Optional hierarchy (marginality principle, Nelder 1977): term -> the
        terms it contains (``"f^2*df"`` -> ``["f*df", "f^2"]``). A term may enter
        only when all its parents are in, and may leave only when none of its
        children is in. None (default) gives ``stepwisefit`` exactly.
    """

    penter: float = PENTER
    premove: float | None = None
    initial: Iterable[str | int | bool] | None = None
    max_steps: int | None = None
    tol: float = COLLINEARITY_TOL
    variance_inflation: float = 1.0
    parents: Mapping[str, Iterable[str]] | None = None


def stepwise(X: Any, y: Any, names: Sequence[str] | None = None,
             rules: StepwiseRules = StepwiseRules(), *, weights: Any = None,
             refine: bool = True) -> StepwiseResult:
    """Stepwise linear regression with MATLAB ``stepwisefit`` semantics, Section 4.1 of [1].

    Parameters
    ----------
    X
        Candidate terms, shape (rows, p); no column of ones (the constant is always in).
    y
        Response, shape (rows,). [units of y]
    names
        Name of each candidate (default ``x1, x2, ...``).
    rules
        Entry and removal thresholds, starting model, step limit, collinearity
        tolerance, variance inflation and hierarchy (:class:`StepwiseRules`).
    weights
        Optional non-negative weight per row.
    refine
        Polish the coefficients of the selected model by extended-precision
        refinement of the augmented system on the rows
        (:func:`hrgtc.drift.regression.refine`); the selection itself, the standard
        errors and the p-values of the steps come from the QR factor either way.

    Returns
    -------
    StepwiseResult

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(1)
    >>> X = rng.normal(size=(500, 5))
    >>> y = 1 + 2 * X[:, 1] - 3 * X[:, 3] + rng.normal(size=500)
    >>> stepwise(X, y, rules=StepwiseRules(penter=0.001, premove=0.01)).selected
    ('x2', 'x4')
    """
    X = np.asarray(X, dtype=np.float64)
    acc = GramAccumulator(_check_names(names, X.shape[1]) if X.ndim == 2 else names)
    acc.partial_fit(X, y, weights)
    found = stepwise_from_accumulator(acc, rules=rules)
    if not refine:
        return found
    columns = [found.candidates.index(name) for name in found.selected]
    polished = _refine(found.result, X[:, columns], y, weights, factor=acc.select(columns))
    return dataclasses.replace(found, result=polished)


_refine = refine  # ``stepwise`` has a parameter of the same name


def stepwise_from_accumulator(acc: GramAccumulator, names: Sequence[str] | None = None,
                              rules: StepwiseRules = StepwiseRules()) -> StepwiseResult:
    """Stepwise regression from accumulated statistics, without the raw rows.

    For data too large to hold: feed the rows chunk by chunk (or per file, per
    worker) into :class:`GramAccumulator` with ``partial_fit``, combine partial
    accumulators with ``merge``, then call this. Every candidate fit is a small
    QR and triangular solve on the stored factor, so the selection costs nothing
    compared with the one pass over the rows; the result equals :func:`stepwise`
    on the concatenated rows. Rules and parameters as in :func:`stepwise`.

    Parameters
    ----------
    acc
        Statistics of all rows.
    names
        Override of the candidate names (default ``acc.names_``).
    rules
        The rules of the search (:class:`StepwiseRules`).

    Examples
    --------
    >>> import numpy as np
    >>> acc = GramAccumulator(["f", "fdot", "f2"])
    >>> rng = np.random.default_rng(2)
    >>> for _ in range(10):  # e.g. one chunk per file
    ...     X = rng.normal(size=(10_000, 3))
    ...     _ = acc.partial_fit(X, 0.5 + 3 * X[:, 0] + rng.normal(size=10_000))
    >>> stepwise_from_accumulator(acc, rules=StepwiseRules(penter=1e-4, premove=1e-3)).selected
    ('f',)
    """
    penter, premove, initial, max_steps = rules.penter, rules.premove, rules.initial, \
        rules.max_steps
    tol, variance_inflation, parents = rules.tol, rules.variance_inflation, rules.parents
    cand = _check_names(names, len(acc._require_data())) if names is not None \
        else acc._require_data()
    premove = max(penter, PREMOVE_FLOOR) if premove is None else premove
    if not (0 < penter < 1 and 0 < premove < 1):
        raise InputError(f"penter and premove must lie in (0, 1), got {penter} and {premove}")
    if penter > premove:
        raise InputError(f"penter ({penter}) must not exceed premove ({premove}); otherwise "
                         "a term could be added and removed forever: raise premove")
    if max_steps is not None and max_steps < 0:
        raise InputError(f"max_steps must be >= 0 or None, got {max_steps}")
    included = _resolve_terms(initial, cand, "initial") if initial is not None else set()
    parent_index = _parent_index(parents, cand)
    current = _solve(acc, sorted(included), cand, tol, variance_inflation)
    history: list[Step] = []
    visited = {frozenset(included)}
    stop_reason = "converged"
    while True:
        entry: dict[int, tuple[float, float]] = {}
        for j in sorted(set(range(len(cand))) - included):
            if not parent_index[j] <= included:
                continue
            try:
                trial = _solve(acc, sorted(included | {j}), cand, tol, variance_inflation)
            except RankDeficientError:
                continue
            pos = sorted(included | {j}).index(j) + 1
            entry[j] = (float(trial.tvalues[pos] ** 2), float(trial.pvalues[pos]))
        move: tuple[str, int, float, float] | None = None
        if entry:
            j = min(entry, key=lambda c: (entry[c][1], c))
            if entry[j][1] < penter:
                move = ("added", j, *entry[j])
        if move is None and included:
            order = sorted(included)
            removable = [pos for pos, i in enumerate(order)
                         if not any(i in parent_index[k] for k in included)]
            if removable:
                pos = max(removable, key=lambda q: (current.pvalues[q + 1], -q))
                if current.pvalues[pos + 1] > premove:
                    move = ("removed", order[pos], float(current.tvalues[pos + 1] ** 2),
                            float(current.pvalues[pos + 1]))
        if move is None:
            break
        if max_steps is not None and len(history) >= max_steps:
            stop_reason = "max_steps"
            break
        nxt = included ^ {move[1]}
        if frozenset(nxt) in visited:
            verb = "adding" if move[0] == "added" else "removing"
            warnings.warn(f"stepwise: {verb} {cand[move[1]]!r} would return to a model "
                          "already visited; stopping. Lower penter or raise premove.",
                          HrgtcWarning, stacklevel=2)
            stop_reason = "cycle"
            break
        visited.add(frozenset(nxt))
        included = nxt
        history.append(Step(move[0], cand[move[1]], move[2], move[3]))
        current = _solve(acc, sorted(included), cand, tol, variance_inflation)
    excluded = [j for j in range(len(cand)) if j not in included]
    return StepwiseResult(history=tuple(history), selected=tuple(cand[j] for j in sorted(included)),
                          result=current, candidates=cand,
                          excluded_pvalues=tuple(entry[j][1] if j in entry else math.nan
                                                 for j in excluded),
                          penter=float(penter), premove=float(premove), stop_reason=stop_reason,
                          variance_inflation=float(variance_inflation))


def _parent_index(parents: Mapping[str, Iterable[str]] | None,
                  cand: tuple[str, ...]) -> list[set[int]]:
    """For each candidate, the indices of its parents among the candidates."""
    if parents is None:
        return [set() for _ in cand]
    unknown = sorted({p for ps in parents.values() for p in ps} - set(cand)
                     | set(parents) - set(cand))
    if unknown:
        raise InputError(f"parents names terms that are not candidates: {unknown}; "
                         f"candidates are {list(cand)}")
    return [{cand.index(p) for p in parents.get(name, ())} for name in cand]


def step_figures(history: Sequence[Step]) -> tuple[Figure, ...]:
    """The steps of a stepwise history as a table (action, term, F, p), after
    ``history[n].``: the summaries of :class:`StepwiseResult` and the drift model."""
    out: list[Figure] = []
    for n, step in enumerate(history):
        key, label = f"history[{n}]", f"step {n + 1}"
        out += [Figure(f"{key}.action", f"{label}, action", step.action, row=str(n),
                       column="action"),
                Figure(f"{key}.term", f"{label}, term", step.term, row=str(n), column="term"),
                Figure(f"{key}.fstat", f"{label}, F", step.fstat, row=str(n), column="F",
                       definition="Partial F statistic of the term when it was added or "
                       "removed."),
                Figure(f"{key}.pvalue", f"{label}, p", step.pvalue, digits=3, row=str(n),
                       column="p", definition="p-value of that F statistic.")]
    return tuple(out)
