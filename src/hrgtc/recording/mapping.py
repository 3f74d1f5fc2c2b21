"""Users' column names and units onto the recording contract of DESIGN.md.

* ``columns`` maps contract names to the file's names, e.g.
  ``{"time_s": "t", "freq_hz": "f_res", "rate_dph": "omega"}``, per-axis names
  included (``{"rate_dph_x": "gyro_x"}``, see :mod:`hrgtc.recording.axes`); other
  columns keep their names (numeric ones are kept, text columns dropped). Axis sets
  are explicit: a per-axis column of an axis without ``rate_dph_<axis>`` is an error
  (:func:`check_axis_sets`), one shared ``temperature_c`` is legal;
* ``units`` gives the units of ``time`` (``s``, ``ms``, ``us``, ``ns`` or
  ``timestamp``), ``freq`` (``Hz`` or ``kHz``), ``rate`` (``dph`` = °/h, ``dps`` =
  °/s, ``mdps`` = m°/s, ``radps`` = rad/s, ``mradps`` = mrad/s, ``drad``/``ddeg`` =
  an angle increment per sample, ``lsb`` = a raw count with ``rate_scale`` LSB per
  °/s) and ``temp`` (``C``, ``F``, ``K`` or ``count``), converted to s, Hz, °/h and °C
  by the one table of :mod:`hrgtc.recording.units`: ``freq`` converts every
  ``freq_hz*`` column, ``rate`` every ``rate_dph*`` and ``input_rate_dph*`` column,
  ``temp`` °F and K every temperature column. Timestamps (ISO 8601 text or
  date-time columns, which are recognised without being asked) become seconds since
  the first sample of the file;
* ``temp_scale`` and ``temp_offset_c`` turn a temperature logged as a raw sensor
  count into °C: ``temperature_c = raw * temp_scale + temp_offset_c`` for every
  ``temperature_c*`` column; a raw count that sits just under 2^16 or 2^32 is a
  signed count stored unsigned and is unwrapped first (``temp_unwrap``);
* ``thermometer="sensor"`` (a gyro without a frequency output): ``freq_hz`` (and
  ``freq_hz_<axis>``) is the temperature sensor's column ``temperature_c_<axis>``
  (or the shared ``temperature_c``), so no frequency column is needed.
"""

from __future__ import annotations

import difflib
import math
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from hrgtc.core.errors import InputError, RecordingError, UnitWarning
from hrgtc.recording.accelerometer import find_accelerometer
from hrgtc.recording.axes import AXIS_COLUMNS, axis_names, base_name, split_axis
from hrgtc.recording.checks import check_thermometer
from hrgtc.recording.formats.base import Source, first_failing
from hrgtc.recording.formats.csv import bad_number_hint
from hrgtc.recording.schema import COLUMNS
from hrgtc.recording.temperature_count import map_problem, unwrap_count, wrapped_count_bits
from hrgtc.recording.time_axis import ZoneClock, check_zone
from hrgtc.recording.units import UNITS, find_unit, median_period, per_sample_steps, unit_of
from hrgtc.settings.reading import TEMP_UNWRAPS, ReadSettings

_READ = ReadSettings


def scales_temperature(temp_scale: float, temp_offset_c: float) -> bool:
    """True when ``temp_scale``/``temp_offset_c`` differ from the defaults (the identity):
    ``temperature_c*`` is then a raw count mapped to °C."""
    return (temp_scale, temp_offset_c) != (_READ.temp_scale, _READ.temp_offset_c)

#: kind -> canonical unit -> accepted spellings (compared case-insensitively); from
#: the one table of units, :data:`hrgtc.recording.units.UNITS`.
UNIT_SPELLINGS: dict[str, dict[str, tuple[str, ...]]] = {}
for _unit in UNITS:
    UNIT_SPELLINGS.setdefault(_unit.kind, {})[_unit.name] = _unit.spellings
#: Contract column converted by each kind of unit.
UNIT_COLUMNS = {"time": "time_s", "freq": "freq_hz", "rate": "rate_dph", "temp": "temperature_c"}
#: Kind of unit of each contract column (per-axis columns by their contract name).
UNIT_KINDS = {"time_s": "time", "freq_hz": "freq", "rate_dph": "rate", "input_rate_dph": "rate",
              "temperature_c": "temp", "chamber_c": "temp", "housing_c": "temp",
              "resonator_c": "temp"}
