"""Reading and writing recordings: users' column names and units, chunks, atomic files.

:func:`read` loads a whole recording, :func:`iter_chunks` streams it in chunks
of a fixed number of rows without loading the file, :func:`write` and
:class:`RecordingWriter` write one atomically (a temporary file in the same
directory, fsync, rename) and never overwrite without ``force=True``. The file
format follows the suffix (see :mod:`hrgtc.recording.formats`).

Users' files are mapped onto the recording contract of DESIGN.md on reading:

* ``columns`` and ``units``: see :mod:`hrgtc.recording.mapping`; the date of the
  first sample of a file with timestamps is kept as ``extra["time_origin"]``;
* missing metadata: ``metadata=`` overrides or completes the file's metadata;
  without a sample rate anywhere it is inferred from the median time step of the
  first rows, and ``extra["sample_rate_inferred"]`` is set to True.
"""

from __future__ import annotations

import os
import weakref
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.errors import InputError, RecordingError
from hrgtc.files import (
    WriteBehind,
    forget_temporary,
    fsync_file,
    publish,
    refuse_existing,
    temporary_beside,
)
from hrgtc.progress import Progress
from hrgtc.recording.csv import CsvSink, CsvSource
from hrgtc.recording.formats import (
    Hdf5Sink,
    Hdf5Source,
    ParquetSink,
    ParquetSource,
    Sink,
    Source,
    format_of,
)
from hrgtc.recording.mapping import (
    ColumnPlan,
    convert_columns,
    plan_columns,
    table_columns,
)
from hrgtc.recording.schema import SCHEMA_VERSION, Metadata, Recording, concatenate
from hrgtc.recording.validation import (
    HEURISTIC_ROWS,
    GapPolicy,
    RecordingValidator,
    check_gap_policy,
    measured_sample_rate,
)
from hrgtc.recording.validation import validate as validate_recording

SOURCES: dict[str, type[Source]] = {"parquet": ParquetSource, "csv": CsvSource, "hdf5": Hdf5Source}
SINKS: dict[str, type[Sink]] = {"parquet": ParquetSink, "csv": CsvSink, "hdf5": Hdf5Sink}

__all__ = ["ReadOptions", "RecordingWriter", "count_rows", "iter_chunks", "open_source", "read",
           "write"]


