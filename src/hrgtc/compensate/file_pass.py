"""Compensation of a file into a new file, chunk by chunk in bounded memory.

:func:`compensate_file` streams a recording through a
:class:`~hrgtc.compensate.compensator.Compensator` (every axis of the model) with
reading, compensating and writing overlapped; the output is marked as compensated by its model
(:func:`compensated_metadata`), carries the restarts of every chunk, and what was read,
dropped and flagged is counted (:func:`compensation_accounting`).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc import recording as rec_io
from hrgtc.compensate.at_rest import DETECTOR_COLUMNS, FlagsMisaligned, RestFlags
from hrgtc.compensate.compensator import Compensator
from hrgtc.compensate.multi_axis import match_axes, recording_axes
from hrgtc.compensate.ranges import RangeReport
from hrgtc.core.accounting import Accounting
from hrgtc.core.errors import InputError
from hrgtc.core.files import check_writable, refuse_input
from hrgtc.core.progress import Progress
from hrgtc.core.time_steps import TimeRepairStream
from hrgtc.core.timeline import RESTARTS_KEY
from hrgtc.model import Model, load_model
from hrgtc.model_fit import (
    check_recording_noise,
    check_thermometer_kind,
    plausible_frequency_band,
    with_model_band,
)
from hrgtc.recording import Recording
from hrgtc.recording.marks import COMPENSATED_KEY, mark, refuse_compensated
from hrgtc.recording.spikes import SPIKE_COLUMN
from hrgtc.settings.compensation import CompensateSettings

__all__ = ["CompensationSummary", "compensate_file", "compensated_metadata",
           "compensation_accounting"]

#: Rows per chunk of :func:`compensate_file`: one Parquet row group, so chunks are read
#: without joining batches and written without waiting for the next chunk.
FILE_CHUNK_ROWS = CompensateSettings.chunk_rows


@dataclass(frozen=True)
class CompensationSummary:
    """What :func:`compensate_file` did."""

    source: str
    output: str
    rows: int
    out_of_range_fraction: float
    rate_out_of_range_fraction: float
    ranges: RangeReport | None = None
    accounting: Accounting | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "source": self.source,
            "output": self.output,
            "rows": self.rows,
            "out_of_range_fraction": self.out_of_range_fraction,
            "rate_out_of_range_fraction": self.rate_out_of_range_fraction,
            "ranges": None if self.ranges is None else self.ranges.to_dict(),
            "accounting": None if self.accounting is None else self.accounting.to_dict(),
        }


def compensate_file(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str],
    model: Model | str | os.PathLike[str],
    *,
    drift: str = "frequency",
    read_options: rec_io.ReadOptions | None = None,
    axes: Sequence[str] | None = None,
    force: bool = False,
    settings: CompensateSettings | None = None,
    progress: Progress | None = None,
) -> CompensationSummary:
    """Compensate every axis of a recording file into a new file, chunk by chunk (bounded
    memory).

    ``model``: the :class:`~hrgtc.model.Model` (one axis or several) or its model file
    (then named in the errors). Its temperature map (a raw count's map to °C from
    ``calibrate --temp-ref``) is applied unless ``read_options`` give their own scale and
    offset. The model's and the recording's axes must agree unless ``axes`` names those to
    compensate (:func:`~hrgtc.compensate.multi_axis.match_axes`); each frequency is
    checked against its axis's plausible band. ``settings``: the chunk size
    (:class:`~hrgtc.settings.compensation.CompensateSettings` defaults when None).

    The output is written atomically in the format of its suffix; it is never
    overwritten without ``force``. ``read_options`` says how to read ``source``
    (column mapping, units, metadata); every row read is written (spikes are flagged
    with ``spike_filter="flag"``, never dropped: ``"drop"`` is refused).

    Three stages overlap, each one chunk ahead of the next (pyarrow, h5py and the
    fused kernel release the GIL): a thread reads and validates the next chunk,
    this thread compensates the current one, and a writer thread writes the previous
    one, starts its write to disk and waits for the one before
    (:meth:`~hrgtc.recording.RecordingWriter.start_writeback`), so that the fsync
    before the atomic rename finds one chunk left to wait for. At most three chunks
    are held at a time.
    """
    from hrgtc.thermometry.reference import options_with_map

    model_source = ""
    if isinstance(model, str | os.PathLike):
        model_source, model = str(model), load_model(model)
    chunk_rows = (settings or CompensateSettings()).chunk_rows
    reading = options_with_map(read_options, model.temperature_map) or rec_io.ReadOptions()
    # before reading: a model of the other thermometer kind
    check_thermometer_kind(reading, model, model_source or None)
    found = recording_axes(source, reading)
    if found is not None:
        model = match_axes(model, found, axes, str(source), model_source)
    if reading.spike_filter == "drop":
        raise InputError("compensate flags spikes, it never drops a row: use --spike-filter "
                         "flag (a 'spike' column marks them) or off")
    bands: dict[str, tuple[float, float]] = {}
    if "" in model.axes:  # the plain columns: the reader checks the one frequency's band
        reading = with_model_band(reading, model)
    else:  # each axis's band on its view, by the compensator
        bands = {axis: plausible_frequency_band(part) for axis, part in model.axes.items()}

    def fresh() -> Compensator:
        return Compensator(model, drift, gaps=reading.gaps, bands_hz=bands, partial=bool(axes))

    compensator = fresh()
    job = _Job(source, output, model, reading, compensator.columns, force, chunk_rows, drift,
               progress)
    refuse_input(output, [source])
    refuse_compensated(source)
    check_writable(output, estimated_output_bytes(source, output, len(job.added)))
    # the detector's pass reads its columns only, unless rows may be dropped because of
    # others (--spikes drop); --motion error names a row: read as the compensation reads
    only = DETECTOR_COLUMNS if reading.motion == "exclude" and reading.spikes != "drop" else None
    try:
        return _compensate(job, compensator, only)
    except FlagsMisaligned:
        if only is None:
            raise
    # the rows differed (at_rest.py): none were kept; again, the pass reading every column
    return _compensate(job, fresh(), None)


@dataclass(frozen=True)
class _Job:
    """What one pass of :func:`compensate_file` reads, writes and counts."""

    source: str | os.PathLike[str]
    output: str | os.PathLike[str]
    model: Model
    options: rec_io.ReadOptions
    added: tuple[str, ...]
    force: bool
    chunk_rows: int
    drift: str
    progress: Progress | None


def _compensate(job: _Job, compensator: Compensator,
                only: tuple[str, ...] | None) -> CompensationSummary:
    """One run of :func:`compensate_file`, the detector's pass reading ``only`` those
    columns (None: all); raises :class:`FlagsMisaligned` before the output is kept if
    its rows were not those compensated."""
    source, output, model, options = job.source, job.output, job.model, job.options
    added, force, chunk_rows, drift, progress = (job.added, job.force, job.chunk_rows,
                                                 job.drift, job.progress)
    repair = TimeRepairStream()  # what the reader dropped (duplicated rows)
    chunks = options.chunks(source, rows=chunk_rows, time_repair=repair)
    spikes = 0
    try:
        first = next(chunks)
        total = rec_io.count_rows(source)
        flags = None  # samples not at rest: flagged, found in one pass first (at_rest.py)
        if options.motion != "keep":
            # duplicated rows in the first chunk: told apart by all the columns
            only = None if repair.duplicates else only
            # the spike filter's flags change no row: not computed in the detector's pass
            quick = dataclasses.replace(options, spike_filter="off", chunk_rows=chunk_rows)
            with ThreadPoolExecutor(max_workers=1) as warming:
                # the kernel's start (numba's) on a thread while the detector's pass reads
                warmed = warming.submit(compensator.warm, first)
                flags = RestFlags(rec_io.iter_chunks(source, quick,
                                                     validate=False, only=only),
                                  list(model.axes), options.motion,
                                  os.path.basename(os.fspath(source)),
                                  validated=lambda: options.chunks(source, rows=chunk_rows),
                                  rows=total)
                warmed.result()
            added = (*added, *flags.columns)
        copies = sensor_copies((*first.names, *added), first.metadata)
        names = tuple(n for n in (*first.names, *added) if n not in copies)
        check_recording_noise(model, first, str(source))
        metadata = compensated_metadata(first.metadata, model, drift)
        with rec_io.RecordingWriter(output, metadata, names, force=force) as writer, \
                ThreadPoolExecutor(max_workers=1) as reading, \
                ThreadPoolExecutor(max_workers=1) as writing:
            ahead = reading.submit(next, chunks, None)
            pending = None
            chunk: Recording | None = first
            restarts: set[float] = set()  # every chunk's restarts, written at close
            while chunk is not None:
                restarts.update(chunk.metadata.extra.get(RESTARTS_KEY) or ())
                taken = None if flags is None else flags.take(chunk)
                result = compensator.transform(chunk, _at_rest(flags, taken))
                if taken is not None:
                    result = result.with_columns(**taken)
                if SPIKE_COLUMN in chunk:
                    spikes += int(np.count_nonzero(chunk[SPIKE_COLUMN]))
                if copies:
                    result = Recording({n: result[n] for n in names}, result.metadata,
                                       result.source)
                if pending is not None:
                    pending.result()
                pending = writing.submit(_write, writer, result)
                if progress is not None:
                    progress(compensator.samples, total)
                chunk = ahead.result()
                if chunk is not None:
                    ahead = reading.submit(next, chunks, None)
            if pending is not None:
                pending.result()
            if flags is not None:
                flags.finish()  # every row the detector saw compensated, or no output
            if restarts:
                writer.set_metadata(dataclasses.replace(metadata, extra={
                    **metadata.extra, RESTARTS_KEY: sorted(restarts)}))
    finally:
        chunks.close()
    accounting = compensation_accounting(compensator, spikes, repair.duplicates,
                                         0 if flags is None else flags.n_not_at_rest)
    return CompensationSummary(str(source), str(output), compensator.samples,
                               compensator.out_of_range_fraction,
                               compensator.rate_out_of_range_fraction, compensator.ranges(),
                               accounting)


def _at_rest(flags: RestFlags | None, taken: dict[str, np.ndarray] | None
             ) -> dict[str, np.ndarray] | None:
    """The at-rest masks of a chunk as :meth:`Compensator.transform` takes them: axis ->
    array (None without flags)."""
    if flags is None or taken is None:
        return None
    return {axis: taken[column] > 0.5 for axis, column in zip(flags.axes, flags.columns,
                                                              strict=True)}


def compensation_accounting(compensator: Compensator, spikes: int = 0,
                            duplicates: int = 0, not_at_rest: int = 0) -> Accounting:
    """Samples read, dropped (duplicated rows, by the reader) and flagged by reason.

    ``compensate`` never drops a sample it read: spikes (the ``spike`` column), samples
    beyond the trained temperature (``out_of_range``) or df/dt (``rate_out_of_range``)
    and those of the df/dt filter's settling (``warmup``) are flagged (``in_range`` 0), and
    ``not_at_rest`` samples (on any axis; the ``at_rest`` columns) as ``motion``. With
    several axes, the axis with the most samples beyond its ranges (the one the
    summary line names).
    """
    worst = compensator.worst()
    accounting = Accounting(read=worst.samples + duplicates)
    accounting.drop("duplicates", duplicates)
    accounting.flag("warmup", worst.settling)
    accounting.flag("spikes", spikes)
    accounting.flag("motion", not_at_rest)
    accounting.flag("out_of_range", worst.temperature_out)
    accounting.flag("rate_out_of_range",
                    worst.variable_ranges.get("df", [worst.rate_out_of_range])[0])
    return accounting


def compensated_metadata(metadata: rec_io.Metadata, model: Model,
                         drift: str = "frequency") -> rec_io.Metadata:
    """``metadata`` with the mark of compensation by ``model`` (:mod:`hrgtc.recording.marks`).

    Its ``drift`` says what drove the model: ``"frequency"`` (the resonator's), ``"sensor
    temperature"`` (a model of the gyro's temperature sensor, ``--thermometer sensor``) or
    ``"housing"`` (the housing-thermistor baseline).
    """
    units = model.axes.values()
    if drift == "frequency" and all(u.thermometer.source == "sensor" for u in units):
        drift = "sensor temperature"
    extra = {**metadata.extra, COMPENSATED_KEY: mark(model.sha256, model.unit, drift)}
    # the restarts known when the output is opened are those of the first chunk only: none
    # are written then, and all at close (compensate_file; its time axis is the repaired one)
    extra.pop(RESTARTS_KEY, None)
    return dataclasses.replace(metadata, extra=extra)


def estimated_output_bytes(source: str | os.PathLike[str], output: str | os.PathLike[str],
                           added_columns: int) -> float:
    """Rough size of ``output``, a copy of ``source`` with ``added_columns`` more columns.

    Counted as 8-byte floats (Parquet, HDF5) or about 20 characters (CSV) per value;
    used to refuse a run that would fill the disk before it starts.
    """
    try:
        with rec_io.open_source(source) as opened:
            columns = len(opened.names) + added_columns
        rows = rec_io.count_rows(source)
    except (InputError, OSError):
        return 0.0
    per_value = 20.0 if str(output).lower().endswith(".csv") else 8.0
    return rows * columns * per_value


def sensor_copies(names: tuple[str, ...], metadata: rec_io.Metadata) -> set[str]:
    """Columns a sensor thermometer's output would only copy its temperature into.

    With ``--thermometer sensor`` the ``freq_hz*`` columns hold the temperature
    sensor's reading and ``resonator_c_est*`` the same again (the thermometer is the
    identity): neither is written; ``temperature_c*`` is.
    """
    if metadata.extra.get("thermometer") != "sensor":
        return set()
    return {n for n in names if n.startswith(("freq_hz", "resonator_c_est"))}


def _write(writer: rec_io.RecordingWriter, chunk: Recording) -> None:
    writer.write(chunk)
    writer.start_writeback()