_PLAIN_UNITS = {u.name: u for u in UNITS if not (u.per_sample or u.scaled)}


def to_contract_unit(values: np.ndarray, unit: str) -> np.ndarray:
    """Convert values in a canonical unit to the contract's s, Hz, °/h or °C.

    The factors of :data:`hrgtc.recording.units.UNITS` (``ms`` / 1000, ``kHz`` × 1000,
    ``radps`` × 648000/π, ``F`` (F − 32) × 5/9, ...); the contract's own units, an
    unknown name and the units that need time steps or a scale unchanged (same array).
    """
    found = _PLAIN_UNITS.get(unit)
    return values if found is None else found.apply(values)


def parse_unit(kind: str, text: str) -> str:
    """Canonical unit name (``"s"``, ``"kHz"``, ``"mradps"``, ``"F"``, ...) of a spelling.

    Parameters
    ----------
    kind
        ``"time"``, ``"freq"``, ``"rate"`` or ``"temp"``.
    text
        A spelling such as ``"kHz"``, ``"°/s"``, ``"mrad/s"``, ``"ms"`` or ``"°F"``.
    """
    return find_unit(kind, text).name


def parse_units(units: Mapping[str, str] | None) -> dict[str, str]:
    """``{"time"|"freq"|"rate"|"temp": spelling}`` -> canonical units (missing kinds left out)."""
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
    temp_scale: float = _READ.temp_scale
    temp_offset_c: float = _READ.temp_offset_c
    thermometer: str = _READ.thermometer
    axes: tuple[str, ...] = ()
    rate_scale: float | None = _READ.rate_scale
    temp_unwrap: str = _READ.temp_unwrap
    previous_time_s: float | None = None
    period_s: float | None = None
    wrap_bits: int | None = None
    wrap_decided: bool = False
    tz: str | None = None  # --tz: the zone naive clock times were written in
    time_aware: bool = False  # the clock times carry their zone (UTC, an offset, epoch)
    zone_clock: Any = None  # its ZoneClock (hrgtc.recording.time_axis), state across chunks
    #: Columns found by their common names, not mapped by the user (the accelerometer's)
    found: dict[str, str] = field(default_factory=dict)
    #: What the count map gave when no thermometer reads that (:func:`map_problem`): the
    #: reader raises it before any impossible-value check judges the mapped values.
    map_problem: str | None = None
    map_checked: bool = False

    def only(self, bases: Iterable[str]) -> ColumnPlan:
        """This plan reading only the columns whose contract name (without its axis) is
        one of ``bases``, plus the temperature a sensor thermometer's ``freq_hz`` is
        filled from (:func:`sensor_frequency`); the file's other columns are not read."""
        wanted = set(bases)
        if self.thermometer == "sensor":
            wanted |= {"freq_hz", "temperature_c"}
        pairs = [(theirs, name) for theirs, name in self.pairs
                 if base_name(name, self.axes) in wanted]
        return replace(self, pairs=pairs, read_names=list(dict.fromkeys(t for t, _ in pairs)))

    @property
    def temperature_is_count(self) -> bool:
        """True when ``temperature_c*`` holds a raw count (a count unit, a scale or an offset)."""
        return (self.units.get("temp") == "count"
                or scales_temperature(self.temp_scale, self.temp_offset_c))


