"""Reading and writing recordings: users' column names and units, chunks, atomic files.

:func:`read` loads a whole recording, :func:`iter_chunks` streams it in chunks
of a fixed number of rows without loading the file, :func:`write` and
:class:`RecordingWriter` write one atomically (a temporary file in the same
directory, fsync, rename) and never overwrite without ``force=True``. The file
format follows the suffix or the content (see :mod:`hrgtc.recording.formats.registry`);
the streams of a file on several time axes are joined by :mod:`hrgtc.recording.align`.

Users' files are mapped onto the recording contract of DESIGN.md on reading:

* ``columns`` and ``units``: see :mod:`hrgtc.recording.mapping`; the date of the
  first sample of a file with timestamps is kept as ``extra["time_origin"]``;
* ``temp_scale``/``temp_offset_c`` (a temperature logged as a raw count) and
  ``thermometer="sensor"`` (a gyro without a frequency output): see
  :mod:`hrgtc.recording.mapping`; the sensor thermometer sets
  ``extra["thermometer"] = "sensor"``;
* ``spikes``: ``"error"`` or ``"drop"`` (see :mod:`hrgtc.recording.spikes`); rows
  dropped are counted in ``extra["spikes_dropped"]`` (by :func:`read`) and a
  :class:`~hrgtc.core.errors.SpikeWarning`;
* odd time steps (see :mod:`hrgtc.core.time_steps`): a wrapped 32-bit µs/ms
  counter is unwrapped, a logger reset to about zero starts a new segment (later
  times follow after a gap), duplicated rows are dropped; :func:`read` lists what
  was done in ``extra["time_repairs"]`` (and ``extra["duplicates_dropped"]``); the
  steps that cannot be repaired (a daylight-saving step in clock times, a step back
  of unknown cause) are left to the validation, which names their kind and row;
* missing metadata: ``metadata=`` overrides or completes the file's metadata;
  without a sample rate anywhere it is inferred from the median time step of the
  first rows, and ``extra["sample_rate_inferred"]`` is set to True.

Multi-axis files (``rate_dph_x``, ...) are read like single-axis ones and
validated axis by axis; :func:`hrgtc.recording.axis_view` gives one axis.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError, RecordingError
from hrgtc.core.progress import Progress
from hrgtc.core.time_steps import TimeRepairStream
from hrgtc.recording.align import align, warn_alignment
from hrgtc.recording.axes import axis_view
from hrgtc.recording.file_rows import take_file_rows, with_file_rows
from hrgtc.recording.formats.base import Source
from hrgtc.recording.formats.registry import open_streams
from hrgtc.recording.mapping import (
    ColumnPlan,
    convert_columns,
    plan_columns,
    scales_temperature,
    table_columns,
)
from hrgtc.recording.rechunk import rechunk
from hrgtc.recording.resample import SlowChannels, fill_slow_channels
from hrgtc.recording.schema import SCHEMA_VERSION, Metadata, Recording, concatenate
from hrgtc.recording.spikes import (
    RobustSpikeFilter,
    SpikeFilter,
    check_spike_policy,
)
from hrgtc.recording.time_axis import (
    _repair_extra,
    _repair_time,
    _restarts_extra,
    _time_repairer,
    _TimeSlice,
)
from hrgtc.recording.validation import (
    HEURISTIC_ROWS,
    GapPolicy,
    RecordingValidator,
    check_gap_policy,
    measured_sample_rate,
)
from hrgtc.recording.validation import validate as validate_recording
from hrgtc.recording.writing import RecordingWriter, write
from hrgtc.settings.reading import CHUNK_ROWS, ReadSettings

_READ = ReadSettings
#: The options of messy files, passed to :func:`read` only when they differ from their
#: defaults.
_MESSY = ("temp_scale", "temp_offset_c", "spikes", "thermometer", "rate_scale",
          "temp_unwrap", "spike_filter", "spike_k", "spike_lsb", "spike_window_s",
          "slow_channels", "hold_max_s")

#: Metadata key counting the rows of robust spikes, by ``spike_filter``.
_SPIKE_KEYS = {"drop": "spikes_removed", "flag": "spikes_flagged"}

__all__ = ["ReadOptions", "RecordingWriter", "count_rows", "iter_chunks", "open_source", "read",
           "write"]


def open_source(path: str | Path, slow_channels: str = "hold",
                hold_max_s: float | None = None) -> Source:
    """Open a recording file for reading as one stream.

    The format is chosen by the registry (:func:`~hrgtc.recording.formats.format_for`:
    by suffix, else by content); a file of several streams is aligned onto one time
    axis (:func:`hrgtc.recording.align.align`, ``slow_channels`` and ``hold_max_s`` as
    in :func:`read`).
    """
    return align(open_streams(path), slow_channels, hold_max_s)


def count_rows(path: str | Path) -> int:
    """Number of data rows of a recording file, without reading its values.

    Exact; Parquet and HDF5 from their metadata, CSV by counting its non-empty
    lines (a fast scan of the bytes). Use it as the ``total`` of a progress bar.
    """
    with open_source(path) as source:
        return source.count_rows()


def _metadata(
    plan: ColumnPlan, override: Mapping[str, Any] | Metadata | None, time_s: np.ndarray | None
) -> Metadata:
    """The file's metadata, completed by ``override`` and, failing that, inference."""
    path = plan.source.path
    if isinstance(override, Metadata):
        return override
    data = dict(plan.source.metadata)
    data.update({k: v for k, v in (override or {}).items() if v is not None})
    if not isinstance(data.get("extra") or {}, Mapping):
        raise RecordingError(f"{path}: metadata extra is {data.get('extra')!r}, not a JSON "
                             "object of key/value pairs; fix or remove it")
    extra = dict(data.get("extra") or {})
    if (override or {}).get("sample_rate_hz") is not None:
        extra.pop("sample_rate_inferred", None)
    try:
        schema = int(data.get("schema", SCHEMA_VERSION))
    except (TypeError, ValueError):
        schema = SCHEMA_VERSION + 1
    if schema > SCHEMA_VERSION:
        raise RecordingError(
            f"{path}: recording schema {data.get('schema')!r} is newer than this hrgtc "
            f"understands ({SCHEMA_VERSION}); upgrade hrgtc"
        )
    if time_s is not None and len(time_s) == 0:
        raise RecordingError(f"{path}: the recording has no rows")
    if data.get("sample_rate_hz") is None:
        if time_s is None:
            raise RecordingError(
                f"{path}: required column 'time_s' missing (the file's columns are "
                f"{plan.source.names}); map yours with --col time_s=<your column>"
            )
        rate = measured_sample_rate(time_s[:HEURISTIC_ROWS])
        if rate is None:
            raise RecordingError(
                f"{path}: no sample_rate_hz in the metadata and none can be inferred (time_s "
                "has no increasing step); give it with --rate-hz (metadata={'sample_rate_hz': ...})"
            )
        data["sample_rate_hz"] = rate
        extra["sample_rate_inferred"] = True
    if plan.thermometer == "sensor":
        extra["thermometer"] = "sensor"
    if plan.wrap_bits is not None:
        extra["temperature_count_bits"] = plan.wrap_bits
    if plan.time_origin_ns is not None and "time_origin" not in extra:
        extra["time_origin"] = str(np.datetime64(plan.time_origin_ns, "ns"))
        if plan.tz is not None:  # clock times read in a zone: the origin is UTC
            extra["time_zone"] = plan.tz
    data["extra"] = extra
    try:
        return Metadata.from_dict(data)
    except RecordingError as exc:
        raise RecordingError(f"{path}: {exc}") from None


