"""A summary of a recording file: size, rates, spans and validation, in one pass.

:func:`describe` streams the file chunk by chunk, so it works on files larger
than memory, and never raises on a bad file: the problem is reported in the
validation part of the result (``ok=False``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import msgspec
import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import RecordingError
from hrgtc.core.progress import Progress
from hrgtc.core.records import Count, Record
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.core.time_steps import TimeRepairStream
from hrgtc.core.timeline import Timeline
from hrgtc.core.timeline_builder import TimelineBuilder
from hrgtc.recording.axes import axis_names, base_name
from hrgtc.recording.formats.registry import format_of
from hrgtc.recording.io import iter_chunks
from hrgtc.recording.resolution import resolution
from hrgtc.recording.schema import COLUMNS, Metadata
from hrgtc.recording.spikes import SPIKE_COLUMN
from hrgtc.recording.validation import (
    Problem,
    RecordingValidator,
    ValidationReport,
    check_gap_policy,
)
from hrgtc.settings.reading import ReadSettings, with_fields

TEMPERATURE_COLUMNS = ("chamber_c", "housing_c", "resonator_c", "temperature_c")
SPAN_COLUMNS = (*TEMPERATURE_COLUMNS, "freq_hz")


@dataclass(frozen=True)
class ColumnSummary(records.Written):
    """Name, unit and range of the finite values of one column.

    Parameters
    ----------
    name
        Column name in the recording.
    unit
        Unit of the recording contract (``""`` for a column outside it).
    minimum, maximum
        Smallest and largest finite value, None if there is none. [unit]
    resolution
        Smallest step between distinct values of the first chunk read (the
        logger's resolution, see :func:`hrgtc.recording.resolution.resolution`),
        None if unknown. [unit]
    """

    #: Its record (:data:`ColumnSummaryRecord`): ``min`` and ``max`` in the file.
    file_names = (("minimum", "min"), ("maximum", "max"))

    name: str
    unit: str
    minimum: float | None = None
    maximum: float | None = None
    resolution: float | None = None


#: The record of :class:`ColumnSummary`, generated from its fields.
ColumnSummaryRecord = records.record_of(
    ColumnSummary, doc="The record of :class:`ColumnSummary` (``min`` / ``max``: its minimum, "
    "maximum).")


@dataclass(frozen=True)
class RecordingInfo:
    """What :func:`describe` found in a recording file.

    Parameters
    ----------
    path
        The file.
    format
        ``"parquet"``, ``"csv"`` or ``"hdf5"``.
    rows
        Rows read (up to the first unreadable one).
    start_time_s, end_time_s
        First and last finite time, None without any. [s]
    duration_s
        ``end - start + 1/sample_rate``, None if unknown. [s]
    sample_rate_hz
        Sample rate of the metadata (or inferred). [Hz]
    sample_rate_inferred
        True when the file had no sample rate and it was inferred from the times.
    measured_sample_rate_hz
        Reciprocal of the median time step (first 100,000 rows). [Hz]
    columns
        Summary of each column, in order.
    metadata
        The metadata as a dict, None if unreadable.
    validation
        The validation report (``ok=False`` with an ``"unreadable"`` problem when
        the file could not be read to the end).
    axes
        The axes of a multi-axis recording (``()`` for a single-axis one).
    spike_rows
        Rows with a single-sample spike (:func:`hrgtc.recording.spikes.find_spikes`),
        None when the spike filter was off.
    """

    path: str
    format: str | None
    rows: int
    start_time_s: float | None
    end_time_s: float | None
    duration_s: float | None
    sample_rate_hz: float | None
    sample_rate_inferred: bool
    measured_sample_rate_hz: float | None
    columns: tuple[ColumnSummary, ...]
    metadata: dict[str, Any] | None
    validation: ValidationReport
    axes: tuple[str, ...] = ()
    spike_rows: int | None = None
    timeline: dict[str, Any] | None = None

    @property
    def ok(self) -> bool:
        """True when the recording passed validation."""
        return self.validation.ok

    def column(self, name: str) -> ColumnSummary | None:
        """The summary of column ``name``, None if absent."""
        return next((c for c in self.columns if c.name == name), None)

    def summary(self) -> Summary:
        """The file at a glance: rows, axes, duration and segments, sample rates, each
        column's unit and range, spikes, spans and the validation report (its figures after
        ``validation.``); its text what ``hrgtc info`` prints."""
        figures, lines = self._file_figures()
        columns, column_lines = self._column_figures()
        lines += column_lines
        found = (self.metadata or {}).get("extra", {}).get("columns_found") or {}
        if found:
            lines.append(escape("  found by name: " + ", ".join(
                f"{theirs!r} as {name}" for name, theirs in found.items())
                + " (the accelerometer: motion and orientation; --col accel_x=... to choose)"))
        if self.spike_rows is not None:
            figures.append(Figure("spike_rows", "rows with single-sample spikes",
                                  self.spike_rows))
            lines.append("  single-sample spikes: {spike_rows} row(s) (calibrate and "
                         "evaluate remove them, compensate flags them; --spike-filter)")
        for col in self._span_columns():
            if col.minimum is not None:
                unit = {"Hz": "Hz", "count": "counts"}.get(col.unit, "°C")
                figures.append(Figure(f"spans.{col.name}", f"{col.name} span",
                                      col.maximum - col.minimum, unit,
                                      definition="Largest minus smallest value."))
                lines.append(f"  {escape(col.name)} span: {{spans.{col.name}:.6g}} "
                             f"{escape(unit)}")
        validation = self.validation.summary().renamed("validation.")
        return Summary(f"{self.path} ({self.format or 'unknown format'})",
                       (("recording", tuple(figures)), ("columns", tuple(columns)),
                        *validation.sections), validation.notes,
                       (*lines, *validation.lines("  ")))

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (:class:`RecordingInfoRecord`)."""
        return records.dump(
            self, RecordingInfoRecord, columns=[c.to_dict() for c in self.columns],
            spans={col.name: [col.minimum, col.maximum] for col in self._span_columns()},
            validation=self.validation.to_dict())

    def _file_figures(self) -> tuple[list[Figure], list[str]]:
        """The summary's figures and lines of the file: metadata, rows, axes, duration and
        segments, time repairs, sample rates."""
        figures: list[Figure] = [Figure("rows", "rows", self.rows)]
        lines = [escape(f"{self.path} ({self.format or 'unknown format'})")]
        meta = self.metadata or {}
        if meta:
            # a field the file does not set (a plain CSV's empty profile) is not shown
            parts = [escape(f"unit {meta.get('unit')!s}")]
            if meta.get("profile"):
                parts.append(escape(f"profile {meta['profile']!r}"))
            if meta.get("profile") or meta.get("input_rate_dph"):
                figures.append(_figure("input_rate_dph", "input rate",
                                       meta.get("input_rate_dph"), "°/h"))
                parts.append(f"input rate {_field('input_rate_dph', meta.get('input_rate_dph'))}"
                             " °/h")
            lines.append("  " + ", ".join(parts))
        lines.append("  rows: {rows}")
        if self.axes:
            lines.append(escape(f"  axes: {', '.join(self.axes)} ({len(self.axes)}-axis "
                                "recording; per-axis columns <name>_<axis>)"))
        figures.append(_figure("duration_s", "duration", self.duration_s, "s"))
        duration = f"{_field('duration_s', self.duration_s)} s ({_hours(self.duration_s)})"
        timeline = self.timeline or {}
        if timeline.get("segments"):
            recorded = timeline["recorded_s"]
            figures += [_figure("timeline.recorded_s", "recorded", recorded, "s"),
                        Figure("timeline.segments", "segments", timeline["segments"])]
            lines.append(f"  duration: span {duration}, recorded "
                         f"{_field('timeline.recorded_s', recorded)} s ({_hours(recorded)}) in "
                         "{timeline.segments} segment(s)")
            if timeline["segments"] > 1:
                figures += [_figure(f"timeline.{k}", label, timeline[k], "s")
                            for k, label in (("burst_length_s", "segment length (median)"),
                                             ("burst_period_s", "segment period (median)"),
                                             ("period_s", "sample period (median)"))]
                lines.append(
                    f"  segments: {_field('timeline.burst_length_s', timeline['burst_length_s'])}"
                    " s long (median), one every "
                    f"{_field('timeline.burst_period_s', timeline['burst_period_s'])} s "
                    "(median); " + ("a burst (duty-cycled) logger" if timeline.get("bursty")
                                    else "a logger with pauses")
                    + f"; median period {_field('timeline.period_s', timeline['period_s'])} s")
        else:
            lines.append(f"  duration: {duration}")
        lines += [escape(f"  time: {repair}") for repair in timeline.get("repairs", [])]
        inferred = " (inferred from the time steps)" if self.sample_rate_inferred else ""
        figures += [_figure("sample_rate_hz", "sample rate (metadata)", self.sample_rate_hz,
                            "Hz"),
                    _figure("measured_sample_rate_hz", "sample rate (measured)",
                            self.measured_sample_rate_hz, "Hz")]
        lines.append(f"  sample rate: {_field('sample_rate_hz', self.sample_rate_hz)} Hz in the "
                     f"metadata{inferred}, "
                     f"{_field('measured_sample_rate_hz', self.measured_sample_rate_hz)} Hz "
                     "measured")
        return figures, lines

    def _column_figures(self) -> tuple[list[Figure], list[str]]:
        """The summary's table of the columns (unit, range, steps) and its lines."""
        lines = ["  columns:"]
        columns: list[Figure] = []
        for k, col in enumerate(self.columns):
            unit = f"[{col.unit}]" if col.unit else "[?]"
            key = f"columns[{k}]"  # by place: a file's column name may hold ':' or braces
            columns += [Figure(f"{key}.name", f"{col.name}", col.name, row=col.name,
                               column="column"),
                        Figure(f"{key}.unit", f"{col.name} unit", col.unit or "?", row=col.name,
                               column="unit"),
                        _figure(f"{key}.minimum", f"{col.name} minimum", col.minimum,
                                row=col.name, column="minimum"),
                        _figure(f"{key}.maximum", f"{col.name} maximum", col.maximum,
                                row=col.name, column="maximum")]
            step = ""
            if col.resolution is not None:
                columns.append(Figure(f"{key}.resolution", f"{col.name} steps", col.resolution,
                                      row=col.name, column="steps",
                                      definition="The smallest step between its values."))
                step = f"  (steps of {{{key}.resolution:.3g}})"
            lines.append(f"    {{{key}.name:<16}} {escape(f'{unit:<8}')} "
                         f"{_field(f'{key}.minimum', col.minimum)} .. "
                         f"{_field(f'{key}.maximum', col.maximum)}{step}")
        return columns, lines

    def _span_columns(self) -> list[ColumnSummary]:
        """Temperature and frequency columns (per axis too), in the order of SPAN_COLUMNS."""
        return sorted((c for c in self.columns if base_name(c.name, self.axes) in SPAN_COLUMNS),
                      key=lambda c: SPAN_COLUMNS.index(base_name(c.name, self.axes)))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RecordingInfo:
        """Inverse of :meth:`to_dict` (``spans`` are derived, not read)."""
        values = records.load(data, RecordingInfoRecord, "recording info")
        values.pop("spans")
        return cls(**values | {
            "columns": tuple(values["columns"]),
            "validation": ValidationReport.from_dict(data["validation"])})