def open_source(path: str | Path) -> Source:
    """Open a recording file for reading, the format chosen by its suffix."""
    return SOURCES[format_of(path)](Path(path))


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
    if plan.time_origin_ns is not None and "time_origin" not in extra:
        extra["time_origin"] = str(np.datetime64(plan.time_origin_ns, "ns"))
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
    gaps: GapPolicy | str = "error",
    metadata: Mapping[str, Any] | Metadata | None = None,
    freq_band_hz: tuple[float, float] | None = None,
    freq_span_hz: tuple[float, float] | None = None,
) -> Recording:
    """Read a whole recording from Parquet, CSV or HDF5 (by suffix).

    Parameters
    ----------
    path
        ``.parquet``/``.pq``, ``.csv`` or ``.h5``/``.hdf5`` file.
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
    with open_source(path) as source:
        plan = plan_columns(source, columns, units)
        columns = table_columns(source.read(plan.read_names, plan.as_text))
        arrays = convert_columns(plan, columns, 0)
        meta = _metadata(plan, metadata, arrays.get("time_s"))
    recording = Recording(arrays, meta, source=str(path))
    if validate:
        validate_recording(recording, gaps, freq_band_hz=freq_band_hz, freq_span_hz=freq_span_hz)
    return recording


def _rechunk(tables: Iterator[dict[str, np.ndarray]], rows: int) -> Iterator[dict[str, np.ndarray]]:
    """Regroup column dicts into consecutive pieces of exactly ``rows`` rows (last shorter)."""
    buffer: list[dict[str, np.ndarray]] = []
    held = 0
    for part in tables:
        n = len(next(iter(part.values()))) if part else 0
        if n == 0:
            continue
        buffer.append(part)
        held += n
        while held >= rows:
            joined = buffer[0] if len(buffer) == 1 else _join(buffer)
            yield {k: v[:rows] for k, v in joined.items()}
            rest = {k: v[rows:] for k, v in joined.items()}
            held -= rows
            buffer = [rest] if held else []
    if held:
        yield _join(buffer)


def _join(parts: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    if len(parts) == 1:
        return parts[0]
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}


def iter_chunks(
    path: str | Path,
    rows: int = 1_000_000,
    columns: Mapping[str, str] | Iterable[str] | None = None,
    units: Mapping[str, str] | None = None,
    validate: bool = True,
    gaps: GapPolicy | str = "error",
    metadata: Mapping[str, Any] | Metadata | None = None,
    progress: Progress | None = None,
    freq_band_hz: tuple[float, float] | None = None,
    freq_span_hz: tuple[float, float] | None = None,
) -> Iterator[Recording]:
    """Stream a recording in chunks of ``rows`` rows without loading the file.

    Parameters are those of :func:`read`, plus:

    rows
        Rows per chunk (the last chunk may be shorter).
    progress
        Called as ``progress(done, total)`` after each chunk (rows, or bytes for CSV).

    Yields
    ------
    Recording
        Consecutive chunks, all with the same metadata. Validation carries its
        state across chunks (time continuity, global row numbers); a chunk is
        yielded only after its rows (and the unit heuristics of the first
        :data:`~hrgtc.recording.validation.HEURISTIC_ROWS` rows) have passed, so a
        bad file raises :class:`~hrgtc.errors.RecordingError` before bad data
        reach the caller. With ``gaps="split"`` gaps pass; split downstream.
    """
    check_gap_policy(gaps)
    if int(rows) < 1:
        raise InputError(f"rows must be a positive number of rows per chunk, got {rows!r}")
    rows = int(rows)
    validator = (RecordingValidator(gaps, freq_band_hz, freq_span_hz) if validate else None)
    with open_source(path) as source:
        plan = plan_columns(source, columns, units)
        offset = 0

        def converted() -> Iterator[dict[str, np.ndarray]]:
            nonlocal offset
            for table in source.iter_tables(plan.read_names, plan.as_text, rows):
                part = convert_columns(plan, table_columns(table), offset)
                offset += table.num_rows
                yield part

        pieces = _rechunk(converted(), rows)
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

        def chunks() -> Iterator[Recording]:
            yield from (Recording(p, meta, source=str(path)) for p in head)
            head.clear()
            yield from (Recording(p, meta, source=str(path)) for p in pieces)

        for chunk in chunks():
            if validator is not None:
                validator.update(chunk)
                validator.raise_for_problems()
            pending.append(chunk)
            if validator is None or validator.heuristics_done:
                yield from pending
                pending.clear()
            if progress is not None:
                progress(*source.position())
        if validator is not None:
            validator.finish().raise_for_problems()
        if progress is not None:
            total = source.position()[1]
            progress(total, total)
        yield from pending


@dataclass(frozen=True)
class ReadOptions:
    """How to read a user's files: the reading options of every command, as one value.

    The command line's ``--col``, ``--time-unit``, ``--freq-unit``, ``--rate-unit``,
    ``--rate-hz``, ``--unit-name``, ``--input-rate-dph`` and ``--gaps`` become one
    ``ReadOptions``, which the library's functions that read runs take as
    ``read_options=``.

    Parameters
    ----------
    columns
        Recording column -> the file's column (see :func:`read`).
    units
        ``{"time"|"freq"|"rate": unit}`` of the file's columns.
    metadata
        Metadata overrides (``sample_rate_hz``, ``unit``, ``input_rate_dph``).
    gaps
        ``"error"``, ``"split"`` or ``"ignore"`` (see :func:`read`).
    chunk_rows
        Rows per chunk when a file is streamed.
    freq_band_hz, freq_span_hz
        Plausible frequencies and the calibrated span of the model the run is
        compensated with (set by compensation and evaluation, see :func:`read`).
    """

    columns: Mapping[str, str] | None = None
    units: Mapping[str, str] | None = None
    metadata: Mapping[str, Any] | None = None
    gaps: str = "error"
    chunk_rows: int = 250_000
    freq_band_hz: tuple[float, float] | None = None
    freq_span_hz: tuple[float, float] | None = None

    def keywords(self) -> dict[str, Any]:
        """The options as keyword arguments of :func:`read` and :func:`iter_chunks`."""
        words = {"columns": self.columns, "units": self.units, "metadata": self.metadata,
                 "gaps": self.gaps}
        if self.freq_band_hz is not None:
            words.update(freq_band_hz=self.freq_band_hz, freq_span_hz=self.freq_span_hz)
        return words

    def read(self, path: str | Path, keep: Sequence[str] | None = None) -> Recording:
        """The whole file; with ``keep``, streamed keeping only those columns (less memory)."""
        if keep is None:
            return read(path, **self.keywords())
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

    def chunks(self, path: str | Path, rows: int | None = None) -> Iterator[Recording]:
        """Stream the file in chunks (:func:`iter_chunks`)."""
        return iter_chunks(path, rows=rows or self.chunk_rows, **self.keywords())


# -- writing -------------------------------------------------------------------
def _remove(path: str) -> None:
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass
    forget_temporary(path)


class RecordingWriter:
    """Write a recording chunk by chunk, atomically.

    Rows go to a temporary file next to ``path``; :meth:`close` (or leaving the
    ``with`` block normally) syncs it to disk and renames it to ``path``; an
    exception in the block (or :meth:`abort`) removes it, leaving nothing behind.

    Parameters
    ----------
    path
        Output file; the format follows the suffix.
    metadata
        Metadata of the recording.
    columns
        Column names, in order; every chunk must have exactly these.
    force
        Overwrite ``path`` if it exists.

    Raises
    ------
    OutputExistsError
        ``path`` exists and ``force`` is False (checked at once and again on rename).

    Examples
    --------
    >>> with RecordingWriter(path, metadata, ["time_s", "freq_hz", "rate_dph"]) as out:
    ...     for chunk in chunks:
    ...         out.write(chunk)                                     # doctest: +SKIP
    """

    def __init__(
        self,
        path: str | Path,
        metadata: Metadata,
        columns: Sequence[str],
        force: bool = False,
    ) -> None:
        self.path = Path(path)
        self.metadata = metadata
        self.columns = list(columns)
        self.force = bool(force)
        self.rows = 0
        fmt = format_of(self.path)
        if len(set(self.columns)) != len(self.columns) or not self.columns:
            raise InputError(f"{self.path}: column names must be unique and non-empty")
        self._check_target()
        directory = self.path.parent
        if not directory.is_dir():
            raise InputError(f"{self.path}: directory {directory} does not exist; create it first")
        tmp = temporary_beside(self.path)
        self._tmp = tmp
        self._behind: WriteBehind | None = None
        self._cleanup = weakref.finalize(self, _remove, tmp)
        try:
            self._sink: Sink | None = SINKS[fmt](Path(tmp), metadata, self.columns)
        except BaseException:
            self._cleanup()
            raise

    def _check_target(self) -> None:
        if self.path.is_dir():
            raise InputError(f"{self.path} is a directory; give a file name")
        refuse_existing(self.path, self.force)

    def write(self, chunk: Recording | Mapping[str, Any]) -> None:
        """Append rows (a :class:`Recording` or a mapping of name -> 1-D array)."""
        if self._sink is None:
            raise InputError(f"{self.path}: the writer is closed")
        names = chunk.names if isinstance(chunk, Recording) else tuple(chunk)
        if set(names) != set(self.columns):
            raise RecordingError(
                f"{self.path}: chunk columns {sorted(names)} differ from the writer's "
                f"{sorted(self.columns)}"
            )
        arrays = {n: np.ascontiguousarray(chunk[n], dtype=np.float64) for n in self.columns}
        lengths = {a.shape for a in arrays.values()}
        if len(lengths) != 1 or len(next(iter(lengths))) != 1:
            raise RecordingError(f"{self.path}: chunk columns must be 1-D of one length")
        self._sink.write(arrays)
        self.rows += len(arrays[self.columns[0]])

    def start_writeback(self) -> None:
        """Send the rows written so far to disk beside the work (:class:`~hrgtc.files.WriteBehind`).

        :meth:`close` still waits for every byte (fsync) before the rename; calling
        this after each chunk, in a writer thread, spreads the disk writes over the
        run (the previous chunk's bytes are waited for here), so that wait is short.
        """
        if self._sink is None:
            return
        if self._behind is None:
            self._behind = WriteBehind(self._tmp)
        self._behind.advance()

    def close(self) -> Path:
        """Finish the file: sync it and rename it to :attr:`path`."""
        if self._sink is None:
            return self.path
        sink, self._sink = self._sink, None
        self._stop_behind()
        try:
            sink.close()
            fsync_file(self._tmp)
            publish(self._tmp, self.path, self.force)
        except BaseException:
            self._cleanup()
            raise
        self._cleanup.detach()
        return self.path

    def _stop_behind(self) -> None:
        behind, self._behind = self._behind, None
        if behind is not None:
            behind.close()

    def abort(self) -> None:
        """Discard everything written; the temporary file is removed."""
        sink, self._sink = self._sink, None
        self._stop_behind()
        try:
            if sink is not None:
                sink.abort()
        finally:
            self._cleanup()

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, exc_type: object, exc: object, tb: object) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def write(recording: Recording, path: str | Path, force: bool = False) -> Path:
    """Write a recording atomically; the format follows the suffix of ``path``.

    Parameters
    ----------
    recording
        The recording (all its columns and its metadata are written).
    path
        ``.parquet``/``.pq``, ``.csv`` or ``.h5``/``.hdf5``.
    force
        Overwrite an existing file.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OutputExistsError
        ``path`` exists and ``force`` is False.
    """
    with RecordingWriter(path, recording.metadata, recording.names, force=force) as writer:
        writer.write(recording)
    return writer.path
