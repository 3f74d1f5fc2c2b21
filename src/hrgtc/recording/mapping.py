"""Users' column names and units onto the recording contract of DESIGN.md.

* ``columns`` maps contract names to the file's names, e.g.
  ``{"time_s": "t", "freq_hz": "f_res", "rate_dph": "omega"}``, per-axis names
  included (``{"rate_dph_x": "gyro_x"}``, see :mod:`hrgtc.recording.axes`); other
  columns keep their names (numeric ones are kept, text columns dropped);
* ``units`` gives the units of ``time`` (``s``, ``ms``, ``us`` or ``timestamp``),
  ``freq`` (``Hz`` or ``kHz``) and ``rate`` (``dph`` = °/h, ``dps`` = °/s or
  ``radps`` = rad/s), converted to s, Hz and °/h: ``freq`` converts every
  ``freq_hz*`` column, ``rate`` every ``rate_dph*`` and ``input_rate_dph*``
  column. Timestamps (ISO 8601 text or date-time columns, which are recognised
  without being asked) become seconds since the first sample of the file;
* ``temp_scale`` and ``temp_offset_c`` turn a temperature logged as a raw sensor
  count into °C: ``temperature_c = raw * temp_scale + temp_offset_c`` for every
  ``temperature_c*`` column;
* ``thermometer="sensor"`` (a gyro without a frequency output): ``freq_hz`` (and
  ``freq_hz_<axis>``) is the temperature sensor's column ``temperature_c_<axis>``
  (or the shared ``temperature_c``), so no frequency column is needed.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from hrgtc.errors import InputError, RecordingError
from hrgtc.recording.axes import AXIS_COLUMNS, axis_names, base_name, split_axis
from hrgtc.recording.checks import check_thermometer
from hrgtc.recording.csv import bad_number_hint
from hrgtc.recording.formats import Source, first_failing
from hrgtc.recording.schema import COLUMNS

#: kind -> canonical unit -> accepted spellings (compared case-insensitively).
UNIT_SPELLINGS: dict[str, dict[str, tuple[str, ...]]] = {
    "time": {
        "s": ("s", "sec", "second", "seconds"),
        "ms": ("ms", "msec", "millisecond", "milliseconds"),
        "us": ("us", "µs", "μs", "usec", "microsecond", "microseconds"),
        "timestamp": ("timestamp", "datetime", "iso", "iso8601"),
    },
    "freq": {"Hz": ("hz",), "kHz": ("khz",)},
    "rate": {
        "dph": ("dph", "°/h", "deg/h", "deg/hr", "°/hr"),
        "dps": ("dps", "°/s", "deg/s", "deg/sec"),
        "radps": ("radps", "rad/s", "rad/sec"),
    },
}
#: Contract column converted by each kind of unit.
UNIT_COLUMNS = {"time": "time_s", "freq": "freq_hz", "rate": "rate_dph"}
#: Kind of unit of each contract column (per-axis columns by their contract name).
UNIT_KINDS = {"time_s": "time", "freq_hz": "freq", "rate_dph": "rate", "input_rate_dph": "rate"}


def to_contract_unit(values: np.ndarray, unit: str) -> np.ndarray:
    """Convert values in a canonical unit to the contract's s, Hz or °/h.

    ``ms`` / 1000, ``us`` / 10^6, ``kHz`` × 1000, ``dps`` × 3600, ``radps`` × (180/π) × 3600;
    ``s``, ``Hz`` and ``dph`` unchanged (same array).
    """
    if unit == "ms":
        return values / 1000.0
    if unit == "us":
        return values / 1e6
    if unit == "kHz":
        return values * 1000.0
    if unit == "dps":
        return values * 3600.0
    if unit == "radps":
        return values * (180.0 / math.pi) * 3600.0
    return values


def parse_unit(kind: str, text: str) -> str:
    """Canonical unit name (``"s"``, ``"kHz"``, ``"dps"``, ...) of a spelling.

    Parameters
    ----------
    kind
        ``"time"``, ``"freq"`` or ``"rate"``.
    text
        A spelling such as ``"kHz"``, ``"°/s"``, ``"rad/s"`` or ``"ms"``.
    """
    if kind not in UNIT_SPELLINGS:
        raise InputError(f"unknown unit kind {kind!r}; use one of {list(UNIT_SPELLINGS)}")
    wanted = str(text).strip().lower().replace(" ", "")
    for canonical, spellings in UNIT_SPELLINGS[kind].items():
        if wanted == canonical.lower() or wanted in spellings:
            return canonical
    known = ", ".join(UNIT_SPELLINGS[kind])
    raise InputError(f"unknown {kind} unit {text!r}; use one of {known}")


def parse_units(units: Mapping[str, str] | None) -> dict[str, str]:
    """``{"time"|"freq"|"rate": spelling}`` -> canonical units (missing kinds left out)."""
    return {kind: parse_unit(kind, text) for kind, text in (units or {}).items()}


def parse_columns(pairs: Mapping[str, str] | Iterable[str] | None) -> dict[str, str]:
    """A column mapping from a mapping or from ``"time_s=t"`` strings (commas allowed).

    Keys must be contract column names (see :data:`hrgtc.recording.COLUMNS`) or
    per-axis ones (``freq_hz_x``, see :mod:`hrgtc.recording.axes`).
    """
    if pairs is None:
        return {}
    if isinstance(pairs, Mapping):
        items = [(str(k), str(v)) for k, v in pairs.items()]
    else:
        items = []
        for text in pairs:
            for part in str(text).split(","):
                name, sep, theirs = part.partition("=")
                if not sep or not name.strip() or not theirs.strip():
                    raise InputError(
                        f"column mapping {part!r} is not NAME=THEIRS; e.g. --col freq_hz=f_res"
                    )
                items.append((name.strip(), theirs.strip()))
    mapping: dict[str, str] = {}
    for name, theirs in items:
        if not is_contract_name(name):
            hint = difflib.get_close_matches(name, COLUMNS, n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise InputError(
                f"column mapping {name}={theirs}: {name!r} is not a recording column{did}; "
                f"use one of {list(COLUMNS)} or a per-axis name <name>_<axis> for a name in "
                f"{list(AXIS_COLUMNS)} (e.g. freq_hz_x)"
            )
        mapping[name] = theirs
    return mapping


def is_contract_name(name: str, axes: Iterable[str] | None = None) -> bool:
    """True for a column of the recording contract, per-axis ones (``rate_dph_x``) included.

    With ``axes`` a per-axis name counts only for one of them (see
    :func:`hrgtc.recording.axes.axis_names`).
    """
    axis = split_axis(name)[1]
    return name in COLUMNS or (axis is not None and (axes is None or axis in axes))


# -- from the file's columns to the contract's ----------------------------------
@dataclass
class ColumnPlan:
    """Which file columns to read, under which names, converted how."""

    source: Source
    pairs: list[tuple[str, str]]  # (file name, recording name)
    as_text: set[str]
    units: dict[str, str]
    time_is_timestamp: bool
    time_origin_ns: int | None = None
    time_origin_s: float | None = None
    read_names: list[str] = field(default_factory=list)
    temp_scale: float = 1.0
    temp_offset_c: float = 0.0
    thermometer: str = "resonator"
    axes: tuple[str, ...] = ()


def plan_columns(source: Source, columns: Any, units: Mapping[str, str] | None,
                 temp_scale: float = 1.0, temp_offset_c: float = 0.0,
                 thermometer: str = "resonator") -> ColumnPlan:
    """Decide which of the file's columns become which recording columns, in which unit.

    Contract columns come first in the order of :data:`hrgtc.recording.COLUMNS`
    (per-axis ones by their contract name, in file order), then the file's other
    numeric columns under their own names.
    """
    mapping = parse_columns(columns)
    canon = parse_units(units)
    check_thermometer(thermometer)
    for name, value in (("temp_scale", temp_scale), ("temp_offset_c", temp_offset_c)):
        usable = isinstance(value, int | float) and math.isfinite(value)
        if not usable or (name == "temp_scale" and value == 0):
            raise InputError(f"{name} must be a finite number (a scale other than 0), got "
                             f"{value!r}; --temp-scale K --temp-offset C give "
                             "temperature_c = raw * K + C")
    for name, theirs in mapping.items():
        if theirs not in source.names:
            hint = difflib.get_close_matches(theirs, source.names, n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise RecordingError(
                f"{source.path}: column {theirs!r} (given for {name}) not found{did}; "
                f"the file's columns are {source.names}"
            )
    kinds = source.kinds()
    pairs = [(theirs, name) for name, theirs in mapping.items()]
    axes = axis_names([*mapping, *(n for n in source.names if n not in mapping.values())])
    pairs += [(n, n) for n in source.names if is_contract_name(n, axes) and n not in mapping]
    order = {name: i for i, name in enumerate(COLUMNS)}
    pairs.sort(key=lambda pair: order.get(base_name(pair[1], axes), len(order)))
    used = {theirs for theirs, _ in pairs}
    pairs += [
        (n, n)
        for n in source.names
        if not is_contract_name(n, axes) and n not in used and kinds.get(n) == "numeric"
    ]
    if thermometer == "sensor":
        _check_sensor_columns(source, [name for _, name in pairs])
    time_file = next((theirs for theirs, name in pairs if name == "time_s"), None)
    time_kind = kinds.get(time_file or "", "numeric")
    stamped = canon.get("time") == "timestamp" or time_kind == "timestamp"
    as_text = {time_file} if stamped and time_kind != "numeric" and time_file else set()
    for theirs, name in pairs:
        kind = kinds.get(theirs)
        if name != "time_s" and kind in ("timestamp", "other"):
            raise RecordingError(
                f"{source.path}: column {theirs!r} ({name}) holds {kind} values, not numbers; "
                "map another column to it"
            )
    names = list(dict.fromkeys(theirs for theirs, _ in pairs))
    return ColumnPlan(source, pairs, as_text, canon, stamped, read_names=names, axes=axes,
                      temp_scale=float(temp_scale), temp_offset_c=float(temp_offset_c),
                      thermometer=thermometer)


def _check_sensor_columns(source: Source, names: list[str]) -> None:
    """The temperature column of every axis, for the sensor thermometer."""
    for axis in axis_names(names) or (None,):
        own = f"temperature_c_{axis}" if axis else "temperature_c"
        if own not in names and "temperature_c" not in names:
            raise RecordingError(
                f"{source.path}: --thermometer sensor needs the gyro's temperature column "
                f"{own!r} (or a shared 'temperature_c'), not found among {source.names}; map "
                f"yours with --col {own}=<your column> (a raw count: add --temp-scale and "
                "--temp-offset)"
            )


def sensor_frequency(columns: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``freq_hz`` (``freq_hz_<axis>``) filled with the temperature sensor's column (no copy).

    For a gyro without a frequency output (``thermometer="sensor"``): the
    temperature ``temperature_c_<axis>`` of each axis, or the shared
    ``temperature_c``, takes the place of the resonator frequency. [°C]
    """
    for axis in axis_names(columns) or (None,):
        suffix = f"_{axis}" if axis else ""
        columns[f"freq_hz{suffix}"] = columns.get(f"temperature_c{suffix}",
                                                   columns.get("temperature_c"))
    return columns


