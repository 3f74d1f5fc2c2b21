"""Writing recordings atomically, chunk by chunk (:class:`RecordingWriter`) or whole.

Rows go to a temporary file in the same directory, which is synced and renamed
to its name when complete; an existing file is never overwritten without
``force=True``. The file format follows the suffix (the format of the registry,
:func:`hrgtc.recording.formats.writable`, that has a writer).
"""

from __future__ import annotations

import os
import weakref
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError, RecordingError
from hrgtc.core.files import (
    WriteBehind,
    forget_temporary,
    fsync_file,
    naming_os_errors,
    publish,
    refuse_existing,
    temporary_beside,
)
from hrgtc.recording.formats.base import Sink, metadata_json
from hrgtc.recording.formats.registry import writable
from hrgtc.recording.schema import Metadata, Recording

__all__ = ["RecordingWriter", "write"]


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
        sink_class = writable(self.path).sink
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
            self._sink: Sink | None = sink_class(Path(tmp), metadata, self.columns)
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
        with naming_os_errors(self.path):
            self._sink.write(arrays)
        self.rows += len(arrays[self.columns[0]])

    def set_metadata(self, metadata: Metadata) -> None:
        """The metadata the file is closed with, in place of that it was opened with: what is
        known only after the last row (the restarts a reader met, ``extra["restarts_s"]``).

        Parquet writes it in the footer's key-value metadata (which readers take before the
        schema's copy), HDF5 in the group's attributes; CSV's header is the file's first
        bytes, so the rows are copied once after the new header at :meth:`close` (only when
        the header changed).
        """
        if self._sink is None:
            raise InputError(f"{self.path}: the writer is closed")
        metadata_json(metadata)  # fail now on non-JSON extra, not at close
        self.metadata = metadata
        self._sink.set_metadata(metadata)

    def start_writeback(self) -> None:
        """Make the rows written so far durable beside the work (a ``WriteBehind``).

        The first call starts a thread that syncs the file as it grows (each later
        call wakes it at once); :meth:`close` still waits for every byte (fsync)
        before the rename, but finds little left to wait for.
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
        try:
            with naming_os_errors(self.path):
                sink.close()
                self._stop_behind()  # after the last bytes, which it may still sync
                fsync_file(self._tmp)
            publish(self._tmp, self.path, self.force)
        except BaseException:
            self._stop_behind(discard=True)
            self._cleanup()
            raise
        self._cleanup.detach()
        return self.path

    def _stop_behind(self, discard: bool = False) -> None:
        behind, self._behind = self._behind, None
        if behind is not None:
            behind.close(discard=discard)

    def abort(self) -> None:
        """Discard everything written; the temporary file is removed."""
        sink, self._sink = self._sink, None
        self._stop_behind(discard=True)
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
