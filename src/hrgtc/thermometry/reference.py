"""A raw temperature count mapped to °C from a sparse reference log (``--temp-ref``).

A MEMS gyro's temperature often arrives as a raw count (``temp = 65236``) whose
datasheet scale is unknown or unreliable; the thermal chamber's operators wrote a
reference probe down every few minutes, with clock times. This module

* reads such a log (:func:`read_reference_log`): a CSV (UTF-8, a byte-order mark
  allowed, trailing empty columns ignored, blank cells skipped and counted) with a
  time column (seconds since the recording's t = 0, or clock times ``HH:MM[:SS]``,
  or dates and times, with or without a UTC offset) and a temperature column in °C
  or °F (``time_s`` and ``temperature_c`` by default, mapped like any file's columns);
  clock times are put on the recording's time axis by the clock time of its t = 0
  (``start``), with midnight rollovers and an optional time zone;
* fits a linear map ``temperature_c = scale · count + offset``
  (:func:`fit_count_map`) by least squares on the recording's count, averaged per
  window and interpolated to each reference time, with the reference probe's lag
  behind the sensor fitted (the lag that minimises the residual: a probe in the
  chamber air or on the fixture follows the gyro's own sensor late, or early), and
  reports its residual (RMS and largest, in °C), the points used and the lag;
* stores the map as a :class:`TemperatureMap` (in the model file, see
  :mod:`hrgtc.model`), which compensation applies to later recordings of the unit.

A wrong ``start`` shifts every reference time: a start given Δ minutes late makes
the fitted lag Δ minutes shorter (the fit absorbs it, while the map stays right as
long as the temperature changes smoothly); with the lag fixed at 0 the map instead
takes the error as a bias of about (the temperature slope) × Δ. The fitted lag is
in the report: a lag far from what the probe's mounting explains means a wrong
start. A delay of an exponential settling is the same curve with a larger
amplitude, so on a run that only settles exponentially the lag and the scale trade
off (a ramp and a hold, or a known lag, pin both down).
"""

from __future__ import annotations

import csv
import datetime as dt
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Literal

import msgspec
import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import CalibrationError, InputError, RecordingError
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.settings.inputs import MAX_LAG_S
from hrgtc.thermometry.clock import parse_clock, parse_tz

__all__ = ["ReferenceLog", "TemperatureMap", "TemperatureReference", "fit_count_map",
           "parse_clock", "read_reference_log"]

#: Default columns of a reference log, and the ``--temp-ref-col`` names.
REFERENCE_COLUMNS = ("time_s", "temperature_c")
#: Largest lag tried either way by default (``--temp-ref-lag-s``'s default text names it),
#: and its step. [s]
LAG_STEP_S = 10.0
#: Largest time between two count windows a reference point is interpolated across. [s]
MAX_INTERPOLATION_S = 1800.0
#: Length of the windows the count is averaged over before interpolation. [s]
COUNT_WINDOW_S = 10.0
_FAHRENHEIT = re.compile(r"(°\s*f\b|\bdeg\s*f\b|\(f\)|\bfahrenheit\b|_f$)", re.IGNORECASE)


@dataclass(frozen=True)
class ReferenceLog:
    """Reference temperatures on the recording's time axis.

    Attributes
    ----------
    time_s
        Time of each reading since the recording's t = 0. [s]
    temperature_c
        The reference temperature. [°C]
    source
        The file.
    skipped
        Rows left out (a blank time or temperature).
    unit
        ``"C"`` or ``"F"``: the unit the log was in.
    """

    time_s: np.ndarray
    temperature_c: np.ndarray
    source: str
    skipped: int = 0
    unit: str = "C"


