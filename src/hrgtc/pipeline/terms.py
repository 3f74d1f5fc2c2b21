"""The candidate terms of a drift fit: the ``--terms`` given or the default set, and the
``a_NAME`` channels ``--aux NAME=COLUMN`` maps, checked against the training runs."""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.drift.features import AUX_NAME, EQ21, parse_terms
from hrgtc.settings.drift import GRADIENT_TERMS

__all__ = ["candidate_terms", "parse_aux", "resolve_terms"]


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