def _is_text(column: pa.ChunkedArray) -> bool:
    return pa.types.is_string(column.type) or pa.types.is_large_string(column.type)


def _to_float(
    plan: ColumnPlan, column: pa.ChunkedArray, theirs: str, row_offset: int
) -> np.ndarray:
    if _is_text(column):
        try:
            column = column.cast(pa.float64())
        except (pa.ArrowInvalid, pa.ArrowTypeError):
            i = first_failing(column, lambda a: a.cast(pa.float64()))
            value = str(column[i].as_py())
            raise RecordingError(
                f"{plan.source.path}: column {theirs!r}, row {row_offset + i}: {value!r} is not "
                f"a number; {bad_number_hint(value)}"
            ) from None
    if not pa.types.is_floating(column.type):
        column = pc.cast(column, pa.float64(), safe=False)
    return float_values(column)


def float_values(column: pa.ChunkedArray) -> np.ndarray:
    """A float column as a contiguous float64 array, without a copy where it can.

    A float64 chunk without nulls is viewed in place (``np.frombuffer`` of its data
    buffer); pyarrow's ``to_numpy`` would first import pandas (~0.5 s) to do the same.
    """
    parts = []
    for chunk in column.chunks:
        if chunk.type == pa.float64() and chunk.null_count == 0:
            parts.append(np.frombuffer(chunk.buffers()[1], dtype=np.float64,
                                       count=len(chunk), offset=chunk.offset * 8))
        else:
            parts.append(np.asarray(chunk.to_numpy(zero_copy_only=False), dtype=np.float64))
    if len(parts) == 1:
        return parts[0]
    return np.concatenate(parts) if parts else np.empty(0)