def plan_columns(source: Source, columns: Any, units: Mapping[str, str] | None,
                 temp_scale: float = _READ.temp_scale,
                 temp_offset_c: float = _READ.temp_offset_c,
                 thermometer: str = _READ.thermometer, rate_scale: float | None = _READ.rate_scale,
                 temp_unwrap: str = _READ.temp_unwrap,
                 tz: str | None = _READ.tz) -> ColumnPlan:
    """Decide which of the file's columns become which recording columns, in which unit.

    Contract columns come first in the order of :data:`hrgtc.recording.COLUMNS`
    (per-axis ones by their contract name, in file order), then the file's other
    numeric columns under their own names. ``rate_scale`` is the LSB per °/s of a
    rate logged as a raw count (``units={"rate": "lsb"}``); ``temp_unwrap``
    (``"auto"`` or ``"off"``) whether a raw temperature count that sits just
    under 2^16 or 2^32 is read as a signed count stored unsigned (``"16"``, ``"32"``:
    always, as a model's temperature map says). ``tz``: the IANA zone the naive clock
    times of the time column were written in (``--tz``): read as UTC, so a daylight
    saving step disappears (:class:`hrgtc.recording.time_axis.ZoneClock`).
    """
    mapping = parse_columns(columns)
    canon = parse_units(units)
    check_thermometer(thermometer)
    rate_unit = unit_of("rate", canon.get("rate", "dph"))
    if rate_unit.scaled:
        usable = isinstance(rate_scale, int | float) and math.isfinite(rate_scale)
        if not usable or rate_scale == 0:
            raise InputError(f"a rate logged as a raw count (--rate-unit lsb) needs its scale in "
                             f"LSB per °/s, a finite number other than 0, got {rate_scale!r}; "
                             "pass --rate-scale K from the datasheet (e.g. 131 for ±250 °/s "
                             "on 16 bits)")
    elif rate_scale is not None:
        raise InputError(f"--rate-scale {rate_scale!r} is the LSB per °/s of a raw count; give "
                         "it with --rate-unit lsb (the rate unit is "
                         f"{rate_unit.symbol})")
    if temp_unwrap not in TEMP_UNWRAPS:
        raise InputError(f"temp_unwrap must be 'auto', 'off', '16' or '32', got {temp_unwrap!r}")
    if canon.get("temp") not in (None, "C", "count") and scales_temperature(temp_scale,
                                                                            temp_offset_c):
        raise InputError(f"--temp-scale/--temp-offset map a raw count to °C; with --temp-unit "
                         f"{canon['temp']} the temperature is not a count: drop one of them")
    for name, value in (("temp_scale", temp_scale), ("temp_offset_c", temp_offset_c)):
        usable = isinstance(value, int | float) and math.isfinite(value)
        if not usable or (name == "temp_scale" and value == 0):
            raise InputError(f"{name} must be a finite number (a scale other than 0), got "
                             f"{value!r}; --temp-scale K --temp-offset C give "
                             "temperature_c = raw * K + C")
    for name, theirs in mapping.items():
        skipped = getattr(source, "skipped", {})
        if theirs not in source.names and theirs in skipped:
            raise RecordingError(
                f"{source.path}: dataset {theirs!r} (given for {name}) has shape "
                f"{skipped[theirs].shape}, not one value per row; store it as a 1-D dataset "
                "(each component of a matrix as its own column)")
        if theirs not in source.names:
            hint = difflib.get_close_matches(theirs, source.names, n=1)
            did = f" (did you mean {hint[0]!r}?)" if hint else ""
            raise RecordingError(
                f"{source.path}: column {theirs!r} (given for {name}) not found{did}; "
                f"the file's columns are {source.names}"
            )
    mapping = with_other_case(mapping, source.names)
    kinds = source.kinds()
    found = find_accelerometer(source.names, mapping.values(), kinds)
    mapping = {**mapping, **found}
    pairs = [(theirs, name) for name, theirs in mapping.items()]
    recording_names = [*mapping, *(n for n in source.names if n not in mapping.values())]
    axes = axis_names(recording_names)
    check_axis_sets(source, recording_names, axes, mapping)
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
    zone = check_zone(tz)
    if zone is not None and not stamped:
        raise InputError(f"--tz {zone} says in which time zone clock times were written, but "
                         f"the time column {time_file!r} counts "
                         f"{canon.get('time', 's')}; drop --tz, or pass --time-unit timestamp "
                         "if it holds clock times")
    return ColumnPlan(source, pairs, as_text, canon, stamped, read_names=names, axes=axes,
                      tz=zone,
                      zone_clock=None if zone is None else ZoneClock(zone, str(source.path)),
                      temp_scale=float(temp_scale), temp_offset_c=float(temp_offset_c),
                      thermometer=thermometer,
                      rate_scale=None if rate_scale is None else float(rate_scale),
                      temp_unwrap=temp_unwrap,
                      wrap_bits=int(temp_unwrap) if temp_unwrap in ("16", "32") else None,
                      wrap_decided=temp_unwrap != "auto", found=found)


