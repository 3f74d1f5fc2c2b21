"""The candidate terms of a drift fit: the ``--terms`` given or the default set, and the
``a_NAME`` channels ``--aux NAME=COLUMN`` maps, checked against the training runs; and the
thermal-history terms added on top of a fit's selection (:func:`add_history`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.drift.features import AUX_NAME, EQ21, parse_terms
from hrgtc.settings.drift import GRADIENT_TERMS

__all__ = ["ALL_IN", "HistoryChoice", "add_history", "candidate_terms", "parse_aux",
           "resolve_terms"]


def parse_aux(items: Iterable[str]) -> dict[str, str]:
    """``NAME=COLUMN`` items (``--aux``) as ``{NAME: COLUMN}``, spaces around each trimmed.

    Raises
    ------
    InputError
        An item without ``=`` or with an empty side, or a name given twice.
    """
    out: dict[str, str] = {}
    for item in items:
        name, sep, column = item.partition("=")
        if not sep or not name.strip() or not column.strip():
            raise InputError(f"--aux {item!r}: write NAME=COLUMN, e.g. --aux drive=drive_amp_v")
        if name.strip() in out:
            raise InputError(f"--aux {name.strip()!r} given twice")
        out[name.strip()] = column.strip()
    return out


def candidate_terms(terms: Iterable[str], aux: Mapping[str, str] | None,
                    heads: Sequence[Any]) -> tuple[str, ...]:
    """The drift fit's candidates: ``terms``, plus ``a_NAME`` for each mapped channel.

    Every training run must log each mapped column (the error names the file and the
    column); gradient terms (``g``) need ``housing_c`` in every run.
    """
    out = [str(t) for t in terms]
    used = {v for t in parse_terms(out) for v in t.variables}
    for name, column in dict(aux or {}).items():
        if not AUX_NAME.match(str(name)):
            raise InputError(f"--aux name {name!r} is not usable; use a letter followed by "
                             "letters or digits, e.g. --aux drive=drive_amplitude_v")
        for head in heads:
            if column not in head:
                raise InputError(f"{head.source}: no column {column!r} for --aux "
                                 f"{name}={column}; columns: {', '.join(head.names)}")
        if f"a_{name}" not in used:
            out.append(f"a_{name}")
    if "g" in used:
        for head in heads:
            if "housing_c" not in head:
                raise InputError(f"{head.source}: no column 'housing_c', which the gradient "
                                 "terms (g) need; drop them or log the housing thermistor")
    return tuple(out)


def resolve_terms(terms: Iterable[str] | None, aux: Mapping[str, str] | None,
                  heads: Sequence[Any]) -> tuple[str, ...]:
    """The candidates of a drift fit: ``terms``, or by default the gradient set when every
    training run logs ``housing_c`` (Eq. 21's nine otherwise), and the ``--aux`` channels."""
    if terms is None:
        housed = all("housing_c" in head for head in heads)
        terms = GRADIENT_TERMS if housed else tuple(t.name for t in EQ21)
    return candidate_terms(terms, aux, heads)


#: Stepwise thresholds at which every candidate enters and none leaves: the history fit
#: refits the base model's terms with a history term added, without choosing them again.
ALL_IN = {"select": "stepwise", "penter": 0.9999, "premove": 0.99999}


@dataclass(frozen=True)
class HistoryChoice:
    """The thermal-history terms added to a fit's selection (:func:`add_history`).

    Attributes
    ----------
    model
        The model kept: the base model when no history term won.
    base
        The base model (today's candidates and selection).
    added
        The history terms kept, in the order they were added (``()``: none).
    play_width_c
        The play's width the scores chose (whether or not ``play`` was kept). [°C]
    scores
        Leave-one-run-out score of each model tried (``"base"``, ``"play w=2"``,
        ``"+gsat"``). [°/h]
    """

    model: Any
    base: Any
    added: tuple[str, ...]
    play_width_c: float
    scores: dict[str, float]


def _score(drift: Any) -> float:
    """The drift fit's leave-one-run-out score; inf without one (a single training run)."""
    validation = drift.cross_validation
    value = math.inf if validation is None else float(validation.score_dph)
    return value if math.isfinite(value) else math.inf


def add_history(fit: Callable[[Mapping[str, Any]], Any],
                widths: Sequence[float] | None = None, axis: str = "") -> HistoryChoice:
    """Thermal-history terms added to a fit's selection, each kept only if it wins
    leave-one-run-out (docs/history.md, "Why the worst runs").

    The base model is ``fit({})``. At each play width of ``widths``
    (:func:`hrgtc.drift.variables.play.learn_width`) the terms are chosen again with
    ``play`` among the candidates, and the model refitted (:data:`ALL_IN`: no third
    choice) on those terms, the powers of ``f`` the base model chose, and ``play``; the
    width whose model has the lowest leave-one-run-out score is taken, and its model kept
    if that score beats the base model's. ``gsat`` is then tried on top of the model kept,
    on the same rule, where the base fit had the gradient ``g`` among its candidates
    (every run logs ``housing_c``).

    Why the powers of ``f`` of the base choice: on a campaign of soaks that all start at
    one temperature and ramps at one rate, ``play`` is nearly ``-w/2 sign(T - T_start)``
    on the soaks and ``-w/2 sign(dT/dt)`` on the ramps. Offered with the others, it stands
    in for an odd power of ``f`` (``f^3`` dropped), which held-out runs at other rates then
    punish; chosen without it, the gradient terms stand in for the memory (a spurious
    ``f^2*g``). So the level in ``f`` comes from the choice without ``play``, the rest
    from the choice with it.

    Parameters
    ----------
    fit
        ``fit(options)``: the fitted model (:class:`hrgtc.model.Model`) with the drift
        settings ``options`` (fields of :class:`hrgtc.settings.drift.DriftSettings` by name)
        over the caller's own; ``{}`` is the base fit.
    widths
        The play widths judged. [°C] Default :data:`hrgtc.drift.variables.play.WIDTHS_C`.
    axis
        The axis whose drift model is judged (``""``: a single-axis unit's).

    A fit without a leave-one-run-out score (one training run) keeps no history term: on
    one run nothing says the memory carries over.
    """
    from hrgtc.drift.variables.play import WIDTHS_C, learn_width

    def drift(model: Any) -> Any:
        return model.axes[axis].drift

    base = fit({})
    scores = {"base": _score(drift(base))}
    chosen, added = base, ()
    selected = tuple(drift(base).selected)
    models: dict[float, Any] = {}

    candidates = (*drift(base).candidates, "play")
    powers = {t.name for t in parse_terms(selected) if set(t.variables) == {"f"}}

    def score(width: float) -> float:
        offered = drift(fit({"terms": candidates, "play_width_c": width})).selected
        keep = {*offered, *powers, "play"}
        terms = tuple(t for t in candidates if t in keep)
        models[width] = fit({**ALL_IN, "terms": terms, "play_width_c": width})
        scores[f"play w={width:g}"] = _score(drift(models[width]))
        return scores[f"play w={width:g}"]

    width = float(drift(base).settings.play_width_c)
    if math.isinf(scores["base"]):  # nothing to judge a history term by
        return HistoryChoice(base, base, (), width, scores)
    if "play" not in selected:
        width, _ = learn_width(score, WIDTHS_C if widths is None else widths)
        if scores[f"play w={width:g}"] < scores["base"]:
            chosen, added = models[width], ("play",)
    if "gsat" not in selected and "g" in drift(base).candidates:  # the runs log housing_c
        trial = fit({**ALL_IN, "terms": (*drift(chosen).selected, "gsat"),
                     "play_width_c": width})
        scores["+gsat"] = _score(drift(trial))
        if scores["+gsat"] < _score(drift(chosen)):
            chosen, added = trial, (*added, "gsat")
    return HistoryChoice(chosen, base, added, width, scores)