def _timestamps_ns(plan: ColumnPlan, column: pa.ChunkedArray, theirs: str, row_offset: int) -> Any:
    if pa.types.is_date(column.type):
        return column.cast(pa.timestamp("ns"))
    if not _is_text(column):
        return column.cast(pa.timestamp("ns", tz=getattr(column.type, "tz", None)))
    naive, utc = pa.timestamp("ns"), pa.timestamp("ns", tz="UTC")
    try:
        return column.cast(naive)
    except (pa.ArrowInvalid, pa.ArrowTypeError) as exc:
        target = utc if "zone offset" in str(exc) else naive
    try:
        return column.cast(target)
    except (pa.ArrowInvalid, pa.ArrowTypeError):
        i = first_failing(column, lambda a: a.cast(target))
    value = column[i].as_py()
    raise RecordingError(
        f"{plan.source.path}: column {theirs!r}, row {row_offset + i}: {value!r} is not an "
        "ISO 8601 timestamp (like the first rows, e.g. 2024-05-01T12:00:00.005); fix that row"
    )


def _time_seconds(
    plan: ColumnPlan, column: pa.ChunkedArray, theirs: str, row_offset: int
) -> np.ndarray:
    if not plan.time_is_timestamp:
        seconds = _to_float(plan, column, theirs, row_offset)
        return to_contract_unit(seconds, plan.units.get("time", "s"))
    if pa.types.is_floating(column.type) or pa.types.is_integer(column.type):
        seconds = _to_float(plan, column, theirs, row_offset)  # epoch seconds
        if plan.time_origin_s is None:
            finite = seconds[np.isfinite(seconds)]
            plan.time_origin_s = float(finite[0]) if finite.size else None
        return seconds - (plan.time_origin_s or 0.0)
    stamps = _timestamps_ns(plan, column, theirs, row_offset).cast(pa.int64())
    valid = ~np.asarray(stamps.is_null().to_numpy(zero_copy_only=False), dtype=bool)
    ns = np.asarray(stamps.fill_null(0).to_numpy(zero_copy_only=False), dtype=np.int64)
    if plan.time_origin_ns is None and valid.any():
        plan.time_origin_ns = int(ns[np.argmax(valid)])
    seconds = (ns - (plan.time_origin_ns or 0)) / 1e9
    seconds[~valid] = np.nan
    return seconds