# -- reading -------------------------------------------------------------------
def read(
    path: str | Path,
    columns: Mapping[str, str] | Iterable[str] | None = None,
    units: Mapping[str, str] | None = None,
    validate: bool = True,
    gaps: GapPolicy | str = _READ.gaps,
    metadata: Mapping[str, Any] | Metadata | None = None,
    freq_band_hz: tuple[float, float] | None = None,
    freq_span_hz: tuple[float, float] | None = None,
    *,
    temp_scale: float = _READ.temp_scale,
    temp_offset_c: float = _READ.temp_offset_c,
    spikes: str = _READ.spikes,
    thermometer: str = _READ.thermometer,
    rate_scale: float | None = _READ.rate_scale,
    temp_unwrap: str = _READ.temp_unwrap,
    spike_filter: str = "off",
    spike_k: float = _READ.spike_k,
    spike_lsb: float = _READ.spike_lsb,
    spike_window_s: float = _READ.spike_window_s,
    start: str | float | None = None,
    end: str | float | None = None,
    slow_channels: str = _READ.slow_channels,
    hold_max_s: float | None = _READ.hold_max_s,
    tz: str | None = _READ.tz,
) -> Recording:
    """Read a whole recording from Parquet, CSV, HDF5 or a registered format.

    Parameters
    ----------
    path
        ``.parquet``/``.pq``, ``.csv`` or ``.h5``/``.hdf5`` file, or one of a format
        registered by another package (:mod:`hrgtc.recording.formats.registry`).
    columns
        Contract name -> the file's column name (or ``"time_s=t"`` strings).
    units
        ``{"time": "s"|"ms"|"timestamp", "freq": "Hz"|"kHz", "rate": "dph"|"dps"|"radps"}``
        (also ``°/h``, ``°/s``, ``rad/s``); converted to s, Hz and °/h.
    validate
        Check the recording (:func:`hrgtc.recording.validate`) and raise on a problem.
    gaps
        Gap policy of the validation: ``"error"``, ``"split"`` or ``"ignore"``.
    metadata
        Keys that complete or override the file's metadata (e.g.
        ``{"sample_rate_hz": 200, "unit": "SN 12"}``), or a whole :class:`Metadata`.
    freq_band_hz, freq_span_hz
        With a model: frequencies outside ``freq_band_hz`` are errors (instead of the
        physical range), ``freq_span_hz`` (the calibrated span) is named in the message.
    temp_scale, temp_offset_c
        ``temperature_c* = raw * temp_scale + temp_offset_c`` (a raw sensor count). [°C]
    spikes
        ``"error"`` (the validation names file, column, row and value) or ``"drop"``
        (rows with a non-finite or implausible value are removed, and counted).
    thermometer
        ``"resonator"`` or ``"sensor"``: ``freq_hz`` is the ``temperature_c`` column.
    rate_scale
        LSB per °/s of a rate logged as a raw count (``units={"rate": "lsb"}``).
    temp_unwrap
        ``"auto"``: a raw temperature count (a count unit, ``temp_scale`` or
        ``temp_offset_c``) that sits just under 2^16 or 2^32 is a signed count stored
        unsigned and is unwrapped (65236 -> -300), with a
        :class:`~hrgtc.core.errors.UnitWarning` and ``extra["temperature_count_bits"]``;
        ``"off"``: read as it is.
    spike_filter
        Single-sample spikes of plausible value in the rate and thermometer columns
        (:func:`hrgtc.recording.spikes.find_spikes`): ``"off"``, ``"drop"`` (rows
        removed, counted in ``extra["spikes_removed"]``) or ``"flag"`` (rows kept,
        a ``spike`` column 1.0 at them, counted in ``extra["spikes_flagged"]``);
        one :class:`~hrgtc.core.errors.SpikeWarning` says how many and where.
    spike_k, spike_lsb, spike_window_s
        Threshold max(k·σ_MAD, m·LSB) and window [s] of the spike filter.
    start, end
        Keep only the rows from ``start`` to before ``end`` (``--start/--end``): seconds
        since the file's first sample, or ISO clock times for a file with clock times
        (e.g. ``"2020-03-07T16:30"``). Rows left out are counted in
        ``extra["rows_sliced"]``; row numbers in later messages count the rows kept.
    slow_channels, hold_max_s
        A channel logged slower than the rows (empty cells), or a stream of the file on
        its own time axis: ``"hold"`` (default), ``"interpolate"`` or ``"error"``, for at
        most ``hold_max_s`` seconds (:mod:`hrgtc.recording.resample`,
        :mod:`hrgtc.recording.align`).
    tz
        IANA zone (``"Europe/Berlin"``) the naive clock times were written in: read as
        UTC, the daylight saving step is gone (:class:`~hrgtc.recording.time_axis.ZoneClock`).

    Returns
    -------
    Recording
        Float64 columns in the contract's names and units; ``source`` is ``path``.

    Raises
    ------
    RecordingError
        Unreadable file, unknown suffix, unknown column, or a validation problem;
        the message names the file, column and row and says how to fix it.
    """
    check_gap_policy(gaps)
    check_spike_policy(spikes)
    spike_filter_ = SpikeFilter(thermometer, str(path)) if spikes == "drop" else None
    robust = RobustSpikeFilter(spike_filter, thermometer, str(path), k=spike_k,
                               lsb_multiple=spike_lsb, window_s=spike_window_s)
    with open_source(path, slow_channels, hold_max_s) as source:
        plan = plan_columns(source, columns, units, temp_scale, temp_offset_c, thermometer,
                            rate_scale, temp_unwrap, tz)
        robust.counts = plan.temperature_is_count and not scales_temperature(temp_scale,
                                                                           temp_offset_c)
        columns = table_columns(source.read(plan.read_names, plan.as_text))
        arrays = with_file_rows(convert_columns(plan, columns, 0), 0)
        arrays, slow = fill_slow_channels(arrays, slow_channels, hold_max_s, str(path))
        if spike_filter_ is not None:
            arrays = spike_filter_.drop(arrays, 0)
        arrays = robust.apply(arrays, 0)
        repairer = _time_repairer(plan)
        arrays = _repair_time(arrays, repairer, plan)
        cut = _TimeSlice(start, end, plan)
        arrays, file_rows = take_file_rows(cut.apply(arrays))
        meta = _metadata(plan, metadata, arrays.get("time_s"))
    if repairer.events or repairer.duplicates:
        meta = replace(meta, extra={**meta.extra, **_repair_extra(repairer)})
    warn_alignment(source)
    slow.warn()
    if spike_filter_ is not None and spike_filter_.dropped:
        meta = replace(meta, extra={**meta.extra, "spikes_dropped": spike_filter_.dropped})
        spike_filter_.warn()
    if spike_filter != "off":
        meta = replace(meta, extra={**meta.extra, _SPIKE_KEYS[spike_filter]: robust.rows})
        robust.warn()
    if cut.dropped:
        meta = replace(meta, extra={**meta.extra, "rows_sliced": cut.dropped})
    recording = Recording(arrays, meta, source=str(path))
    if validate:
        validate_recording(recording, gaps, freq_band_hz=freq_band_hz, freq_span_hz=freq_span_hz,
                           thermometer=thermometer, file_rows=file_rows)
    return recording