def with_other_case(mapping: Mapping[str, str], names: Iterable[str]) -> dict[str, str]:
    """``mapping`` with the file's contract names written in another case mapped too
    (``RATE_DPH_X`` -> ``rate_dph_x``: issue 27's audit found an upper-case 3-axis
    header read as "single-axis"), unless the name is mapped or exists as written."""
    names = list(names)
    out = dict(mapping)
    taken = set(names) | set(out) | set(out.values())
    for name in names:
        lower = name.lower()
        if lower != name and lower not in taken and is_contract_name(lower) and sum(
                n.lower() == lower for n in names) == 1:
            out[lower] = name
            taken.add(lower)
    return out


def check_axis_sets(source: Source, names: list[str], axes: tuple[str, ...],
                    mapping: Mapping[str, str]) -> None:
    """Refuse per-axis columns of an axis that has no ``rate_dph_<axis>`` column.

    The axes of a file are those of its ``rate_dph_<axis>`` columns; a
    ``freq_hz_z`` or ``temperature_c_z`` without ``rate_dph_z`` would otherwise be
    carried along as an unknown column and the axis z dropped without a word. A
    single-axis file may have columns that look per-axis (``temperature_c_ambient``)
    except ``freq_hz_<axis>`` and ``rate_dph``-like ones beside no ``freq_hz``. A
    ``rate_dph`` or ``freq_hz`` without an axis beside per-axis rates is ambiguous (one
    gyro, or the axes? whose resonator?) and refused too (issue 27's audit: a stray
    ``rate_dph_x`` made a single-axis file a one-axis instrument ``x``).
    """
    if axes:
        for plain in ("rate_dph", "freq_hz"):
            if plain not in names:
                continue
            theirs = mapping.get(plain, plain)
            called = repr(theirs) if theirs == plain else f"{theirs!r} ({plain})"
            per_axis = [mapping.get(f"rate_dph_{a}", f"rate_dph_{a}") for a in axes]
            raise RecordingError(
                f"{source.path}: column {called} has no axis, beside the per-axis rate "
                f"column(s) {per_axis} of axes {list(axes)}: hrgtc cannot tell "
                + ("whether the file is one gyro's (rate_dph) or an instrument's"
                   if plain == "rate_dph" else "whose resonator it is")
                + f"; remove or rename {theirs!r} (e.g. {plain}_ref) if it is another "
                "channel, or the per-axis columns if the file is a single gyro's")
    for name in names:
        base, axis = split_axis(name)
        if axis is None or axis in axes:
            continue
        if not axes and (base not in ("freq_hz", "input_rate_dph") or "freq_hz" in names):
            continue  # a single-axis file's own column, e.g. temperature_c_ambient
        theirs = mapping.get(name, name)
        called = repr(theirs) if theirs == name else f"{theirs!r} ({name})"
        known = f"the file's axes are {list(axes)}" if axes else "the file has no rate_dph_<axis>"
        raise RecordingError(
            f"{source.path}: column {called} belongs to axis {axis!r}, which has "
            f"no 'rate_dph_{axis}' column ({known}): the axis would be dropped; add its "
            f"rate column (or map yours with --col rate_dph_{axis}=<your column>), or "
            f"remove {theirs!r} if the axis is not wanted"
        )


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


def _rate_values(plan: ColumnPlan, values: np.ndarray, time_s: np.ndarray | None,
                 theirs: str) -> np.ndarray:
    """A rate column in °/h: a factor, a raw count's scale, or an increment per sample ÷ Δt."""
    unit = unit_of("rate", plan.units.get("rate", "dph"))
    if unit.scaled:
        return values * (3600.0 / float(plan.rate_scale or 1.0))
    if not unit.per_sample:
        return unit.apply(values)
    if time_s is None:
        raise RecordingError(f"{plan.source.path}: column {theirs!r} is an angle increment per "
                             f"sample ({unit.symbol}), which needs the time column to divide "
                             "by each sample's Δt; map it with --col time_s=<your column>")
    if plan.period_s is None:
        plan.period_s = median_period(time_s)
        if plan.period_s is None:
            raise RecordingError(f"{plan.source.path}: column {theirs!r} is an angle increment "
                                 f"per sample ({unit.symbol}) but time_s has no increasing step "
                                 "to give a sample's Δt")
    steps = per_sample_steps(time_s, plan.previous_time_s, plan.period_s)
    return unit.apply(values) / steps


