"""Leave-one-run-out cross-validation of a drift model, and term selection by it.

A drift model is trained on several runs (cool-down, warm-up, cycles, the soaks'
transients) and used on runs it has not seen. In-sample F-tests say how well a
term fits the training runs; they do not say whether it carries over. Here each
run in turn is left out, the model's terms are refitted by OLS on the window
means of the other runs, and the left-out run's window residuals are measured:
their standard deviation is the run's cross-validated bias stability at the
window length (10 s by default, the figure of Section 4.2 of [1]). The residuals
of all left-out windows are also split into heating and cooling (sign of the
resonator temperature rate, from df/dt and the thermometer's slope), because HRG
bias behaves differently in the two (Li et al., Sci. Rep. 13:6019, 2023).

:func:`select_terms` searches by that figure: starting from the stepwise
selection, the one-term change (a term in or out) that lowers the root mean
square of the per-run cross-validated stabilities most is made, until none
lowers it by more than ``min_gain``.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.core.timeline import time_blocks
from hrgtc.drift.edge_slope import unknown_edge_slope
from hrgtc.drift.regression import newey_west_inflation
from hrgtc.drift.slow_noise import SLOW_NOISE_LEVEL, beyond_slow_noise
from hrgtc.drift.stepwise import StepwiseRules, stepwise

#: Windows whose |df/dt| is below this share of the largest are neither heating nor cooling.
RATE_DEADBAND = 0.05


@dataclass(frozen=True)
class CrossValidation(records.Written):
    """Leave-one-run-out residuals of one term set.

    Attributes
    ----------
    terms
        The terms refitted on each fold.
    sources
        Name of each run, in run order (not written: the keys of ``per_run_dph``).
    per_run_dph
        Run name -> standard deviation of its held-out window residuals (its
        cross-validated bias stability at the window length), NaN where the run
        could not be left out. [°/h]
    heating_dph, cooling_dph
        The same over all held-out windows while heating / cooling. [°/h]
    score_dph
        Root mean square of the finite per-run values (what :func:`select_terms` lowers).
    """

    not_written = ("sources",)

    terms: tuple[str, ...]
    sources: tuple[str, ...] = field(default=(), kw_only=True)
    per_run_dph: dict[str, records.Statistic]
    heating_dph: records.Statistic
    cooling_dph: records.Statistic
    score_dph: records.Statistic

    def __post_init__(self) -> None:
        if not self.sources:
            object.__setattr__(self, "sources", tuple(self.per_run_dph))

    def summary(self) -> Summary:
        """The held-out residual of each run and over heating, cooling and all runs (its
        text: the per-run table)."""
        runs = tuple(Figure(f"per_run_dph.{name}", name, value, "°/h", digits=4,
                            definition=f"Standard deviation of the held-out window residuals "
                            f"of {name} when the model is refitted without it.")
                     for name, value in self.per_run_dph.items())
        totals = (Figure("heating_dph", "heating", self.heating_dph, "°/h", digits=4,
                         definition="The same over every held-out window while heating."),
                  Figure("cooling_dph", "cooling", self.cooling_dph, "°/h", digits=4,
                         definition="The same over every held-out window while cooling."),
                  Figure("score_dph", "RMS over runs", self.score_dph, "°/h", digits=4,
                         definition="Root mean square of the finite per-run values."))
        width = max((len(s) for s in self.sources), default=4)
        title = (f"Leave-one-run-out cross-validation ({len(self.terms)} terms): "
                 "std of held-out window residuals [°/h]")
        layout = (escape(title),
                  *(f"  {escape(f'{name:<{width}}')}  {{per_run_dph.{name}:8.4f}}"
                    for name in self.per_run_dph),
                  "  heating {heating_dph:.4f}, cooling {cooling_dph:.4f}, "
                  "RMS over runs {score_dph:.4f}")
        return Summary(title, (("held-out runs", runs), ("held-out windows", totals)),
                       layout=layout)


#: The record of :class:`CrossValidation` (nested in other records).
CrossValidationRecord = records.record_of(CrossValidation)


def _std(values: np.ndarray) -> float:
    return float(np.std(values, ddof=1)) if values.size > 2 else math.nan


def heating_mask(rate: np.ndarray, slope_sign: float) -> tuple[np.ndarray, np.ndarray]:
    """(heating, cooling) masks of windows from df/dt and the sign of df/dT."""
    temperature_rate = np.asarray(rate) * slope_sign
    band = RATE_DEADBAND * float(np.max(np.abs(temperature_rate))) if rate.size else 0.0
    return temperature_rate > band, temperature_rate < -band


def _held_out_residuals(x: np.ndarray, y: np.ndarray, run: np.ndarray,
                        columns: Sequence[int]) -> np.ndarray:
    """Residual of every window when its own run is left out of the fit (NaN: not possible)."""
    out = np.full(y.size, np.nan)
    design = np.column_stack([np.ones(y.size), x[:, list(columns)]])
    for r in np.unique(run):
        if r < 0:  # never left out (the middle of a single run: always training)
            continue
        test = run == r
        train = ~test
        if np.count_nonzero(train) <= design.shape[1] + 1:
            continue
        solution = np.linalg.lstsq(design[train], y[train], rcond=None)[0]
        out[test] = y[test] - design[test] @ solution
    return out


def cross_validate(x_scaled: np.ndarray, bias_dph: np.ndarray, run: np.ndarray,
                   names: Sequence[str], terms: Sequence[str], sources: Sequence[str],
                   rate: np.ndarray, slope_sign: float = 1.0) -> CrossValidation:
    """Leave-one-run-out cross-validation of the model with ``terms`` (a subset of ``names``).

    Parameters
    ----------
    x_scaled
        Window means of the candidate terms (scaled), shape (windows, candidates).
    bias_dph
        Window means of the measured bias. [°/h]
    run
        Run index of each window.
    names
        Candidate names (columns of ``x_scaled``).
    terms
        The terms to refit on each fold.
    sources
        Run names, by run index.
    rate
        Window means of df/dt (heating/cooling split). [Hz/s]
    slope_sign
        Sign of df/dT of the thermometer (+1 when frequency rises with temperature).
    """
    columns = [list(names).index(t) for t in terms]
    residual = _held_out_residuals(x_scaled, bias_dph, run, columns)
    per_run = {}
    for r, source in enumerate(sources):
        per_run[source] = _std(residual[(run == r) & np.isfinite(residual)])
    heating, cooling = heating_mask(rate, slope_sign)
    finite = np.isfinite(residual)
    values = np.array([v for v in per_run.values() if math.isfinite(v)])
    score = float(np.sqrt(np.mean(values ** 2))) if values.size else math.nan
    return CrossValidation(tuple(terms), per_run, _std(residual[heating & finite]),
                           _std(residual[cooling & finite]), score, sources=tuple(sources))


@dataclass(frozen=True)
class Windowed:
    """The training windows a choice of terms is judged on.

    Attributes
    ----------
    x_scaled, bias_dph
        The scaled design matrix (a column per candidate) and the bias of each window
        (offsets projected off). [°/h]
    run, names
        Each window's run index and the candidates' names (the columns' order).
    sources
        The runs' names (for the per-run figures of :func:`cross_validate`).
    rate
        df/dt of each window (the heating/cooling split of :func:`cross_validate`).
    time_s, temperature
        Each window's time and thermometer variable (the time blocks of a single run).
    variables, scales
        Each window's mean of every variable, and each variable's scale (the slope a
        single run's model leaves at the edges of its range,
        :func:`hrgtc.drift.edge_slope.unknown_edge_slope`); None: not tested.
    """

    x_scaled: np.ndarray
    bias_dph: np.ndarray
    run: np.ndarray
    names: tuple[str, ...]
    sources: tuple[str, ...] = ()
    rate: np.ndarray | None = None
    time_s: np.ndarray | None = None
    temperature: np.ndarray | None = None
    variables: Mapping[str, np.ndarray] | None = None
    scales: Mapping[str, float] | None = None


def select_terms(data: Windowed, slope_sign: float = 1.0, min_gain: float = 0.01,
                 parents: Mapping[str, Sequence[str]] | None = None,
                 initial: Sequence[str] = ()) -> tuple[str, ...]:
    """Terms chosen by leave-one-run-out cross-validated bias stability.

    From ``initial`` (e.g. the stepwise selection), the move that lowers
    :attr:`CrossValidation.score_dph` the most, adding one candidate or removing one
    term, is taken while it lowers it by more than ``min_gain`` (relative); with
    ``parents``, a term enters only once its parents are in and a parent stays while a
    child is in. The result is never worse by this figure than ``initial``. Needs at
    least two runs. Returns the terms in candidate order.
    """
    names = data.names

    def score(terms: Sequence[str]) -> float:
        value = cross_validate(data.x_scaled, data.bias_dph, data.run, names, terms,
                               data.sources, data.rate, slope_sign).score_dph
        return value if math.isfinite(value) else math.inf

    chosen = [n for n in names if n in set(initial)]
    best = score(chosen)
    for _ in range(4 * len(names)):  # a bound; each accepted move lowers the score
        trial = {}
        for name in names:
            if name in chosen:
                children = [c for c in chosen if name in (parents or {}).get(c, ())]
                if not children:
                    trial[name] = score([n for n in chosen if n != name])
            elif not parents or set(parents.get(name, ())) <= set(chosen):
                trial[name] = score([n for n in names if n in chosen or n == name])
        if not trial:
            break
        name = min(trial, key=trial.__getitem__)
        if not trial[name] < best * (1.0 - min_gain):
            break
        chosen = [n for n in chosen if n != name] if name in chosen else [*chosen, name]
        best = trial[name]
    return tuple(n for n in names if n in chosen)


#: Contiguous time blocks a single training run is cut into for blocked cross-validation.
TIME_BLOCKS = 5
#: A term is pruned when the held-out score without it is within this share of the best.
PRUNE_TOLERANCE = 0.01
#: The line in the thermometer variable, which the slow-noise test never removes.
LINE_TERM = "f"
#: Description of the folds of a single run (stored in the model's ``pruning`` record).
EXTREME_BLOCKS = "coldest and hottest time blocks"


def folds_of(run: np.ndarray, time_s: np.ndarray, temperature: np.ndarray | None = None,
             blocks: int = TIME_BLOCKS) -> tuple[np.ndarray, str]:
    """Cross-validation folds of training windows.

    With two runs or more the folds are the runs. A single run is cut into ``blocks``
    contiguous blocks of its time axis (:func:`hrgtc.core.timeline.time_blocks`: about
    equal numbers of windows, cut at the gaps between bursts where possible); the block
    with the lowest mean ``temperature`` (fold 0) and the one with the highest (fold 1)
    are left out, each predicted from all the other windows. A term then earns its
    place only by predicting temperatures beyond the range it was fitted on, which is
    what a model does on a later, colder or warmer run. On a monotonic ramp these are
    the first and the last block; on a cycle the cold extreme may lie in the middle.
    Without ``temperature``, the first and the last block. Fold -1 is never left out.

    Parameters
    ----------
    run
        Run index of each window.
    time_s
        Window centre times. [s]
    temperature
        Window means of the thermometer variable (a frequency or a temperature; only
        its order matters). [Hz or °C]
    blocks
        Number of time blocks.

    Returns
    -------
    folds, kind
        The fold of each window, and ``"runs"`` or :data:`EXTREME_BLOCKS`.
    """
    run = np.asarray(run)
    if np.unique(run).size >= 2:
        return run, "runs"
    time_s = np.asarray(time_s, dtype=np.float64)
    folds = np.full(time_s.size, -1, dtype=np.int64)
    count = min(blocks, time_s.size)
    if count < 2:
        return folds, EXTREME_BLOCKS
    order = np.argsort(time_s, kind="stable")
    ranges = time_blocks(time_s[order], count)
    coldest, hottest = 0, count - 1
    if temperature is not None:
        sorted_temperature = np.asarray(temperature, dtype=np.float64)[order]
        means = np.array([np.mean(sorted_temperature[a:b]) for a, b in ranges])
        if np.all(np.isfinite(means)) and np.ptp(means) > 0.0:
            coldest, hottest = int(np.argmin(means)), int(np.argmax(means))
    for fold, block in enumerate((coldest, hottest)):
        start, stop = ranges[block]
        folds[order[start:stop]] = fold
    return folds, EXTREME_BLOCKS


def held_out_rms(x_scaled: np.ndarray, bias_dph: np.ndarray, folds: np.ndarray,
                 names: Sequence[str], terms: Sequence[str]) -> float:
    """Root mean square over folds of each left-out fold's residual RMS (offset included:
    a term that extrapolates badly shows in the level as much as in the slope). [°/h]"""
    columns = [list(names).index(t) for t in terms]
    residual = _held_out_residuals(x_scaled, bias_dph, folds, columns)
    per_fold = [float(np.mean(residual[(folds == f) & np.isfinite(residual)] ** 2))
                for f in np.unique(folds) if np.any((folds == f) & np.isfinite(residual))]
    return float(np.sqrt(np.mean(per_fold))) if per_fold else math.nan


def prune_terms(x_scaled: np.ndarray, bias_dph: np.ndarray, folds: np.ndarray,
                names: Sequence[str], selected: Sequence[str],
                tolerance: float = PRUNE_TOLERANCE,
                parents: Mapping[str, Sequence[str]] | None = None,
                keep: Sequence[str] = (), through: bool = False,
                ) -> tuple[tuple[str, ...], float, float]:
    """Drop selected terms that do not carry over to held-out folds.

    Backward elimination by :func:`held_out_rms`: from ``selected`` (the stepwise
    terms), the term whose removal gives the lowest held-out score is removed, then the
    next. Without ``through`` it stops at the first step that raises the score beyond
    ``tolerance`` of the best seen. With ``through`` the path is followed to its end
    (only ``keep`` left) and, of its nested models, the smallest one whose score is
    within ``tolerance`` of the lowest, or within one standard error of it
    (:func:`_within_one_error`), is taken: a group of terms that helps only together
    (``f·df`` propping up a poor ``df``) goes with the rest when the smaller model
    predicts the held-out folds better, where a stop at the first rise keeps them all.

    A term that only fits the training folds (a cubic that runs away outside the
    temperatures it was fitted on) goes; a term the held-out folds need stays. Only
    removals: the result is never richer than ``selected``. With ``parents`` (term ->
    its lower-order parents), a term is removed only once no kept term has it as a
    parent: the highest orders go first (marginality). Terms in ``keep`` (the user's
    starting model) are never removed.

    Returns
    -------
    terms, score_before, score_after
        The kept terms (candidate order) and the held-out RMS before and after. [°/h]
    """
    chosen = [n for n in names if n in set(selected)]
    before = held_out_rms(x_scaled, bias_dph, folds, names, chosen)
    if not math.isfinite(before):
        return tuple(chosen), before, before
    path = [(tuple(chosen), before)]
    while chosen:
        step = _next_removal(x_scaled, bias_dph, folds, names, chosen, parents, keep)
        if step is None:
            break
        name, score = step
        if not through and not score <= min(s for _, s in path) * (1.0 + tolerance):
            break
        chosen.remove(name)
        path.append((tuple(chosen), score))
    if not through:
        return path[-1][0], before, path[-1][1]
    best = min(range(len(path)), key=lambda k: path[k][1])
    reference = _held_out_residuals(x_scaled, bias_dph, folds, _columns(names, path[best][0]))
    for terms, score in reversed(path[best:]):  # the smallest first
        if score <= path[best][1] * (1.0 + tolerance) or _within_one_error(
                _held_out_residuals(x_scaled, bias_dph, folds, _columns(names, terms)),
                reference, folds):
            return terms, before, score
    return path[best][0], before, path[best][1]


def _next_removal(x_scaled: np.ndarray, bias_dph: np.ndarray, folds: np.ndarray,
                  names: Sequence[str], chosen: Sequence[str],
                  parents: Mapping[str, Sequence[str]] | None, keep: Sequence[str],
                  ) -> tuple[str, float] | None:
    """The term of ``chosen`` (no parent of another, not in ``keep``) whose removal gives
    the lowest :func:`held_out_rms`, and that score; None when no term can go."""
    leaves = [n for n in chosen if n not in keep
              and not any(n in (parents or {}).get(c, ()) for c in chosen if c != n)]
    trial = {n: held_out_rms(x_scaled, bias_dph, folds, names,
                             [c for c in chosen if c != n]) for n in leaves}
    trial = {n: v for n, v in trial.items() if math.isfinite(v)}
    if not trial:
        return None
    name = min(trial, key=trial.__getitem__)
    return name, trial[name]


def prune_slow_noise(x_scaled: np.ndarray, bias_dph: np.ndarray, folds: np.ndarray,
                     time_s: np.ndarray, names: Sequence[str], selected: Sequence[str],
                     parents: Mapping[str, Sequence[str]] | None = None,
                     keep: Sequence[str] = (), level: float = SLOW_NOISE_LEVEL,
                     ) -> tuple[tuple[str, ...], list[dict[str, Any]]]:
    """Backward elimination of terms whose held-out gain does not beat the training
    residual's slow noise (:func:`hrgtc.drift.slow_noise.beyond_slow_noise`): on one ramp
    a random walk in the bias looks like curvature to the coldest and the hottest block,
    and a term kept for it runs away beyond them.

    Each step tests every removable term (not in ``keep``, no parent of a kept term): the
    chance, under the model without it plus slow noise estimated under that model, of a
    held-out RMS ratio (with / without) as low as observed. The term with the largest
    chance goes while that chance reaches ``level``.

    Returns the kept terms (candidate order) and one record per term removed, and one for
    the last step's most doubtful term kept (``term``, ``ratio``, ``chance``,
    ``white_dph``, ``walk_dph_per_sqrt_h``, ``kept``).
    """
    chosen = [n for n in names if n in set(selected)]
    tests: list[dict[str, Any]] = []
    while chosen:
        score = held_out_rms(x_scaled, bias_dph, folds, names, chosen)
        leaves = [n for n in chosen if n not in keep
                  and not any(n in (parents or {}).get(c, ()) for c in chosen if c != n)]
        trial = {}
        for name in leaves:
            rest = [c for c in chosen if c != name]
            smaller = held_out_rms(x_scaled, bias_dph, folds, names, rest)
            if not (math.isfinite(score) and math.isfinite(smaller)):
                continue
            ratio = score / smaller if smaller > 0.0 else math.inf
            beyond, chance, noise = beyond_slow_noise(
                x_scaled, bias_dph, folds, time_s, _columns(names, rest),
                _columns(names, chosen), ratio, level)
            trial[name] = {"term": name, "ratio": ratio, "chance": chance,
                           "white_dph": noise.white_dph,
                           "walk_dph_per_sqrt_h": noise.over(3600.0), "kept": beyond}
        if not trial:
            break
        doubt = max(trial.values(), key=lambda r: -1.0 if math.isnan(r["chance"])
                    else r["chance"])
        tests.append(doubt)
        if doubt["kept"]:
            break
        chosen.remove(doubt["term"])
    return tuple(chosen), tests


def _columns(names: Sequence[str], terms: Sequence[str]) -> list[int]:
    return [list(names).index(t) for t in terms]


def _within_one_error(smaller: np.ndarray, best: np.ndarray, folds: np.ndarray) -> bool:
    """Is the held-out mean square of ``smaller`` within one standard error of ``best``'s?

    Both are held-out residuals of the same windows. The difference of their squares is
    averaged as :func:`held_out_rms` averages (each fold's mean, then over folds); its
    standard error counts the correlation of neighbouring windows (Newey-West, as the
    F-tests do). The one-standard-error rule of Breiman et al. (Classification and
    Regression Trees, 1984; Hastie, Tibshirani and Friedman, The Elements of Statistical
    Learning, 2nd ed., Section 7.10): the simplest model the held-out data cannot tell
    from the best.
    """
    excess, variance, count = 0.0, 0.0, 0
    for fold in np.unique(folds[folds >= 0]):
        inside = (folds == fold) & np.isfinite(smaller) & np.isfinite(best)
        d = smaller[inside] ** 2 - best[inside] ** 2
        if d.size < 2:
            continue
        inflation, _ = newey_west_inflation(d)
        excess += float(np.mean(d))
        variance += inflation * float(np.var(d, ddof=1)) / d.size
        count += 1
    if count == 0:
        return False
    return excess / count <= math.sqrt(variance) / count


def _line_admitted(x_scaled: np.ndarray, bias_dph: np.ndarray, names: Sequence[str],
                   line_test: tuple[float, float] | None) -> bool:
    """Does a plain F-test ``(penter, premove)`` admit the line on its own? The one term
    physics expects is the floor of one run unless the data cannot tell it from no slope."""
    if line_test is None or LINE_TERM not in names:
        return False
    k = list(names).index(LINE_TERM)
    penter, premove = line_test
    return stepwise(x_scaled[:, [k]], bias_dph, names=[LINE_TERM],
                    rules=StepwiseRules(penter, premove)).selected == (LINE_TERM,)


def guard_selection(data: Windowed, selected: Sequence[str],
                    parents: Mapping[str, Sequence[str]] | None = None,
                    keep: Sequence[str] = (), line_test: tuple[float, float] | None = None,
                    ) -> tuple[tuple[str, ...] | None, dict[str, Any]]:
    """The guarded selection: :func:`prune_terms` on the folds of :func:`folds_of`
    (``data.temperature``: the window means of the thermometer variable, which pick the
    coldest and the hottest block of a single run). ``line_test``: ``(penter, premove)``
    of a plain F-test of the line in the thermometer variable (:data:`LINE_TERM`) on its
    own; on a single run, a line it admits is kept whatever the other terms.

    Returns the terms to refit (None when nothing was dropped) and the record of the check
    (``folds``, ``dropped``, ``before_dph``, ``after_dph``) stored in the model.
    """
    x_scaled, bias_dph, names, time_s = data.x_scaled, data.bias_dph, data.names, data.time_s
    folds, kind = folds_of(data.run, time_s, data.temperature)
    original = set(selected)
    if kind != "runs" and _line_admitted(x_scaled, bias_dph, names, line_test):
        # one long run: a line in the thermometer variable that is significant on its own
        # is the floor, kept whatever the joint F-tests said (the held-out blocks of one
        # run cannot tell a slope from the hysteresis of its ramps; a real chamber cycle's
        # axis did worse held out without it than the plain line,
        # docs/real-loggers/corpus.md)
        keep = list(dict.fromkeys([*keep, LINE_TERM]))
        if LINE_TERM not in selected:
            selected = [LINE_TERM, *selected]
    # across runs a fold's complement may lack what one run alone excites (a heating-only
    # term when the one warm-up is left out): there, stop at the first rise
    kept, before, after = prune_terms(x_scaled, bias_dph, folds, names, selected,
                                      parents=parents, keep=keep, through=kind != "runs")
    tests, edge = None, None
    if kind != "runs" and kept:  # one ramp: the extreme blocks are its ends, walk and all
        # the line in the thermometer variable stays: the test is of what goes beyond it
        kept, tests = prune_slow_noise(x_scaled, bias_dph, folds, time_s, names, kept,
                                       parents=parents, keep=[*keep, LINE_TERM])
        if data.variables is not None and data.scales is not None:
            # the blocks cannot tell whether a bend carries on beyond the run's ends: the
            # slope compensation continues with there must stay known where the line's is
            kept, edge = unknown_edge_slope(data, kept, parents=parents, keep=keep,
                                            line=LINE_TERM)
        after = held_out_rms(x_scaled, bias_dph, folds, names, kept)
    record = {"folds": kind, "dropped": [t for t in selected if t not in kept],
              "before_dph": before, "after_dph": after}
    if tests:
        record["slow_noise"] = tests
    if edge and edge["dropped"]:
        record["edge_slope"] = edge
    return (tuple(kept) if set(kept) != original else None), record