def iter_chunks(
    path: str | Path,
    rows: int = CHUNK_ROWS,
    columns: Mapping[str, str] | Iterable[str] | None = None,
    units: Mapping[str, str] | None = None,
    validate: bool = True,
    gaps: GapPolicy | str = _READ.gaps,
    metadata: Mapping[str, Any] | Metadata | None = None,
    progress: Progress | None = None,
    freq_band_hz: tuple[float, float] | None = None,
    freq_span_hz: tuple[float, float] | None = None,
    *,
    temp_scale: float = _READ.temp_scale,
    temp_offset_c: float = _READ.temp_offset_c,
    spikes: str = _READ.spikes,
    thermometer: str = _READ.thermometer,
    rate_scale: float | None = _READ.rate_scale,
    temp_unwrap: str = _READ.temp_unwrap,
    spike_filter: str = "off",
    spike_k: float = _READ.spike_k,
    spike_lsb: float = _READ.spike_lsb,
    spike_window_s: float = _READ.spike_window_s,
    time_repair: TimeRepairStream | None = None,
    start: str | float | None = None,
    end: str | float | None = None,
    slow_channels: str = _READ.slow_channels,
    hold_max_s: float | None = _READ.hold_max_s,
    dropped: dict[str, int] | None = None,
    tz: str | None = _READ.tz,
    file_rows: Callable[[np.ndarray | None], None] | None = None,
) -> Iterator[Recording]:
    """Stream a recording in chunks of ``rows`` rows without loading the file.

    Parameters are those of :func:`read`, plus:

    rows
        Rows per chunk (the last chunk may be shorter).
    file_rows
        Called with the file rows of the next chunk's rows before it is yielded.
    progress
        Called as ``progress(done, total)`` after each chunk (rows, or bytes for CSV).
    dropped
        A dict the caller reads once the chunks are exhausted: its ``"spikes"`` is
        then the count of rows the spike filters removed (``spikes="drop"`` and
        ``spike_filter="drop"``), for the caller's :class:`~hrgtc.core.Accounting`.

    Yields
    ------
    Recording
        Consecutive chunks, all with the same metadata. Validation carries its
        state across chunks (time continuity, global row numbers); a chunk is
        yielded only after its rows (and the unit heuristics of the first
        :data:`~hrgtc.recording.validation.HEURISTIC_ROWS` rows) have passed, so a
        bad file raises :class:`~hrgtc.core.errors.RecordingError` before bad data
        reach the caller. With ``gaps="split"`` gaps pass; split downstream. The time
        axis is repaired as by :func:`read` (``time_repair``: a
        :class:`~hrgtc.core.time_steps.TimeRepairStream` to use, whose events and counts
        the caller reads afterwards) and sliced by ``start``/``end``. With
        ``spikes="drop"`` the rows of spikes are left out before the chunks are cut
        (the rows of later problems then count the rows kept).
    """
    check_gap_policy(gaps)
    check_spike_policy(spikes)
    spike_filter_ = SpikeFilter(thermometer, str(path)) if spikes == "drop" else None
    robust = RobustSpikeFilter(spike_filter, thermometer, str(path), k=spike_k,
                               lsb_multiple=spike_lsb, window_s=spike_window_s)
    if int(rows) < 1:
        raise InputError(f"rows must be a positive number of rows per chunk, got {rows!r}")
    rows = int(rows)
    validator = (RecordingValidator(gaps, freq_band_hz, freq_span_hz, thermometer)
                 if validate else None)
    slow = SlowChannels(slow_channels, hold_max_s, str(path))
    with open_source(path, slow_channels, hold_max_s) as source:
        plan = plan_columns(source, columns, units, temp_scale, temp_offset_c, thermometer,
                            rate_scale, temp_unwrap, tz)
        robust.counts = plan.temperature_is_count and not scales_temperature(temp_scale,
                                                                           temp_offset_c)
        offset = 0
        repairer = _time_repairer(plan)
        if time_repair is not None:  # the caller's, to read what was repaired
            time_repair.time_unit, time_repair.naive_clock = (repairer.time_unit,
                                                              repairer.naive_clock)
            time_repair.source = repairer.source
            repairer = time_repair
        cut = _TimeSlice(start, end, plan)

        def converted() -> Iterator[dict[str, np.ndarray]]:
            nonlocal offset
            for table in source.iter_tables(plan.read_names, plan.as_text, rows):
                part = slow.fill(with_file_rows(convert_columns(plan, table_columns(table),
                                                                offset), offset), offset)
                if spike_filter_ is not None:
                    part = spike_filter_.drop(part, offset)
                part = robust.apply(part, offset)
                offset += table.num_rows
                part = cut.apply(_repair_time(part, repairer, plan))
                if part.get("time_s") is None or len(part["time_s"]):
                    yield part
            tail = slow.flush()  # rows held back by --slow-channels interpolate
            if tail is not None:
                if spike_filter_ is not None:
                    tail = spike_filter_.drop(tail, offset)
                tail = cut.apply(_repair_time(robust.apply(tail, offset), repairer, plan))
                if tail.get("time_s") is None or len(tail["time_s"]):
                    yield tail

        pieces = rechunk(converted(), rows)
        head: list[dict[str, np.ndarray]] = []
        held = 0
        for piece in pieces:  # hold back the first rows: metadata may be inferred from them
            head.append(piece)
            held += len(next(iter(piece.values())))
            if held >= HEURISTIC_ROWS:
                break
        time_head = (
            np.concatenate([p["time_s"] for p in head])
            if head and "time_s" in head[0]
            else (np.empty(0) if not head else None)
        )
        meta = _metadata(plan, metadata, time_head)
        pending: list[Recording] = []

        def chunk_meta() -> Metadata:  # with the logger restarts found so far (new runs)
            restarts = _restarts_extra(repairer)
            return replace(meta, extra={**meta.extra, **restarts}) if restarts else meta

        def chunks() -> Iterator[tuple[Recording, np.ndarray | None]]:
            held, parts = list(head), pieces
            head.clear()
            for p in itertools.chain(held, parts):  # the file rows go to the validator
                part, file_rows = take_file_rows(p)
                yield Recording(part, chunk_meta(), source=str(path)), file_rows

        for chunk, rows_of_file in chunks():
            if file_rows is not None:
                file_rows(rows_of_file)
            if validator is not None:
                validator.partial_fit(chunk, rows_of_file)
                validator.raise_for_problems()
            pending.append(chunk)
            if validator is None or validator.heuristics_done:
                yield from pending
                pending.clear()
            if progress is not None:
                progress(*source.position())
        if validator is not None:
            validator.finish().raise_for_problems()
        if spike_filter_ is not None:
            spike_filter_.warn()
        robust.warn()
        warn_alignment(source)
        slow.warn()
        if dropped is not None:
            dropped["spikes"] = dropped.get("spikes", 0) + (
                (spike_filter_.dropped if spike_filter_ is not None else 0)
                + (robust.rows if robust.mode == "drop" else 0))
        if progress is not None:
            total = source.position()[1]
            progress(total, total)
        yield from pending