def _temperature_values(plan: ColumnPlan, values: np.ndarray, base: str,
                        theirs: str, row_offset: int = 0) -> np.ndarray:
    """A temperature column in °C: °F or K converted; a raw count unwrapped, scaled, offset."""
    temp = plan.units.get("temp", "C")
    if temp in ("F", "K"):
        return unit_of("temp", temp).apply(values)
    if base != "temperature_c" or not plan.temperature_is_count:
        return values
    if plan.temp_unwrap == "auto" and not plan.wrap_decided:
        plan.wrap_bits = wrapped_count_bits(values)
        plan.wrap_decided = True
        if plan.wrap_bits is not None:
            bits = plan.wrap_bits
            first = values[np.isfinite(values)][:1]
            warnings.warn(
                f"{plan.source.path}: column {theirs!r} sits just under 2^{bits} "
                f"({first[0]:.0f} at first): read as a signed {bits}-bit count stored unsigned, "
                f"values from 2^{bits - 1} on taken minus 2^{bits} ({first[0]:.0f} -> "
                f"{unwrap_count(first, bits)[0]:.0f}); pass --temp-unwrap off if your sensor "
                "really counts that high", UnitWarning, stacklevel=4)
    raw = values
    if plan.wrap_bits is not None:
        values = unwrap_count(values, plan.wrap_bits)
    if scales_temperature(plan.temp_scale, plan.temp_offset_c):
        mapped = values * plan.temp_scale + plan.temp_offset_c
        if not plan.map_checked and np.isfinite(mapped).any():
            plan.map_checked = True
            plan.map_problem = map_problem(plan, raw, mapped, theirs, row_offset)
        return mapped
    return values


def _is_text(column: pa.ChunkedArray) -> bool:
    return pa.types.is_string(column.type) or pa.types.is_large_string(column.type)


def _to_float(
    plan: ColumnPlan, column: pa.ChunkedArray, theirs: str, row_offset: int
) -> np.ndarray:
    if _is_text(column):
        # numbers as text padded with spaces: HDF5 fixed-length strings as MATLAB and
        # Fortran write them (issue 27's audit: "'4417.677   ' is not a number")
        column = pc.utf8_trim_whitespace(column)
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
        plan.time_aware = True
        if plan.time_origin_s is None:
            finite = seconds[np.isfinite(seconds)]
            plan.time_origin_s = float(finite[0]) if finite.size else None
        return seconds - (plan.time_origin_s or 0.0)
    stamps = _timestamps_ns(plan, column, theirs, row_offset)
    valid = ~np.asarray(stamps.is_null().to_numpy(zero_copy_only=False), dtype=bool)
    plan.time_aware = getattr(stamps.type, "tz", None) is not None
    if plan.zone_clock is not None and not plan.time_aware:
        ns = plan.zone_clock.utc_ns(stamps, theirs, row_offset)  # --tz: local clock -> UTC
    else:
        ns = np.asarray(stamps.cast(pa.int64()).fill_null(0).to_numpy(zero_copy_only=False),
                        dtype=np.int64)
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
            if kind == "rate":
                out[name] = _rate_values(plan, values, out.get("time_s"), theirs)
            elif kind == "temp":
                out[name] = _temperature_values(plan, values, base, theirs, row_offset)
            elif kind:
                out[name] = to_contract_unit(values, plan.units.get(kind, ""))
            else:
                out[name] = values
        del column
    if "time_s" in out and len(out["time_s"]):
        plan.previous_time_s = float(out["time_s"][-1])
    return sensor_frequency(out) if plan.thermometer == "sensor" else out
