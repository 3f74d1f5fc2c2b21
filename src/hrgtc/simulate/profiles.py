"""Chamber set-point profiles: the program type and its JSON/YAML file schema.

A profile is the program of a thermal chamber: a start temperature (the unit
and the chamber are in equilibrium there when the run starts) and a list of
segments, each either

* a **hold**: the chamber moves to ``setpoint_c`` at its maximum rate
  (``chamber_max_c_per_min``, 2 °C/min by default) and then holds it; the
  segment lasts ``hold_h`` hours in total, slewing included; or
* a **ramp**: the chamber moves to ``setpoint_c`` at ``ramp_c_per_min``
  (at most the chamber's maximum rate); the segment lasts as long as the ramp.

The chamber air temperature is therefore piecewise linear in time
(:meth:`Profile.breakpoints`), which the thermal network integrates exactly.
A profile starts with chamber, housing and resonator in equilibrium at ``start_c``.

The standard runs (soaks, cool-down, warm-up, ramp, constant) are built in
:mod:`hrgtc.simulate.standard_profiles`.

Profile files (JSON or YAML) hold either a list of segments or a mapping::

    # my-profile.yaml
    name: cold-cycle            # optional; default: the file's stem
    start_c: 20                 # optional; default 20 (room temperature) [°C]
    chamber_max_c_per_min: 2    # optional; default 2 [°C/min]
    segments:
      - {setpoint_c: -20, ramp_c_per_min: 1.0}   # ramp to -20 °C at 1 °C/min
      - {setpoint_c: -20, hold_h: 2}             # hold for 2 h
      - {setpoint_c: 40, ramp_c_per_min: 0.5}
      - {setpoint_c: 40, hold_h: 3}

Each segment has ``setpoint_c`` and exactly one of ``hold_h`` and ``ramp_c_per_min``.

A segment may also turn a rate table under the unit (IEEE Std 1431 scale-factor
tests): ``table_rate_dps`` is the table's rate held through the segment [°/s]
(none: the table at rest), and ``axis`` the axis of a multi-axis unit it turns
(the other axes see no table rate; none for a single-axis unit)::

      - {setpoint_c: 30, hold_h: 3}                                  # soak at 30 °C
      - {setpoint_c: 30, hold_h: 0.025, table_rate_dps: 100, axis: x}  # 90 s at 100 °/s

:func:`hrgtc.simulate.standard_profiles.rate_table` builds such a program.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

import msgspec
import numpy as np
import yaml

import hrgtc.settings.simulation as _settings
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.summary import Figure, Summary, escape

__all__ = [
    "AXIS_NAME",
    "CHAMBER_MAX_C_PER_MIN",
    "DEFAULT_RAMP_C_PER_MIN",
    "ROOM_TEMPERATURE_C",
    "Profile",
    "ProfileRecord",
    "Segment",
    "SegmentRecord",
    "from_mapping",
    "load",
]

#: Room temperature at which soaks start, as in Fig. 3 of [1] (hrgtc.settings.simulation). [°C]
ROOM_TEMPERATURE_C = _settings.ROOM_TEMPERATURE_C
#: Default maximum rate of change of the chamber air temperature. [°C/min]
CHAMBER_MAX_C_PER_MIN = 2.0
#: Default ramp rate of the cool-down and warm-up runs (Fig. 6 of [1]). [°C/min]
DEFAULT_RAMP_C_PER_MIN = _settings.DEFAULT_RAMP_C_PER_MIN
#: An axis name: a letter, then letters or digits (the suffix of per-axis columns).
AXIS_NAME = re.compile(r"[A-Za-z][A-Za-z0-9]*")


def finite_number(name: str, value: Any, unit: str, where: str = "") -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        out = math.nan
    if not math.isfinite(out):
        raise InputError(f"{where}{name} must be a finite number [{unit}], got {value!r}")
    return out


def format_temperature(value: float) -> str:
    return f"{value:g}"


@dataclass(frozen=True)
class Segment(records.Written):
    """One step of a chamber program: hold a set-point, or ramp to it.

    Parameters
    ----------
    setpoint_c
        Chamber set-point at the end of the segment. [°C]
    hold_h
        Duration of a hold segment, slewing at the chamber's maximum rate
        included; None for a ramp. [h]
    ramp_c_per_min
        Ramp rate of a ramp segment; None for a hold. [°C/min]
    table_rate_dps
        Rate of a rate table under the unit through the segment; None: at rest. [°/s]
    axis
        Axis of a multi-axis unit the table turns (the others see none); None
        for a single-axis unit.
    """

    #: Its record (:data:`SegmentRecord`): the keys of a profile file's segment, the
    #: optional ones written only when given.
    forbid_unknown_fields = True
    omit_when_default = ("hold_h", "ramp_c_per_min", "table_rate_dps", "axis")

    setpoint_c: float
    hold_h: records.Positive | None = None
    ramp_c_per_min: records.Positive | None = None
    table_rate_dps: float | None = None
    axis: Annotated[str, msgspec.Meta(pattern=r"^[A-Za-z][A-Za-z0-9]*$")] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "setpoint_c", finite_number("setpoint_c", self.setpoint_c, "°C"))
        if self.table_rate_dps is not None:
            rate = finite_number("table_rate_dps", self.table_rate_dps, "°/s")
            object.__setattr__(self, "table_rate_dps", rate)
        if self.axis is not None:
            if not (isinstance(self.axis, str) and AXIS_NAME.fullmatch(self.axis)):
                raise InputError(
                    f"axis must be a letter then letters or digits (e.g. x), got {self.axis!r}"
                )
            if self.table_rate_dps is None:
                raise InputError(
                    f"axis {self.axis!r} is given without table_rate_dps; give the table's "
                    "rate [°/s] or drop the axis"
                )
        if (self.hold_h is None) == (self.ramp_c_per_min is None):
            raise InputError(
                "a segment needs exactly one of hold_h and ramp_c_per_min, got "
                f"hold_h={self.hold_h!r}, ramp_c_per_min={self.ramp_c_per_min!r}"
            )
        if self.hold_h is not None:
            hold = finite_number("hold_h", self.hold_h, "h")
            if hold <= 0.0:
                raise InputError(f"hold_h must be > 0 [h], got {hold!r}")
            object.__setattr__(self, "hold_h", hold)
        else:
            rate = finite_number("ramp_c_per_min", self.ramp_c_per_min, "°C/min")
            if rate <= 0.0:
                raise InputError(
                    f"ramp_c_per_min must be > 0 [°C/min], got {rate!r}; the direction "
                    "follows from the set-point"
                )
            object.__setattr__(self, "ramp_c_per_min", rate)


#: The record of :class:`Segment`, generated from its fields.
SegmentRecord = records.record_of(
    Segment, doc="A :class:`Segment` in a profile file: ``setpoint_c`` and one of ``hold_h`` "
    "and\n``ramp_c_per_min`` (the segment checks which), the others written only when given.")
#: Keys of a segment in a profile file (:class:`SegmentRecord`'s fields).
SEGMENT_KEYS = tuple(f.name for f in msgspec.structs.fields(SegmentRecord))


@dataclass(frozen=True)
class Profile(records.Written):
    """A chamber program: start temperature, segments, chamber rate limit.

    Parameters
    ----------
    segments
        The program, in order.
    start_c
        Temperature of chamber, housing and resonator at time 0 (equilibrium). [°C]
    chamber_max_c_per_min
        Maximum rate of change of the chamber air temperature. [°C/min]
    name
        Short name used for file names, e.g. ``"soak_-10C"``.
    description
        Free text for the recording's ``profile`` metadata, e.g. ``"soak -10 C, 5 h"``.
    setpoint_c
        The set-point a soak calibrates (None for other profiles). [°C]
    """

    #: Its record (:data:`ProfileRecord`: a profile file's mapping form, a recording's
    #: ``chamber_program``; :func:`from_mapping` reads the file's other forms).
    forbid_unknown_fields = True
    record_order = ("name", "description", "start_c", "chamber_max_c_per_min", "setpoint_c",
                    "segments")

    segments: Annotated[tuple[Segment, ...], msgspec.Meta(min_length=1)]
    start_c: float = ROOM_TEMPERATURE_C
    chamber_max_c_per_min: records.Positive = CHAMBER_MAX_C_PER_MIN
    name: str = "profile"
    description: str = ""
    setpoint_c: float | None = field(default=None)

    def __post_init__(self) -> None:
        segments = tuple(self.segments)
        if not segments:
            raise InputError("a profile needs at least one segment")
        for index, segment in enumerate(segments):
            if not isinstance(segment, Segment):
                raise InputError(
                    f"segment {index} must be a Segment, got {type(segment).__name__}"
                )
        object.__setattr__(self, "segments", segments)
        object.__setattr__(self, "start_c", finite_number("start_c", self.start_c, "°C"))
        rate = finite_number("chamber_max_c_per_min", self.chamber_max_c_per_min, "°C/min")
        if rate <= 0.0:
            raise InputError(f"chamber_max_c_per_min must be > 0 [°C/min], got {rate!r}")
        object.__setattr__(self, "chamber_max_c_per_min", rate)
        for index, segment in enumerate(segments):
            if segment.ramp_c_per_min is not None and segment.ramp_c_per_min > rate:
                raise InputError(
                    f"segment {index}: ramp_c_per_min={segment.ramp_c_per_min:g} exceeds the "
                    f"chamber's maximum rate {rate:g} °C/min; lower the ramp rate or raise "
                    "chamber_max_c_per_min"
                )
        if not self.description:
            object.__setattr__(self, "description", self._default_description())

    def _default_description(self) -> str:
        parts = [
            f"hold {format_temperature(s.setpoint_c)} C {s.hold_h:g} h"
            if s.hold_h is not None
            else f"ramp to {format_temperature(s.setpoint_c)} C at {s.ramp_c_per_min:g} C/min"
            for s in self.segments
        ]
        return f"from {format_temperature(self.start_c)} C: " + ", ".join(parts)

    def breakpoints(self) -> tuple[np.ndarray, np.ndarray]:
        """Corners of the piecewise-linear chamber air temperature.

        Returns
        -------
        time_s : numpy.ndarray
            Times of the corners, starting at 0, non-decreasing. [s]
        chamber_c : numpy.ndarray
            Chamber temperature at the corners. [°C]
        """
        times, temps, _ = self._corners()
        return times, temps

    def segment_ends_s(self) -> np.ndarray:
        """Time at which each segment ends (the next one starts). [s]"""
        return self._corners()[2]

    @property
    def has_rate_table(self) -> bool:
        """True if a segment turns a rate table (the run has an ``input_rate_dph`` column)."""
        return any(s.table_rate_dps is not None for s in self.segments)

    @property
    def table_axes(self) -> tuple[str | None, ...]:
        """The axes the table turns, in order of first use (None: a single-axis segment)."""
        axes = [s.axis for s in self.segments if s.table_rate_dps is not None]
        return tuple(dict.fromkeys(axes))

    def table_rate_dps(self, time_s: Any, axis: str | None = None) -> np.ndarray:
        """Rate of the table on ``axis`` at the given times (0 at rest or on another axis). [°/s]

        A sample at a segment's end time belongs to the next segment; after the
        end of the program the last segment's rate holds.

        Parameters
        ----------
        time_s
            Times. [s]
        axis
            The axis (None for a single-axis unit: the segments that name no axis).
        """
        rates = np.array([
            s.table_rate_dps if s.table_rate_dps is not None and s.axis == axis else 0.0
            for s in self.segments
        ])
        index = np.searchsorted(self.segment_ends_s(), np.asarray(time_s, np.float64), "right")
        return rates[np.minimum(index, rates.size - 1)]

    def _corners(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        max_rate = self.chamber_max_c_per_min / 60.0
        times, temps = [0.0], [self.start_c]
        ends: list[float] = []
        t, temp = 0.0, self.start_c
        for segment in self.segments:
            delta = segment.setpoint_c - temp
            if segment.hold_h is not None:
                duration = segment.hold_h * 3600.0
                slew = abs(delta) / max_rate
                if slew >= duration:  # the chamber does not reach the set-point in time
                    temp += math.copysign(max_rate * duration, delta)
                    t += duration
                    times.append(t)
                    temps.append(temp)
                    ends.append(t)
                    continue
                if slew > 0.0:
                    times.append(t + slew)
                    temps.append(segment.setpoint_c)
                t += duration
                temp = segment.setpoint_c
            else:
                assert segment.ramp_c_per_min is not None
                t += abs(delta) / (segment.ramp_c_per_min / 60.0)
                temp = segment.setpoint_c
            times.append(t)
            temps.append(temp)
            ends.append(t)
        return np.array(times), np.array(temps), np.array(ends)

    @property
    def duration_s(self) -> float:
        """Total duration of the program. [s]"""
        return float(self.breakpoints()[0][-1])

    def chamber_c(self, time_s: Any) -> np.ndarray:
        """Chamber air temperature at the given times (held after the end). [°C]"""
        times, temps = self.breakpoints()
        return np.interp(np.asarray(time_s, dtype=np.float64), times, temps)

    def summary(self) -> Summary:
        """The chamber temperature at each breakpoint and the duration (its text: one line
        per breakpoint)."""
        times, temps = self.breakpoints()
        cells: list[Figure] = []
        for k, (t, c) in enumerate(zip(times, temps, strict=True)):
            cells += [Figure(f"breakpoints[{k}].time_s", f"breakpoint {k + 1}: t", float(t), "s",
                             row=str(k), column="t"),
                      Figure(f"breakpoints[{k}].chamber_c", f"breakpoint {k + 1}: chamber",
                             float(c), "°C", row=str(k), column="chamber")]
        duration = Figure("duration_s", "duration", float(times[-1]), "s")
        layout = (escape(f"profile {self.name}: {self.description}"),
                  "  duration {duration_s:.0f} s",
                  *(f"  t = {{breakpoints[{k}].time_s:9.0f}} s  chamber "
                    f"{{breakpoints[{k}].chamber_c:8.3f}} °C" for k in range(len(times))))
        return Summary(f"profile {self.name}", (("profile", (duration,)),
                                                ("breakpoints", tuple(cells))), layout=layout)


#: The record of :class:`Profile`, generated from its fields.
ProfileRecord = records.record_of(
    Profile, doc="A :class:`Profile` (a profile file's mapping form, a recording's "
    "``chamber_program``).")


def from_mapping(data: Any, source: str = "profile", name: str = "profile") -> Profile:
    """A profile from the file schema of the module docstring (a list or a mapping).

    Parameters
    ----------
    data
        A list of segment mappings, or a mapping with ``segments`` and the
        optional keys ``name``, ``description``, ``start_c``,
        ``chamber_max_c_per_min``, ``setpoint_c``.
    source
        Where the data came from, for error messages (a file name).
    name
        Default profile name.
    """
    if isinstance(data, Mapping):
        allowed = {
            "segments", "name", "description", "start_c", "chamber_max_c_per_min", "setpoint_c"
        }
        unknown = sorted(set(map(str, data)) - allowed)
        if unknown:
            raise InputError(f"{source}: unknown key(s) {unknown}; allowed: {sorted(allowed)}")
        if "segments" not in data:
            raise InputError(f"{source}: no 'segments' list; see the schema in the README")
        segments_data = data["segments"]
        options = {k: data[k] for k in data if k != "segments" and data[k] is not None}
    else:
        segments_data, options = data, {}
    if not isinstance(segments_data, Sequence) or isinstance(segments_data, str | bytes):
        raise InputError(
            f"{source}: segments must be a list of {{setpoint_c, hold_h | ramp_c_per_min}} "
            f"mappings, got {type(segments_data).__name__}"
        )
    segments = []
    for index, item in enumerate(segments_data):
        where = f"{source}: segment {index}: "
        if not isinstance(item, Mapping):
            raise InputError(f"{where}expected a mapping, got {item!r}")
        unknown = sorted(set(map(str, item)) - set(SEGMENT_KEYS))
        if unknown:
            raise InputError(
                f"{where}unknown key(s) {unknown}; use setpoint_c and one of hold_h, "
                "ramp_c_per_min (optionally table_rate_dps and axis)"
            )
        if "setpoint_c" not in item:
            raise InputError(f"{where}missing setpoint_c [°C]")
        try:
            segments.append(
                Segment(
                    item["setpoint_c"],
                    item.get("hold_h"),
                    item.get("ramp_c_per_min"),
                    item.get("table_rate_dps"),
                    item.get("axis"),
                )
            )
        except InputError as exc:
            raise InputError(f"{where}{exc}") from None
    if not segments:
        raise InputError(f"{source}: the profile has no segments")
    try:
        return Profile(
            tuple(segments),
            start_c=options.get("start_c", ROOM_TEMPERATURE_C),
            chamber_max_c_per_min=options.get("chamber_max_c_per_min", CHAMBER_MAX_C_PER_MIN),
            name=_slug(str(options.get("name", name))),
            description=str(options.get("description", "")),
            setpoint_c=options.get("setpoint_c"),
        )
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None


def load(path: str | Path) -> Profile:
    """Read a profile file (``.json``, ``.yaml`` or ``.yml``), schema in the module docstring."""
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    suffix = path.suffix.lower()
    if suffix not in (".json", ".yaml", ".yml"):
        raise InputError(f"{path}: unknown profile file type {suffix!r}; use .json, .yaml or .yml")
    try:
        data = json.loads(text) if suffix == ".json" else yaml.safe_load(text)
    except (ValueError, yaml.YAMLError) as exc:  # json.JSONDecodeError is a ValueError
        raise InputError(f"{path}: cannot parse the profile: {exc}") from None
    return from_mapping(data, source=str(path), name=path.stem)


def _slug(name: str) -> str:
    """A profile name safe as a file name (letters, digits, ``_.+-``)."""
    slug = re.sub(r"[^A-Za-z0-9_.+-]+", "_", name).strip(".")
    return slug or "profile"