@dataclass(frozen=True)
class ReadOptions(ReadSettings):
    """How to read a user's files: the reading options of every command, as one value.

    The command line's ``--col``, ``--time-unit``, ``--freq-unit``, ``--rate-unit``,
    ``--rate-hz``, ``--unit-name``, ``--input-rate-dph``, ``--gaps``, ``--temp-scale``,
    ``--temp-offset``, ``--spikes`` and ``--thermometer`` become one ``ReadOptions``,
    which the library's functions that read runs take as ``read_options=``.

    Parameters
    ----------
    columns
        Recording column -> the file's column (see :func:`read`).
    units
        ``{"time"|"freq"|"rate"|"temp": unit}`` of the file's columns (see
        :mod:`hrgtc.recording.units`).
    metadata
        Metadata overrides (``sample_rate_hz``, ``unit``, ``input_rate_dph``).
    gaps
        ``"error"``, ``"split"`` or ``"ignore"`` (see :func:`read`).
    chunk_rows
        Rows per chunk when a file is streamed.
    freq_band_hz, freq_span_hz
        Plausible frequencies and the calibrated span of the model the run is
        compensated with (set by compensation and evaluation, see :func:`read`).
    temp_scale, temp_offset_c
        ``temperature_c* = raw * temp_scale + temp_offset_c`` (a raw sensor count). [°C]
    spikes
        ``"error"`` (default) or ``"drop"`` (see :func:`read`).
    thermometer
        ``"resonator"`` (default: ``freq_hz`` is the resonator frequency) or
        ``"sensor"`` (a gyro without a frequency output: ``freq_hz`` is filled from
        ``temperature_c``, per axis from ``temperature_c_<axis>``). [°C]
    axis
        Read one axis of a multi-axis file: every axis is validated, the single-axis
        view of this one returned (:func:`~hrgtc.recording.axis_view`), and the
        plausible band checked on its frequency only. None: the file as it is.
    rate_scale
        LSB per °/s of a rate logged as a raw count (``--rate-unit lsb --rate-scale K``).
    temp_unwrap
        ``"auto"`` or ``"off"``: a signed temperature count stored unsigned (see :func:`read`).
    spike_filter, spike_k, spike_lsb, spike_window_s
        The robust spike filter (see :func:`read`); ``spike_filter`` None: the
        command's default (``calibrate``/``evaluate`` drop, ``compensate`` flags),
        ``"off"`` in the library.
    motion
        Samples not at rest (:mod:`hrgtc.recording.motion`) in calibration and
        evaluation: ``"exclude"`` (left out and counted, default), ``"keep"`` (used, not
        checked) or ``"error"``. Reading itself never drops them.
    start, end
        ``--start/--end``: the slice of the file to read, seconds since its first
        sample or ISO clock times (see :func:`read`). None: from the start / to the end.
    slow_channels, hold_max_s
        Channels logged slower than the rows: ``"hold"``, ``"interpolate"`` or
        ``"error"``, values used for at most ``hold_max_s`` seconds (see :func:`read`).
    tz
        ``--tz``: the IANA time zone naive clock times were written in (see :func:`read`).
    """

    def keywords(self) -> dict[str, Any]:
        """The options as keyword arguments of :func:`read` and :func:`iter_chunks`.

        The options of messy files (``temp_scale``, ``temp_offset_c``, ``spikes``,
        ``thermometer``) only when they differ from their defaults.
        """
        words = {"columns": self.columns, "units": self.units, "metadata": self.metadata,
                 "gaps": self.gaps}
        if self.freq_band_hz is not None:
            words.update(freq_band_hz=self.freq_band_hz, freq_span_hz=self.freq_span_hz)
        defaults = {field.name: field.default for field in fields(ReadSettings)
                    if field.name in _MESSY}
        words.update({key: getattr(self, key) for key, default in defaults.items()
                      if getattr(self, key) != default})
        words.update({key: getattr(self, key) for key in ("start", "end", "tz")
                      if getattr(self, key) is not None})
        return words

    def with_spike_default(self, mode: str) -> ReadOptions:
        """These options with ``spike_filter`` set to ``mode`` unless the user chose one."""
        return self if self.spike_filter is not None else replace(self, spike_filter=mode)

    def read(self, path: str | Path, keep: Sequence[str] | None = None) -> Recording:
        """The whole file; with ``keep``, streamed keeping only those columns (less memory)."""
        if keep is None and self.axis is None:
            return read(path, **self.keywords())
        if keep is None:
            return concatenate(list(self.chunks(path)))
        parts = [Recording({k: c[k] for k in keep if k in c}, c.metadata, c.source)
                 for c in self.chunks(path)]
        return concatenate(parts)

    def head(self, path: str | Path, rows: int = 10_000) -> Recording:
        """The first ``rows`` rows of a file (its columns and metadata), file closed after."""
        chunks = self.chunks(path, rows=rows)
        try:
            return next(chunks)
        except StopIteration:
            raise InputError(f"{path}: the recording holds no rows") from None
        finally:
            chunks.close()

    def chunks(self, path: str | Path, rows: int | None = None,
               dropped: dict[str, int] | None = None,
               time_repair: TimeRepairStream | None = None) -> Iterator[Recording]:
        """Stream the file in chunks (:func:`iter_chunks`); with ``axis``, that axis's view.
        ``dropped``: filled with the rows the spike filters removed (see there);
        ``time_repair``: a stream whose counts (duplicates dropped) the caller reads after."""
        if self.axis is None:
            return iter_chunks(path, rows=rows or self.chunk_rows, dropped=dropped,
                               time_repair=time_repair,
                               **self.keywords())
        words = self.keywords()
        words["time_repair"] = time_repair
        words.pop("freq_band_hz", None)
        words.pop("freq_span_hz", None)
        return self._axis_chunks(iter_chunks(path, rows=rows or self.chunk_rows,
                                             dropped=dropped, **words), str(path))

    def _axis_chunks(self, chunks: Iterator[Recording], path: str) -> Iterator[Recording]:
        axis = str(self.axis)
        row = 0
        try:
            for chunk in chunks:
                view = axis_view(chunk, axis)
                band = self.freq_band_hz
                if band is not None and len(view):
                    freq = view.freq_hz
                    bad = np.flatnonzero(~((freq >= band[0]) & (freq <= band[1])))
                    if bad.size:
                        raise RecordingError(
                            f"{path}: column freq_hz_{axis}, row {row + int(bad[0])}: "
                            f"{float(freq[bad[0]])!r} is outside the band "
                            f"{band[0]:.6g}-{band[1]:.6g} this axis of the model can reach "
                            f"({bad.size} such rows in the chunk); is it another unit's file, "
                            "or the wrong column?")
                row += len(chunk)
                yield view
        finally:
            chunks.close()
