"""A model's axes against a recording's: which axes a recording has, ``--axes``, and the
model's axes to apply (:func:`match_axes`), for compensation, evaluation and the report.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

from hrgtc import recording as rec_io
from hrgtc.core.errors import InputError
from hrgtc.model import Model
from hrgtc.recording import axis_names
from hrgtc.recording.axes import AXIS_PATTERN

__all__ = ["match_axes", "parse_axes", "recording_axes"]


def recording_axes(path: str | os.PathLike[str],
                   options: rec_io.ReadOptions | None = None) -> tuple[str, ...] | None:
    """Axis names of a recording file as read with ``options`` (its column mapping); ()
    for a single-axis file. Reads the file's column names only; None when the file cannot
    be opened (reading it will say why)."""
    from hrgtc.core.errors import HrgtcError
    from hrgtc.recording.mapping import check_axis_sets, parse_columns, with_other_case

    try:
        mapping = parse_columns((options or rec_io.ReadOptions()).columns)
        with rec_io.open_source(path) as source:
            if not mapping and _header_less(source.names):
                return None  # no axis can be told: reading says the header line is missing
            mapping = with_other_case(mapping, source.names)  # as reading maps them
            names = [*mapping, *(n for n in source.names if n not in mapping.values())]
            axes = tuple(axis_names(names))
            # an incomplete axis (freq_hz_z without rate_dph_z) is the reading's error to
            # name, not an axis mismatch with the model (issue 21)
            check_axis_sets(source, names, axes, mapping)
    except (HrgtcError, OSError, ValueError):
        return None
    return axes


def _header_less(names: Sequence[str]) -> bool:
    """True for the names a CSV without a header line gets (``column_1``, ``column_2``, ...)."""
    return bool(names) and all(n == f"column_{i}" for i, n in enumerate(names, start=1))


def parse_axes(text: str | Sequence[str] | None) -> tuple[str, ...] | None:
    """``"x,y"`` (the ``--axes`` option) -> ``("x", "y")``; None or empty: None."""
    if text is None:
        return None
    items = text.split(",") if isinstance(text, str) else list(text)
    names = tuple(a.strip() for a in items if a.strip())
    bad = [a for a in names if not AXIS_PATTERN.fullmatch(a)]
    if bad:
        raise InputError(f"--axes {','.join(names)}: {bad[0]!r} is not an axis name (a letter, "
                         "then letters or digits, as the column suffixes: --axes x,y)")
    return names or None


def match_axes(model: Model, recording_axes: Sequence[str] | None,
               axes: Sequence[str] | None = None, source: str = "",
               model_source: str = "") -> Model:
    """The model's axes to apply to a recording with ``recording_axes``: all of each, or
    those ``axes`` names.

    A model and a recording must have the same axes: a recording axis the model lacks
    would pass through uncompensated, a model axis the recording lacks has nothing to
    compensate. Either is an error unless ``axes`` (``--axes``) says which to
    compensate. A single-axis model applies to one axis of a multi-axis recording only
    when ``axes`` names it (then it is that axis's model, its outputs suffixed).

    Raises
    ------
    InputError
        The axis sets differ and ``axes`` does not say which, or ``axes`` names an axis
        the model or the recording lacks.
    """
    if recording_axes is None:  # the file cannot be opened: reading it will say why
        return model
    found = tuple(recording_axes)
    named = tuple(a for a in model.names if a)
    where = f"the recording {source}" if source else "the recording"
    of_model = f"the model {model_source or repr(model.unit)}"
    has = f"has axes {', '.join(found)}" if found else "is single-axis"
    if axes:
        axes = tuple(axes)
        lacking = [a for a in axes if a not in found]
        if lacking:
            raise InputError(f"--axes {','.join(axes)}: {where} has no axis "
                             f"{', '.join(lacking)} (it {has})")
        if model.is_single_axis:
            if len(axes) != 1:
                raise InputError(f"--axes {','.join(axes)}: {of_model} is single-axis; name "
                                 "the one recording axis to compensate with it")
            return Model({axes[0]: model.axes[""]}, model.unit,
                                   dict(model.provenance), model.temperature_map)
        unknown = [a for a in axes if a not in named]
        if unknown:
            raise InputError(f"--axes {','.join(axes)}: {of_model} has no axis "
                             f"{', '.join(unknown)} (its axes: {', '.join(named)})")
        return Model({a: model.axes[a] for a in axes}, model.unit,
                               dict(model.provenance), model.temperature_map)
    if model.is_single_axis and not found:
        return model
    if model.is_single_axis:
        raise InputError(f"{where} {has} and {of_model} is single-axis: pass --axes "
                         f"{found[0]} (one of {', '.join(found)}) to compensate that axis with "
                         "it, or use the instrument's multi-axis model")
    if not found:
        raise InputError(f"{where} is single-axis (freq_hz, rate_dph) and {of_model} has "
                         f"axes {', '.join(named)}: compensate each axis's recording with a "
                         "single-axis model, or name the columns by axis (rate_dph_x, ...)")
    extra = [a for a in found if a not in named]
    missing = [a for a in named if a not in found]
    if extra or missing:
        common = [a for a in named if a in found]
        what = (f"axis {', '.join(extra)} of the recording would be left uncompensated"
                if extra else f"the model's axis {', '.join(missing)} is not in the recording")
        hint = (f"pass --axes {','.join(common)} to compensate only those" if common else
                "is it another instrument's model?")
        raise InputError(f"{where} {has} but {of_model} has axes {', '.join(named)}: {what}; "
                         f"{hint}")
    return model
