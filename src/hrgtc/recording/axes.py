"""Multi-axis recordings: one file, several gyros (axes) sharing a clock and a chamber.

An inertial measurement unit has three (or four, skewed) gyros, each with its own
resonator. Its recording holds the per-axis columns ``<name>_<axis>`` for every
``name`` in :data:`AXIS_COLUMNS` (``freq_hz_x``, ``rate_dph_x``, ...) and the
shared columns (``time_s``, ``chamber_c``, ``housing_c`` and any other). An axis
name is a letter followed by letters or digits (no underscore): ``x``, ``y``,
``z``; ``a`` .. ``d`` for a skewed four-axis unit. A file is multi-axis when it
has ``rate_dph_<axis>`` columns; a single-axis file is unchanged.

:func:`axis_view` gives the recording of one axis in the single-axis contract
(``freq_hz_x`` -> ``freq_hz``, ...), without copying, so every single-axis
function (thermometry, drift, compensation, evaluation) works on it. The other
axes' ``freq_hz_<other>`` and ``temperature_c_<other>`` stay in the view under
their suffixed names, for cross-axis terms (a temperature difference across the
unit). Constant per-axis input rates (the Earth-rate component on each axis) are
kept in ``metadata.extra["axis_input_rate_dph"] = {axis: rate}``.

Examples
--------
>>> axis_names(["time_s", "rate_dph_x", "freq_hz_x", "rate_dph_y", "freq_hz_y"])
('x', 'y')
>>> axis_names(["time_s", "freq_hz", "rate_dph"])
()
>>> split_axis("input_rate_dph_z")
('input_rate_dph', 'z')
>>> base_name("resonator_c_est", axes=())
'resonator_c_est'
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Iterable, Mapping

from hrgtc.core.errors import RecordingError
from hrgtc.recording.schema import Metadata, Recording

#: Contract columns that a multi-axis recording has once per axis, as ``<name>_<axis>``.
AXIS_COLUMNS: tuple[str, ...] = (
    "freq_hz", "rate_dph", "input_rate_dph", "temperature_c", "resonator_c", "bias_dph",
    "scale_ppm",
)
#: Per-axis columns of the other axes that an axis view keeps (cross-axis terms).
CROSS_AXIS_COLUMNS: tuple[str, ...] = ("freq_hz", "temperature_c")
#: Metadata ``extra`` key of the constant per-axis input rates, ``{axis: rate_dph}``.
AXIS_INPUT_RATE_KEY = "axis_input_rate_dph"
AXIS_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9]*")
# longest names first, so that "input_rate_dph_x" is not read as "rate_dph" of axis "x"
_BY_LENGTH = sorted(AXIS_COLUMNS, key=len, reverse=True)
#: Names that look per-axis but are not: compensation's estimate of the resonator
#: temperature (``resonator_c_est`` is not ``resonator_c`` of an axis ``est``).
NOT_PER_AXIS = frozenset({"resonator_c_est"})

__all__ = [
    "AXIS_COLUMNS", "AXIS_INPUT_RATE_KEY", "CROSS_AXIS_COLUMNS", "axis_input_rate_dph",
    "axis_names", "axis_view", "base_name", "split_axis",
]


def split_axis(name: str) -> tuple[str, str | None]:
    """``(contract name, axis)`` of a column name; ``(name, None)`` if it is not per-axis.

    Parameters
    ----------
    name
        A column name such as ``"freq_hz_x"`` or ``"chamber_c"``.
    """
    if name in NOT_PER_AXIS:
        return name, None
    for base in _BY_LENGTH:
        if name.startswith(base + "_"):
            axis = name[len(base) + 1:]
            if AXIS_PATTERN.fullmatch(axis):
                return base, axis
    return name, None


def base_name(name: str, axes: Iterable[str]) -> str:
    """The single-axis contract name of a column of a recording with ``axes``.

    ``"rate_dph_x"`` -> ``"rate_dph"`` when ``"x"`` is one of ``axes`` (see
    :func:`axis_names`); any other name unchanged, so that a column such as
    ``resonator_c_est`` of a single-axis recording is not taken for an axis's.
    """
    base, axis = split_axis(name)
    return base if axis is not None and axis in axes else name


def axis_names(names: Iterable[str]) -> tuple[str, ...]:
    """The axes of a recording (or file) from its column names, in file order.

    Parameters
    ----------
    names
        Column names.

    Returns
    -------
    tuple of str
        The ``<axis>`` of every ``rate_dph_<axis>`` column, in the order of the
        columns; ``()`` for a single-axis recording.
    """
    axes: list[str] = []
    for name in names:
        base, axis = split_axis(name)
        if base == "rate_dph" and axis is not None and axis not in axes:
            axes.append(axis)
    return tuple(axes)


def axis_input_rate_dph(metadata: Metadata, axis: str | None) -> float:
    """Constant known input rate on ``axis`` (the metadata's ``input_rate_dph`` without one). [°/h]

    From ``metadata.extra["axis_input_rate_dph"][axis]`` when given, else the
    metadata's ``input_rate_dph``.
    """
    rates = metadata.extra.get(AXIS_INPUT_RATE_KEY)
    if axis is None or not isinstance(rates, Mapping) or axis not in rates:
        return metadata.input_rate_dph
    value = rates[axis]
    try:
        rate = float(value)
    except (TypeError, ValueError):
        rate = math.nan
    if not math.isfinite(rate):
        raise RecordingError(
            f"metadata extra {AXIS_INPUT_RATE_KEY}[{axis!r}] is {value!r}, not a finite number "
            "of °/h; fix it in the file's metadata"
        )
    return rate


def axis_view(recording: Recording, axis: str) -> Recording:
    """The recording of one axis of a multi-axis recording, in the single-axis contract.

    Parameters
    ----------
    recording
        A multi-axis recording (``rate_dph_<axis>`` columns).
    axis
        One of :func:`axis_names` of the recording.

    Returns
    -------
    Recording
        ``<name>_<axis>`` renamed ``<name>``; shared columns kept; the other axes'
        columns dropped except ``freq_hz_<other>`` and ``temperature_c_<other>``
        (kept under their names). The metadata's ``input_rate_dph`` is the axis's
        (``extra["axis_input_rate_dph"][axis]``), ``extra["axis"]`` is ``axis``.
        The arrays are the recording's own (no copies).

    Raises
    ------
    RecordingError
        A single-axis recording, or an axis the recording does not have.
    """
    axes = axis_names(recording.names)
    where = f"{recording.source}: " if recording.source else ""
    if not axes:
        raise RecordingError(
            f"{where}axis {axis!r} asked of a single-axis recording (no rate_dph_<axis> "
            f"columns; columns {list(recording.names)}); use the recording as it is, or map "
            f"per-axis columns with --col rate_dph_{axis}=<your column>"
        )
    if axis not in axes:
        raise RecordingError(
            f"{where}no axis {axis!r} in the recording; its axes are {list(axes)}"
        )
    columns = {}
    for name in recording.names:
        base, other = split_axis(name)
        if other == axis:
            columns[base] = recording[name]
        elif other is None or other not in axes:
            columns.setdefault(name, recording[name])  # shared (an axis's own column wins)
        elif base in CROSS_AXIS_COLUMNS:
            columns[name] = recording[name]
    meta = recording.metadata
    extra = {**meta.extra, "axis": axis}
    metadata = dataclasses.replace(
        meta, input_rate_dph=axis_input_rate_dph(meta, axis), extra=extra)
    return Recording(columns, metadata, recording.source)