def table_columns(table: pa.Table) -> dict[str, pa.ChunkedArray]:
    """The columns of ``table`` by name (a dict that :func:`convert_columns` empties)."""
    return {name: table.column(name) for name in table.column_names}


def convert_columns(
    plan: ColumnPlan, columns: dict[str, pa.ChunkedArray], row_offset: int
) -> dict[str, np.ndarray]:
    """Float64 arrays in the contract's names and units from the file's columns.

    ``columns`` is emptied as the columns are converted, so the peak memory is
    the columns read plus one converted column.
    """
    last_use = {theirs: i for i, (theirs, _) in enumerate(plan.pairs)}
    out: dict[str, np.ndarray] = {}
    for i, (theirs, name) in enumerate(plan.pairs):
        column = columns[theirs] if last_use[theirs] > i else columns.pop(theirs)
        if name == "time_s":
            out[name] = _time_seconds(plan, column, theirs, row_offset)
        else:
            values = _to_float(plan, column, theirs, row_offset)
            base = base_name(name, plan.axes)
            kind = UNIT_KINDS.get(base)
            out[name] = to_contract_unit(values, plan.units.get(kind, "")) if kind else values
            if base == "temperature_c" and (plan.temp_scale != 1.0 or plan.temp_offset_c != 0.0):
                out[name] = out[name] * plan.temp_scale + plan.temp_offset_c
        del column
    return sensor_frequency(out) if plan.thermometer == "sensor" else out