@dataclass(frozen=True)
class TemperatureMap:
    """``temperature_c = scale_c_per_count · count + offset_c`` of a raw sensor count.

    Attributes
    ----------
    scale_c_per_count, offset_c
        The map. [°C per count], [°C]
    count_bits
        16 or 32 when the count is a signed count stored unsigned (unwrapped before
        the map), None otherwise.
    lag_s
        The reference probe's fitted lag behind the sensor. [s]
    residual_rms_c, residual_max_c
        Residual of the reference points about the map. [°C]
    points
        Reference points used.
    count_range
        Smallest and largest count of the points (the map's calibrated span).
    reference
        The reference log's file name.
    """

    scale_c_per_count: float
    offset_c: float
    count_bits: int | None = None
    lag_s: float = 0.0
    residual_rms_c: float = math.nan
    residual_max_c: float = math.nan
    points: int = 0
    count_range: tuple[float, float] = (math.nan, math.nan)
    reference: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    def apply(self, count: np.ndarray) -> np.ndarray:
        """°C of raw counts (already unwrapped). [°C]"""
        return np.asarray(count, dtype=np.float64) * self.scale_c_per_count + self.offset_c

    def summary(self) -> Summary:
        """The map's scale and offset, the points, the residual and the reference's lag
        (its text: one line)."""
        figures = (Figure("scale_c_per_count", "scale", self.scale_c_per_count, "°C/count"),
                   Figure("offset_c", "offset", self.offset_c, "°C"),
                   Figure("points", "points", self.points,
                          definition="Settled stretches the map is fitted on."),
                   Figure("residual_rms_c", "residual RMS", self.residual_rms_c, "°C",
                          definition="RMS of the map's residuals at its points."),
                   Figure("residual_max_c", "largest residual", self.residual_max_c, "°C"),
                   Figure("lag_s", "reference lag", self.lag_s, "s",
                          definition="Delay of the reference log against the sensor."))
        return Summary("temperature map", (("temperature map", figures),), layout=(
            "temperature_c = {scale_c_per_count:.6g} × count + {offset_c:.6g} °C from "
            + escape(self.reference or "the reference log") + ": {points} points, residual "
            "RMS {residual_rms_c:.3g} °C (largest {residual_max_c:.3g} °C), reference lag "
            "{lag_s:+.0f} s",))

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (the model file's ``temperature_map``), as
        :class:`TemperatureMapRecord` writes them (NaN -> None), then the keys of ``extra``."""
        return {**records.dump(self, TemperatureMapRecord), **self.extra}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TemperatureMap:
        """Inverse of :meth:`to_dict` (checked against :class:`TemperatureMapRecord`; keys
        it does not know are kept in ``extra``); a scale of 0 or a non-finite number is
        refused."""
        if not isinstance(data, Mapping):
            raise InputError(f"temperature_map is {data!r}, not an object")
        known = {f.name for f in msgspec.structs.fields(TemperatureMapRecord)}
        return cls.from_values(records.load(data, TemperatureMapRecord, "temperature_map"),
                               {k: v for k, v in data.items() if k not in known})

    @classmethod
    def from_values(cls, values: Mapping[str, Any],
                    extra: Mapping[str, Any] | None = None) -> TemperatureMap:
        """The map of its record's values (:func:`hrgtc.core.records.built` of a converted
        :class:`TemperatureMapRecord`), checked: a scale of 0 or a non-finite number is
        refused."""
        scale, offset = values["scale_c_per_count"], values["offset_c"]
        if not (math.isfinite(scale) and math.isfinite(offset) and scale != 0.0):
            raise InputError(f"temperature_map scale {scale!r} / offset {offset!r}: a finite "
                             "scale other than 0 and a finite offset are needed")
        count_range = values["count_range"] or (math.nan, math.nan)
        return cls(**{**values, "count_range": count_range}, extra=dict(extra or {}))


class TemperatureMapRecord(records.Record, kw_only=True):
    """A :class:`TemperatureMap` in a file (the model file's optional ``temperature_map``):
    field names and bounds, from which its ``to_dict``/``from_dict`` and its JSON Schema
    are generated (keys a newer version wrote are kept beside it, in ``extra``)."""

    scale_c_per_count: float
    offset_c: float
    count_bits: Literal[16, 32, None] = None
    lag_s: float = 0.0
    residual_rms_c: records.Statistic = None
    residual_max_c: records.Statistic = None
    points: records.Count = 0
    count_range: tuple[records.Statistic, records.Statistic] | None = None
    reference: str = ""


# -- reading the log ---------------------------------------------------------------
def parse_reference_columns(items: list[str] | None) -> dict[str, str]:
    """``--temp-ref-col NAME=THEIRS`` options (repeated, or comma separated) as a dict."""
    mapping: dict[str, str] = {}
    for text in items or []:
        for part in str(text).split(","):
            name, sep, theirs = part.partition("=")
            if not sep or name.strip() not in REFERENCE_COLUMNS or not theirs.strip():
                raise InputError(f"--temp-ref-col {part!r}: write NAME=THEIRS with NAME one of "
                                 f"{list(REFERENCE_COLUMNS)}, e.g. --temp-ref-col time_s=Time")
            mapping[name.strip()] = theirs.strip()
    return mapping


def read_reference_log(path: str | Path, columns: Mapping[str, str] | None = None,
                       unit: str | None = None, start: str | None = None,
                       tz: str | None = None) -> ReferenceLog:
    """Read a sparse reference log onto the recording's time axis.

    Parameters
    ----------
    path
        CSV file (UTF-8, a byte-order mark allowed).
    columns
        ``{"time_s": "Time", "temperature_c": "C1 (C)"}``: the log's columns for the
        time and the temperature (defaults ``time_s`` and ``temperature_c``).
    unit
        ``"C"`` or ``"F"``; None: °F when the temperature column's header says so
        (``(F)``, ``°F``, ``degF``), else °C.
    start
        Clock time of the recording's t = 0 (``15:40``, ``2020-03-07T15:40:00+01:00``);
        needed when the log's times are clock times, not seconds.
    tz
        Time zone of clock times without a UTC offset, when the other side has one.

    Raises
    ------
    RecordingError
        Missing column, a value that is not a number or a time (file, column and row
        named), fewer than two readings, or clock times without ``start``.
    """
    path = Path(path)
    mapping = {**dict(zip(REFERENCE_COLUMNS, REFERENCE_COLUMNS, strict=True)), **(columns or {})}
    unknown = set(mapping) - set(REFERENCE_COLUMNS)
    if unknown:
        raise InputError(f"--temp-ref-col {sorted(unknown)[0]}=...: the reference log's columns "
                         f"are {list(REFERENCE_COLUMNS)}")
    with open(path, encoding="utf-8-sig", newline="") as handle:
        rows = list(csv.reader(handle))
    if not rows:
        raise RecordingError(f"{path}: the reference log is empty")
    header = [name.strip() for name in rows[0]]
    index = {}
    for name, theirs in mapping.items():
        if theirs not in header:
            named = [h for h in header if h]
            raise RecordingError(f"{path}: column {theirs!r} (the reference {name}) not found; "
                                 f"the log's columns are {named}; map yours with --temp-ref-col "
                                 f"{name}=<column>")
        index[name] = header.index(theirs)
    if unit is None:
        unit = "F" if _FAHRENHEIT.search(mapping["temperature_c"]) else "C"
    unit = {"c": "C", "°c": "C", "degc": "C", "f": "F", "°f": "F", "degf": "F"}.get(
        str(unit).strip().lower(), str(unit))
    if unit not in ("C", "F"):
        raise InputError(f"reference log unit {unit!r}: use C or F")
    times: list[str] = []
    temps: list[float] = []
    skipped = 0
    for number, row in enumerate(rows[1:], start=2):
        cells = [row[i].strip() if i < len(row) else "" for i in (index["time_s"],
                                                                  index["temperature_c"])]
        if not cells[0] or not cells[1]:
            skipped += 1
            continue
        try:
            temps.append(float(cells[1]))
        except ValueError:
            raise RecordingError(f"{path}: column {mapping['temperature_c']!r}, line {number}: "
                                 f"{cells[1]!r} is not a number; fix or blank that cell") from None
        times.append(cells[0])
    if len(times) < 2:
        raise RecordingError(f"{path}: fewer than two readings with a time and a temperature "
                             f"({skipped} rows with a blank cell)")
    temperature = np.array(temps, dtype=np.float64)
    if unit == "F":
        temperature = (temperature - 32.0) * 5.0 / 9.0
    time_s = _times_on_axis(times, path, mapping["time_s"], start, parse_tz(tz))
    return ReferenceLog(time_s, temperature, str(path), skipped, unit)


def _times_on_axis(times: list[str], path: Path, column: str, start: str | None,
                   zone: dt.tzinfo | None) -> np.ndarray:
    """Seconds since the recording's t = 0 of the log's times (seconds or clock times)."""
    try:
        return np.array([float(t) for t in times], dtype=np.float64)
    except ValueError:
        pass
    if start is None:
        raise RecordingError(f"{path}: column {column!r} holds clock times ({times[0]!r}); give "
                             "the clock time of the recording's t = 0 with --temp-ref-start "
                             "(e.g. --temp-ref-start 15:40 or 2020-03-07T15:40)")
    parsed = []
    for number, text in enumerate(times):
        try:
            parsed.append(parse_clock(text, zone))
        except InputError as exc:
            raise RecordingError(f"{path}: column {column!r}, reading {number + 1}: {exc}") \
                from None
    origin = parse_clock(start, zone)
    if all(isinstance(p, dt.time) for p in parsed):
        seconds = np.array([_day_seconds(p) for p in parsed])  # type: ignore[arg-type]
        rollover = np.concatenate([[0.0], np.cumsum(np.diff(seconds) < 0) * 86400.0])
        seconds = seconds + rollover  # each step back in clock time is a midnight
        origin_s = _day_seconds(origin.timetz() if isinstance(origin, dt.datetime) else origin)
        shift = origin_s - seconds[0]  # the start within ±12 h of the first reading
        origin_s -= 86400.0 * round(shift / 86400.0)
        return seconds - origin_s
    if any(isinstance(p, dt.time) for p in parsed):
        raise RecordingError(f"{path}: column {column!r} mixes clock times and dates; give "
                             "every time the same way")
    stamps: list[dt.datetime] = parsed  # type: ignore[assignment]
    if isinstance(origin, dt.time):
        origin = dt.datetime.combine(stamps[0].date(), origin, tzinfo=stamps[0].tzinfo)
        if (origin - stamps[0]).total_seconds() > 43200.0:
            origin -= dt.timedelta(days=1)
    aware = {s.tzinfo is not None for s in [*stamps, origin]}
    if len(aware) > 1:
        raise RecordingError(f"{path}: the reference times and --temp-ref-start do not both "
                             "carry a UTC offset; give the time zone of the naive ones with "
                             "--temp-ref-tz (e.g. +01:00 or Europe/Berlin)")
    return np.array([(s - origin).total_seconds() for s in stamps], dtype=np.float64)


def _day_seconds(clock: dt.time) -> float:
    return clock.hour * 3600.0 + clock.minute * 60.0 + clock.second + clock.microsecond / 1e6


# -- the fit -------------------------------------------------------------------------
def window_means(time_s: np.ndarray, count: np.ndarray,
                 window_s: float = COUNT_WINDOW_S) -> tuple[np.ndarray, np.ndarray]:
    """Mean time and mean count of consecutive ``window_s`` windows (empty ones left out)."""
    good = np.isfinite(time_s) & np.isfinite(count)
    t, c = time_s[good], count[good]
    if t.size == 0:
        return t, c
    block = np.floor((t - t[0]) / window_s).astype(np.int64)
    _, first, sizes = np.unique(block, return_index=True, return_counts=True)
    return np.add.reduceat(t, first) / sizes, np.add.reduceat(c, first) / sizes


def _interpolate(at: np.ndarray, t: np.ndarray, c: np.ndarray,
                 max_gap_s: float) -> np.ndarray:
    """Count at times ``at``, linear between windows at most ``max_gap_s`` apart, else NaN."""
    values = np.interp(at, t, c)
    right = np.clip(np.searchsorted(t, at), 1, len(t) - 1)
    span = t[right] - t[right - 1]
    outside = (at < t[0]) | (at > t[-1]) | (span > max_gap_s)
    values[outside] = np.nan
    return values


def _line(x: np.ndarray, y: np.ndarray) -> tuple[float, float, np.ndarray]:
    design = np.column_stack([x - x.mean(), np.ones_like(x)])
    (slope, level), *_ = np.linalg.lstsq(design, y, rcond=None)
    offset = level - slope * x.mean()
    return float(slope), float(offset), y - (slope * x + offset)


def fit_count_map(time_s: np.ndarray, count: np.ndarray, reference: ReferenceLog, *,
                  lag_s: float | None = None, max_lag_s: float = MAX_LAG_S,
                  lag_step_s: float = LAG_STEP_S, window_s: float = COUNT_WINDOW_S,
                  max_interpolation_s: float = MAX_INTERPOLATION_S,
                  count_bits: int | None = None) -> TemperatureMap:
    """Fit ``temperature_c = scale · count + offset`` of a raw count to a reference log.

    The count is averaged over ``window_s`` windows and interpolated linearly to each
    reference time minus the lag (never across more than ``max_interpolation_s``
    without samples, never beyond the recording); the lag is the one of the grid
    −``max_lag_s`` … +``max_lag_s`` (step ``lag_step_s``) with the smallest residual,
    or ``lag_s`` when given.

    Parameters
    ----------
    time_s, count
        The recording's time [s] and raw count (unwrapped).
    reference
        The reference log on the recording's time axis.

    Raises
    ------
    CalibrationError
        Fewer than three reference points inside the recording, or a count that does
        not change over them.
    """
    t, c = window_means(np.asarray(time_s, float), np.asarray(count, float), window_s)
    if t.size < 2:
        raise CalibrationError("the recording has fewer than two windows of counts to map")
    lags = (np.array([float(lag_s)]) if lag_s is not None else
            np.arange(-max_lag_s, max_lag_s + 0.5 * lag_step_s, lag_step_s))
    trials = []
    for lag in lags:
        at = _interpolate(reference.time_s - lag, t, c, max_interpolation_s)
        used = np.isfinite(at)
        if np.count_nonzero(used) >= 3 and np.ptp(at[used]) > 0:
            trials.append((float(lag), used, at))
    # Lags that keep different numbers of reference points (a lag loses readings at the
    # recording's ends) are compared by the residual variance per degree of freedom,
    # sum(r²)/(n − 2), which fewer points do not lower by themselves; a lag must keep at
    # least half of the most points any lag keeps.
    most = max((int(np.count_nonzero(used)) for _, used, _ in trials), default=0)
    best: tuple[float, float, float, float, np.ndarray, np.ndarray] | None = None
    best_variance = np.inf
    for lag, used, at in trials:
        n = int(np.count_nonzero(used))
        if n < max(3, (most + 1) // 2):
            continue
        scale, offset, residual = _line(at[used], reference.temperature_c[used])
        variance = float(np.sum(residual**2)) / max(n - 2, 1)
        # the same residual: the lag nearest 0 (grid order is not a preference)
        if best is None or variance < best_variance * (1 - 1e-12) or (
                abs(variance - best_variance) <= 1e-12 * best_variance
                and abs(lag) < abs(best[1])):
            rms = float(np.sqrt(np.mean(residual**2)))
            best, best_variance = (rms, lag, scale, offset, residual, at[used]), variance
    if best is None:
        inside = np.count_nonzero((reference.time_s >= t[0]) & (reference.time_s <= t[-1]))
        raise CalibrationError(
            f"{reference.source}: {inside} reference reading(s) fall inside the recording "
            f"(t = {t[0]:.0f} … {t[-1]:.0f} s on its clock) with a changing count; at least 3 "
            "are needed: is --temp-ref-start the clock time of the recording's t = 0?")
    rms, lag, scale, offset, residual, used_counts = best
    extra = {}
    if lag_s is None and abs(lag) >= max_lag_s - lag_step_s:
        extra["note"] = (f"the fitted lag {lag:+.0f} s is at the edge of the search (±{max_lag_s:g}"
                         " s): the stated start of the recording is probably wrong")
    return TemperatureMap(scale, offset, count_bits, lag, rms, float(np.max(np.abs(residual))),
                          int(residual.size),
                          (float(used_counts.min()), float(used_counts.max())),
                          Path(reference.source).name, extra)


# -- from files to a map, and a map onto the reading options ------------------------------
def map_from_reference(recording: str | Path, reference: str | Path,
                       read_options: Any = None, *, columns: Mapping[str, str] | None = None,
                       unit: str | None = None, start: str | None = None, tz: str | None = None,
                       lag_s: float | None = None) -> TemperatureMap:
    """Fit the count → °C map of a recording's raw temperature to a reference log.

    Parameters
    ----------
    recording
        The recording the reference log was written beside (its ``temperature_c``
        column, or ``temperature_c_<axis>`` of the first axis, is the raw count).
    reference
        The reference log (see :func:`read_reference_log` for ``columns``, ``unit``,
        ``start`` and ``tz``); ``start`` defaults to the recording's first time stamp
        when its time column holds dates.
    read_options
        :class:`hrgtc.recording.ReadOptions` of the recording (its scale and offset
        are ignored: the count is read raw, unwrapped as ``temp_unwrap`` says).
    lag_s
        The reference's lag behind the sensor [s]; None: fitted.
    """
    from dataclasses import replace

    from hrgtc.recording import ReadOptions

    options = replace(read_options or ReadOptions(), temp_scale=1.0, temp_offset_c=0.0,
                      units={**dict((read_options.units if read_options else None) or {}),
                             "temp": "count"},
                      spike_filter="off", spikes="error", gaps="split")
    # spikes="error" and no validation: the count has no physical bounds, impossible
    # temperatures are judged after the map (a count of -300 is no -300 °C)
    run = _read_raw(options, recording)
    names = [n for n in run.names if n == "temperature_c" or n.startswith("temperature_c_")]
    if not names:
        raise RecordingError(f"{recording}: no temperature_c column to map; map the raw count "
                             "with --col temperature_c=<your column>")
    origin = run.metadata.extra.get("time_origin")
    log = read_reference_log(reference, columns, unit, start if start is not None else origin,
                             tz)
    bits = run.metadata.extra.get("temperature_count_bits")
    return fit_count_map(run.time_s, run[names[0]], log, lag_s=lag_s, count_bits=bits)


@dataclass(frozen=True)
class TemperatureReference(records.Written):
    """A reference log of the temperature and how to read it (``hrgtc calibrate
    --temp-ref`` and its ``--temp-ref-*`` options): what
    :func:`hrgtc.pipeline.calibration.calibrate` fits the count's map from (built from
    :class:`hrgtc.settings.inputs.TemperatureReferenceSettings` by
    :func:`hrgtc.pipeline.calibration.temperature_reference`).

    Attributes
    ----------
    path
        The reference log (CSV), written beside the first drift recording (kept as text).
    columns
        Its columns by our names (``{"time_s": "Time", "temperature_c": "C1 (C)"}``);
        empty (or None): ``time_s`` and ``temperature_c``.
    unit
        ``"C"`` or ``"F"``; None: F when the temperature column's header says so.
    start
        Clock time of the recording's t = 0 (``"15:40"`` or an ISO date-time) when the
        log has clock times; None: the recording's first time stamp.
    tz
        Time zone of naive clock times (``"+01:00"``, ``"Europe/Berlin"``).
    lag_s
        The reference's lag behind the sensor; None: fitted. [s]
    """

    path: str
    columns: dict[str, str] = field(default_factory=dict)
    unit: str | None = None
    start: str | None = None
    tz: str | None = None
    lag_s: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", str(self.path))
        object.__setattr__(self, "columns", dict(self.columns or {}))

    def fit(self, recording: str | Path, read_options: Any = None) -> TemperatureMap:
        """The count → °C map of ``recording``'s raw temperature
        (:func:`map_from_reference`)."""
        return map_from_reference(recording, self.path, read_options,
                                  columns=self.columns or None,
                                  unit=self.unit, start=self.start, tz=self.tz,
                                  lag_s=self.lag_s)


#: The record of :class:`TemperatureReference` (a model file's provenance: how the log was
#: read), generated from its fields.
TemperatureReferenceRecord = records.record_of(
    TemperatureReference, doc="The record of :class:`TemperatureReference` (``columns``: "
    "ours -> the log's;\nempty for the default names).")


def _read_raw(options: Any, recording: str | Path) -> Any:
    """The recording with its raw count, not validated (a count is no temperature in °C)."""
    from hrgtc.recording import read

    return read(recording, replace(options, freq_band_hz=None, freq_span_hz=None),
                validate=False)


def options_with_map(read_options: Any, temperature_map: TemperatureMap | Mapping[str, Any]
                     | None) -> Any:
    """Reading options that apply a model's temperature map to the raw count.

    Unchanged when there is no map, or when the user gave ``--temp-scale`` /
    ``--temp-offset`` or a temperature unit other than a count (their choice wins).
    """
    from dataclasses import replace

    from hrgtc.recording import ReadOptions

    options = read_options or ReadOptions()
    if temperature_map is None:
        return options
    if not isinstance(temperature_map, TemperatureMap):
        temperature_map = TemperatureMap.from_dict(temperature_map)
    temp_unit = dict(options.units or {}).get("temp")
    if options.temp_scale != 1.0 or options.temp_offset_c != 0.0 or temp_unit not in (
            None, "count"):
        return options
    bits = temperature_map.count_bits
    return replace(options, temp_scale=temperature_map.scale_c_per_count,
                   temp_offset_c=temperature_map.offset_c,
                   temp_unwrap=str(bits) if bits else "off")