class RecordingInfoRecord(Record, kw_only=True):
    """The record of :class:`RecordingInfo` (``spans``, the temperature and frequency
    columns' (min, max), written, not read back)."""

    path: str
    format: str | None = None
    rows: Count
    start_time_s: float | None = None
    end_time_s: float | None = None
    duration_s: float | None = None
    sample_rate_hz: float | None = None
    sample_rate_inferred: bool = False
    measured_sample_rate_hz: float | None = None
    columns: list[ColumnSummaryRecord]
    spans: dict[str, tuple[float | None, float | None]] = records.empty()
    metadata: dict[str, Any] | None = None
    validation: dict[str, Any]
    axes: list[str] = msgspec.field(default_factory=list)
    spike_rows: int | None = None
    timeline: dict[str, Any] | None = None


def _field(name: str, value: Any) -> str:
    """A figure in a summary's layout as :func:`_num` writes it (``?``: not known)."""
    return "?" if value is None else "{" + name + ":.6g}"


def _figure(name: str, label: str, value: Any, unit: str = "", **cells: str) -> Figure:
    """A figure that may not be known (None: NaN, shown as ``-``)."""
    return Figure(name, label, math.nan if value is None else value, unit, **cells)


def _hours(seconds: float | None) -> str:
    return "?" if seconds is None else f"{seconds / 3600.0:.3g} h"


