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
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError, RecordingError
from hrgtc.core.progress import Progress
from hrgtc.core.time_steps import TimeRepairStream
from hrgtc.recording.align import align, warn_alignment
from hrgtc.recording.axis_views import axis_views
from hrgtc.recording.axis_views import check_axis_band as check_axis_band  # its old home
from hrgtc.recording.file_rows import RemovedInSlice, take_file_rows, with_file_rows
from hrgtc.recording.formats.base import Source
from hrgtc.recording.formats.registry import open_streams
from hrgtc.recording.mapping import (
    ColumnPlan,
    convert_columns,
    parse_columns,
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
    _time_repairer,
    _TimeSlice,
    warn_restarts,
    with_restarts,
)
from hrgtc.recording.validated import known_report, remember, validation_key
from hrgtc.recording.validation import (
    HEURISTIC_ROWS,
    RecordingValidator,
    check_gap_policy,
    measured_sample_rate,
)
from hrgtc.recording.validation import validate as validate_recording
from hrgtc.recording.writing import RecordingWriter, write
from hrgtc.settings.reading import ReadSettings, with_fields

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
    if plan.found:  # said by info, kept in the outputs' metadata
        extra["columns_found"] = dict(plan.found)
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
def read(path: str | Path, options: ReadSettings | None = None, *, validate: bool = True,
         **fields: Any) -> Recording:
    """Read a whole recording from Parquet, CSV, HDF5 or a registered format.

    Parameters
    ----------
    path
        ``.parquet``/``.pq``, ``.csv`` or ``.h5``/``.hdf5`` file, or one of a format
        registered by another package (:mod:`hrgtc.recording.formats.registry`).
    options
        How to read the file (:class:`ReadOptions`, its fields described there); None:
        the defaults.
    validate
        Check the recording (:func:`hrgtc.recording.validate`) and raise on a problem.
    **fields
        Any field of :class:`ReadOptions` by name, in place of that of ``options``
        (``read(path, columns={"time_s": "t"}, units={"rate": "dps"}, spikes="drop")``).
        ``spike_filter`` None (the default) is ``"off"``; with ``axis``, that axis's view
        (:func:`~hrgtc.recording.axis_view`) of the file validated as a whole.

    Notes
    -----
    What reading does with the options: ``columns`` and ``units`` map the file's
    columns and units onto the contract's (converted to s, Hz and °/h); ``metadata``
    completes or overrides the file's (e.g. ``{"sample_rate_hz": 200, "unit": "SN
    12"}``, or a whole :class:`Metadata`); ``spikes="drop"`` removes the rows with a
    non-finite or implausible value and counts them (``extra["spikes_dropped"]``);
    ``temp_unwrap="auto"`` unwraps a signed temperature count stored unsigned, with a
    :class:`~hrgtc.core.errors.UnitWarning` and ``extra["temperature_count_bits"]``;
    ``spike_filter`` ``"drop"`` or ``"flag"`` removes or flags single-sample spikes
    (:func:`hrgtc.recording.spikes.find_spikes`, counted in ``extra["spikes_removed"]``
    or ``extra["spikes_flagged"]``, one :class:`~hrgtc.core.errors.SpikeWarning`);
    ``start``/``end`` keep a slice (rows left out counted in ``extra["rows_sliced"]``;
    row numbers in later messages count the rows kept); ``slow_channels`` fills the
    empty cells of channels logged slower than the rows, or joins the streams of a file on
    their own time axes (:mod:`hrgtc.recording.resample`, :mod:`hrgtc.recording.align`);
    ``tz`` reads naive clock times in that zone as UTC, so the daylight-saving step is gone
    (:class:`~hrgtc.recording.time_axis.ZoneClock`).

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
    opts = with_fields(options, fields, "read")
    if opts.axis is not None:  # one axis of a multi-axis file
        return concatenate(list(iter_chunks(path, opts, validate=validate)))
    spike_filter, robust = _spike_filters(opts, path)
    with open_source(path, opts.slow_channels, opts.hold_max_s) as source:
        plan = _plan(source, opts, robust, spike_filter)
        arrays = with_file_rows(convert_columns(plan, table_columns(
            source.read(plan.read_names, plan.as_text)), 0), 0)
        if validate and plan.map_problem:  # before any check judges the mapped values
            raise RecordingError(plan.map_problem)
        arrays, slow = fill_slow_channels(arrays, opts.slow_channels, opts.hold_max_s, str(path))
        if spike_filter is not None:
            arrays = spike_filter.drop(arrays, 0)
        arrays = robust.apply(arrays, 0)
        repairer = _time_repairer(plan)
        arrays = _repair_time(arrays, repairer, plan)
        cut = _TimeSlice(opts.start, opts.end, plan)
        arrays, file_rows = take_file_rows(cut.apply(arrays))
        meta = _metadata(plan, opts.metadata, arrays.get("time_s"))
    if repairer.events or repairer.duplicates:
        meta = replace(meta, extra={**meta.extra, **_repair_extra(repairer)})
    warn_alignment(source)
    slow.warn()
    if spike_filter is not None and spike_filter.dropped:
        meta = replace(meta, extra={**meta.extra, "spikes_dropped": spike_filter.dropped})
        spike_filter.warn()
    if robust.mode != "off":
        meta = replace(meta, extra={**meta.extra, _SPIKE_KEYS[robust.mode]: robust.rows})
        robust.warn()
    if cut.dropped:
        meta = replace(meta, extra={**meta.extra, "rows_sliced": cut.dropped})
    recording = Recording(arrays, meta, source=str(path))
    if validate:
        validate_recording(recording, opts.gaps, freq_band_hz=opts.freq_band_hz,
                           freq_span_hz=opts.freq_span_hz, thermometer=opts.thermometer,
                           file_rows=file_rows, dropout_s=opts.dropout_s,
                           temperature_counts=robust.counts).warn_bridged()
        warn_restarts(repairer)  # a file that passes: a wrong diagnosis never precedes an error
    return recording


def _spike_filters(opts: ReadSettings, path: str | Path,
                   default: str = "off") -> tuple[SpikeFilter | None, RobustSpikeFilter]:
    """The filters of ``spikes="drop"`` (None otherwise) and of ``spike_filter`` (its
    ``default`` when None), after checking the policies."""
    check_gap_policy(opts.gaps)
    check_spike_policy(opts.spikes)
    drop = SpikeFilter(opts.thermometer, str(path)) if opts.spikes == "drop" else None
    robust = RobustSpikeFilter(opts.spike_filter or default, opts.thermometer, str(path),
                               k=opts.spike_k, lsb_multiple=opts.spike_lsb,
                               window_s=opts.spike_window_s)
    return drop, robust


def _plan(source: Source, opts: ReadSettings, robust: RobustSpikeFilter,
          drop: SpikeFilter | None = None) -> ColumnPlan:
    """How to read the columns of ``source`` with ``opts`` (the spike filters told
    whether the temperature is a raw count, not yet in °C)."""
    plan = plan_columns(source, opts.columns, opts.units, opts.temp_scale, opts.temp_offset_c,
                        opts.thermometer, opts.rate_scale, opts.temp_unwrap, opts.tz)
    robust.counts = plan.temperature_is_count and not scales_temperature(opts.temp_scale,
                                                                       opts.temp_offset_c)
    if drop is not None:
        drop.counts = robust.counts
    return plan


def iter_chunks(path: str | Path, options: ReadSettings | None = None, *,
                validate: bool = True,
                progress: Progress | None = None, time_repair: TimeRepairStream | None = None,
                dropped: dict[str, int] | None = None,
                file_rows: Callable[[np.ndarray | None], None] | None = None,
                only: Collection[str] | None = None,
                **fields: Any) -> Iterator[Recording]:
    """Stream a recording in chunks of ``rows`` rows without loading the file.

    Parameters are those of :func:`read` (``options``, ``validate`` and any field of
    :class:`ReadOptions` by name: ``chunk_rows`` is the rows per chunk, the last chunk
    may be shorter), plus:

    file_rows
        Called with the file rows of the next chunk's rows before it is yielded.
    progress
        Called as ``progress(done, total)`` after each chunk (rows, or bytes for CSV).
    time_repair
        A :class:`~hrgtc.core.time_steps.TimeRepairStream` to repair the time axis with,
        whose events and counts the caller reads afterwards.
    dropped
        A dict the caller reads once the chunks are exhausted: its ``"spikes"`` is
        then the count of rows the spike filters removed (``spikes="drop"`` and
        ``spike_filter="drop"``), for the caller's :class:`~hrgtc.core.Accounting`.
    only
        Read only the file's columns of these contract names (``"rate_dph"`` stands for
        every axis's; :meth:`~hrgtc.recording.mapping.ColumnPlan.only`). The rows may
        then differ from those of the whole file's: a row the reader drops because of
        another column (``spikes="drop"``, a gap of a slow channel, a duplicated row told
        from a duplicated time by the other columns) is kept. For a pass whose result
        the caller checks against the whole file's rows (``hrgtc.compensate.at_rest``), with
        ``validate=False`` (the validation asks for every column).

    Yields
    ------
    Recording
        Consecutive chunks, all with the same metadata. Validation carries its
        state across chunks (time continuity, global row numbers); a chunk is
        yielded only after its rows (and the unit heuristics of the first
        :data:`~hrgtc.recording.validation.HEURISTIC_ROWS` rows) have passed, so a
        bad file raises :class:`~hrgtc.core.errors.RecordingError` before bad data
        reach the caller. With ``gaps="split"`` gaps pass; split downstream. The time
        axis is repaired as by :func:`read` and sliced by ``start``/``end``. With
        ``axis``, each chunk's view of that axis, its frequency checked against
        ``freq_band_hz`` (the file validated as a whole, without the band). With
        ``spikes="drop"`` the rows of spikes are left out before the chunks are cut
        (the rows of later problems then count the rows kept).
    """
    opts = with_fields(options, fields, "iter_chunks")
    rows = opts.chunk_rows
    if opts.axis is not None:  # the views of one axis, the file validated as a whole
        whole = replace(opts, axis=None, freq_band_hz=None, freq_span_hz=None)
        yield from axis_views(iter_chunks(path, whole, validate=validate,
                                           progress=progress, time_repair=time_repair,
                                           dropped=dropped, file_rows=file_rows,
                                           only=only),
                               opts.axis, opts.freq_band_hz, str(path))
        return
    spike_filter, robust = _spike_filters(opts, path)
    if int(rows) < 1:
        raise InputError(f"rows must be a positive number of rows per chunk, got {rows!r}")
    rows = int(rows)
    # the chunk size changes no check: one key for every chunk size
    key = validation_key(path, replace(opts, chunk_rows=1), only) if validate else None
    known = known_report(key)  # this file passed with these options: not again
    validator = (RecordingValidator(opts.gaps, opts.freq_band_hz, opts.freq_span_hz,
                                    opts.thermometer, opts.dropout_s)
                 if validate and known is None else None)
    slow = SlowChannels(opts.slow_channels, opts.hold_max_s, str(path))
    with open_source(path, opts.slow_channels, opts.hold_max_s) as source:
        plan = _plan(source, opts, robust, spike_filter)
        if validator is not None and robust.counts:
            validator.count_temperatures()
        if only is not None:
            plan = plan.only(only)
        offset = 0
        repairer = _time_repairer(plan)
        if time_repair is not None:  # the caller's, to read what was repaired
            time_repair.time_unit, time_repair.naive_clock = (repairer.time_unit,
                                                              repairer.naive_clock)
            time_repair.source = repairer.source
            repairer = time_repair
        cut = _TimeSlice(opts.start, opts.end, plan)
        numbered = validate or file_rows is not None
        in_slice = RemovedInSlice()  # the spikes inside --start/--end, for the accounting

        def converted() -> Iterator[dict[str, np.ndarray]]:
            nonlocal offset
            for table in source.iter_tables(plan.read_names, plan.as_text, rows):
                part = convert_columns(plan, table_columns(table), offset)
                if validate and plan.map_problem:  # before the spike filters judge it
                    raise RecordingError(plan.map_problem)
                if numbered:  # the file rows, for the validator's messages
                    part = with_file_rows(part, offset)
                part = slow.fill(part, offset)
                before = part
                if spike_filter is not None:
                    part = spike_filter.drop(part, offset)
                part = robust.apply(part, offset)
                if cut.active and numbered:
                    in_slice.filtered(before, part)
                offset += table.num_rows
                part = cut.apply(_repair_time(part, repairer, plan))
                if part.get("time_s") is None or len(part["time_s"]):
                    yield part
            tail = slow.flush()  # rows held back by --slow-channels interpolate
            if tail is not None:
                if spike_filter is not None:
                    tail = spike_filter.drop(tail, offset)
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
        meta = _metadata(plan, opts.metadata, time_head)
        pending: list[Recording] = []

        def chunks() -> Iterator[tuple[Recording, np.ndarray | None]]:
            held, parts = list(head), pieces
            head.clear()
            for p in itertools.chain(held, parts):  # the file rows go to the validator
                part, file_rows = take_file_rows(p)
                in_slice.kept(file_rows)
                yield Recording(part, with_restarts(meta, repairer), source=str(path)), file_rows

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
            known = validator.finish()
            known.raise_for_problems()
            remember(key, known)
        if known is not None:  # validated now or by an earlier pass: the same warnings
            known.warn_bridged()
            warn_restarts(repairer)
        if spike_filter is not None:
            spike_filter.warn()
        robust.warn()
        warn_alignment(source)
        slow.warn()
        if dropped is not None:
            spikes = ((spike_filter.dropped if spike_filter is not None else 0)
                      + (robust.rows if robust.mode == "drop" else 0))
            if cut.active and numbered:  # the spikes inside the slice read, not the file's
                spikes = in_slice.count
            dropped["spikes"] = dropped.get("spikes", 0) + spikes
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

    def with_spike_default(self, mode: str) -> ReadOptions:
        """These options with ``spike_filter`` set to ``mode`` unless the user chose one."""
        return self if self.spike_filter is not None else replace(self, spike_filter=mode)

    def read(self, path: str | Path, keep: Sequence[str] | None = None) -> Recording:
        """The whole file; with ``keep``, streamed keeping only those columns (less memory)."""
        if keep is None:
            return read(path, self)
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
        own = self if rows is None else replace(self, chunk_rows=rows)
        return iter_chunks(path, own, dropped=dropped, time_repair=time_repair)

    def logged_frequency(self, path: str | Path) -> tuple[str, np.ndarray] | None:
        """The resonator frequency the file logs for this axis (its first rows), also
        when the temperature sensor is the thermometer (``freq_hz`` is then filled from
        ``temperature_c``): ``(column, values)``, None without one. A file that logs a
        resonator frequency is an HRG's, whatever the thermometer chosen."""
        own = replace(self, thermometer="resonator", axis=None, spike_filter="off",
                      spikes="error", start=None, end=None, chunk_rows=HEURISTIC_ROWS)
        name = f"freq_hz_{self.axis}" if self.axis else "freq_hz"
        chunks = iter_chunks(path, own, validate=False,
                             only=("time_s", "freq_hz", "rate_dph"))
        try:
            head = next(chunks, None)
        finally:
            chunks.close()
        if head is None or name not in head:
            return None
        return parse_columns(self.columns).get(name, name), np.asarray(head[name])

    def _axis_chunks(self, chunks: Iterator[Recording], path: str) -> Iterator[Recording]:
        return axis_views(chunks, str(self.axis), self.freq_band_hz, path)