def describe(path: str | Path, options: ReadSettings | None = None, *,
             rows: int | None = None, progress: Progress | None = None,
             **fields: Any) -> RecordingInfo:
    """Summarise and validate a recording file in one streaming pass.

    Parameters
    ----------
    path, options, **fields
        As for :func:`hrgtc.recording.read`: how to read the file, one
        :class:`~hrgtc.recording.ReadOptions` and any of its fields by name. The robust
        spike filter (``spike_filter``) flags and counts by default (None):
        ``metadata["extra"]["spikes_flagged"]``, no row dropped. For the sensor
        thermometer the ``freq_hz*`` columns, copies of the temperature, are not listed.
    rows
        Rows per chunk read; None: ``options.chunk_rows``.
    progress
        Optional ``progress(done, total)`` callback.

    Returns
    -------
    RecordingInfo
        Never raises on a bad or unreadable file (except a missing file): the
        problem is in ``validation`` with ``ok=False``.
    """
    opts = with_fields(options, fields, "describe")
    opts = replace(opts, spike_filter=opts.spike_filter or "flag",
                   chunk_rows=opts.chunk_rows if rows is None else rows)
    thermometer = opts.thermometer
    check_gap_policy(opts.gaps)
    validator = RecordingValidator(opts.gaps, thermometer=thermometer, dropout_s=opts.dropout_s)
    if (dict(opts.units or {}).get("temp") == "count"
            and (opts.temp_scale, opts.temp_offset_c) == (1.0, 0.0)):
        validator.count_temperatures()  # a raw count, no map: not judged as °C
    ranges: dict[str, list[float]] = {}
    steps: dict[str, float] = {}
    spike_rows: int | None = None if opts.spike_filter == "off" else 0
    first_time: float | None = None
    last_time: float | None = None
    meta: Metadata | None = None
    unreadable: str | None = None
    fmt: str | None = None
    names: list[str] = []
    builder: TimelineBuilder | None = None
    repairer = TimeRepairStream()  # filled by iter_chunks: what the time repair did
    file_rows: list[Any] = []  # the file row of each row of the chunk (messages name them)
    try:
        fmt = format_of(path)
        for chunk in iter_chunks(path, opts, validate=False, progress=progress,
                                 time_repair=repairer, file_rows=file_rows.append):
            meta = chunk.metadata
            names = names or [n for n in chunk.names if n != SPIKE_COLUMN
                              and not _sensor_copy(n, chunk.names, thermometer)]
            if SPIKE_COLUMN in chunk:
                spike_rows = (spike_rows or 0) + int(np.count_nonzero(chunk[SPIKE_COLUMN]))
            validator.partial_fit(chunk, file_rows.pop() if file_rows else None)
            if "time_s" in chunk:
                if builder is None:
                    builder = TimelineBuilder(1.0 / meta.sample_rate_hz)
                builder.partial_fit(chunk.time_s)
            for name in names:
                values = chunk[name]
                finite = values[np.isfinite(values)]
                if finite.size:
                    low, high = float(finite.min()), float(finite.max())
                    old = ranges.setdefault(name, [low, high])
                    old[0], old[1] = min(old[0], low), max(old[1], high)
                    if first_time is None:  # the first chunk's
                        step = resolution(finite)
                        if step is not None:
                            steps[name] = step
            if "time_s" in chunk:
                finite = chunk.time_s[np.isfinite(chunk.time_s)]
                if finite.size:
                    first_time = float(finite[0]) if first_time is None else first_time
                    last_time = float(finite[-1])
    except RecordingError as exc:
        unreadable = str(exc).removeprefix(f"{Path(path)}: ")
    report = validator.finish()
    if unreadable is not None:
        so_far = tuple(p for p in report.problems if p.kind != "empty")
        report = ValidationReport(
            ok=False,
            problems=(Problem("unreadable", unreadable), *so_far),
            gaps=report.gaps,
            n_gaps=report.n_gaps,
            rows=report.rows,
            source=str(path),
            measured_sample_rate_hz=report.measured_sample_rate_hz,
            gap_policy=report.gap_policy,
        )
    raw_count = (dict(opts.units or {}).get("temp") in ("count", "counts", "lsb", "raw")
                 and (opts.temp_scale, opts.temp_offset_c) == (1.0, 0.0))
    duration = None
    if first_time is not None and meta is not None:
        duration = last_time - first_time + 1.0 / meta.sample_rate_hz
    timeline: Timeline | None = None if builder is None else builder.finish()
    return RecordingInfo(
        path=str(path),
        format=fmt,
        rows=validator.rows,
        start_time_s=first_time,
        end_time_s=last_time,
        duration_s=duration if duration is None or math.isfinite(duration) else None,
        sample_rate_hz=None if meta is None else meta.sample_rate_hz,
        sample_rate_inferred=bool(meta is not None and meta.extra.get("sample_rate_inferred")),
        measured_sample_rate_hz=report.measured_sample_rate_hz,
        columns=tuple(
            ColumnSummary(n, _unit(n, axis_names(names), thermometer, raw_count),
                          *ranges.get(n, (None, None)), steps.get(n))
            for n in names
        ),
        metadata=None if meta is None else meta.to_dict(),
        validation=report,
        axes=axis_names(names),
        spike_rows=spike_rows,
        timeline=None if timeline is None or not timeline.n_segments else {
            **timeline.to_dict(), "repairs": [e.message for e in repairer.events if e.repaired],
            "duplicates_dropped": repairer.duplicates},
    )


def _sensor_copy(name: str, names: Iterable[str], thermometer: str) -> bool:
    """True for ``freq_hz*`` of the sensor thermometer (a copy of its temperature column)."""
    if thermometer != "sensor" or not name.startswith("freq_hz"):
        return False
    own = "temperature_c" + name[len("freq_hz"):]
    return own in names or "temperature_c" in names


def _unit(name: str, axes: tuple[str, ...], thermometer: str, raw_count: bool = False) -> str:
    """Contract unit of a column (per-axis ones too); ``freq_hz`` of a sensor thermometer: °C.

    ``raw_count``: ``temperature_c*`` holds a raw count not yet mapped to °C (``count``).
    """
    base = base_name(name, axes)
    if raw_count and base == "temperature_c":
        return "count"
    if base == "freq_hz" and thermometer == "sensor":
        return "degC"
    return COLUMNS[base][0] if base in COLUMNS else ""
