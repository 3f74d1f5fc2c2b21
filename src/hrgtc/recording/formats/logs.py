"""What the readers of the files test benches and flight controllers write share.

The readers of TDMS, MATLAB, ULog, DataFlash and MDF4 files (one module each in this
package) import their library only when a file is read (:func:`require`, which names the
``pip install 'hrgtc[EXTRA]'`` that brings it when it is missing), so listing the formats
and ``hrgtc --help`` load none of them. A file of one table is one stream with the
file's own column names; a log of several streams on their own time axes (topics,
messages, groups) gives one :class:`~hrgtc.recording.formats.base.TableSource` per stream
(:func:`streams`), each with its time in seconds as ``time_s`` and its other columns
named ``<stream><separator><column>`` (``sensor_gyro_0.x``, ``IMU.GyrX``,
``Measured Data/Sine``), marked on request: the column mapping names the columns wanted
and :mod:`hrgtc.recording.align` puts them on one time axis.
"""

from __future__ import annotations

import contextlib
import importlib
import io
import logging
import re
import sys
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from hrgtc.core.errors import RecordingError
from hrgtc.recording.formats.base import TableSource

#: MATLAB's datenum of the Unix epoch: datenum(1970, 1, 1) = 719529. [days]
DATENUM_UNIX_EPOCH_DAYS = 719529.0
SECONDS_PER_DAY = 86400.0


def require(module: str, extra: str, what: str, path: Path,
            action: str = "reading") -> ModuleType:
    """Import ``module`` for reading (or writing) ``path``, or RecordingError naming the
    extra to install.

    Parameters
    ----------
    module
        The library's module (``"nptdms"``).
    extra
        The extra of hrgtc that installs it (``"tdms"``: ``pip install 'hrgtc[tdms]'``).
    what
        The format's name for the message (``"TDMS"``).
    path
        The file being read (named in the message).
    action
        ``"reading"`` or ``"writing"``, for the message.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise RecordingError(
            f"{path}: {action} {what} files needs the Python package {module!r}, which is not "
            f"installed ({exc}); install it with pip install 'hrgtc[{extra}]' (or "
            "'hrgtc[formats]' for every file format)") from None


#: The name of a temporary file :func:`hrgtc.core.files.temporary_beside` makes for a target:
#: ``.<target name>.<pid>.<random>.tmp``.
_TEMPORARY = re.compile(r"\.(?P<name>.+)\.\d+\.\w+\.tmp")


def output_path(path: Path) -> Path:
    """The file a sink writes ``path`` for: the target of hrgtc's temporary file (named in
    messages, as the user gave it), else ``path`` itself."""
    found = _TEMPORARY.fullmatch(path.name)
    return path.with_name(found["name"]) if found else path


def unreadable(path: Path, what: str, exc: BaseException, fix: str = "") -> RecordingError:
    """The error for a file its library cannot parse (corrupt, truncated, another format)."""
    detail = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    return RecordingError(
        f"{path}: not a readable {what} file ({type(exc).__name__}: {detail[:200]}); it may be "
        f"truncated or corrupt, or another format under this suffix: "
        f"{fix or 'export it again from the software that wrote it'}")


@contextlib.contextmanager
def quiet(loggers: Sequence[str] = (), collect: bool = False) -> Iterator[list[str]]:
    """What a library prints, logs (``loggers``) or reports from ``__del__`` while it reads,
    gathered into the list yielded instead of reaching the user's terminal (hrgtc reports
    it in its own words; a half-built reader object of a corrupt file must not print a
    traceback when it is collected)."""
    said: list[str] = []
    text = io.StringIO()

    class Gather(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            said.append(record.getMessage())

    gather = Gather(logging.WARNING)
    hook = sys.unraisablehook
    saved = []
    for name in loggers:
        logger = logging.getLogger(name)
        saved.append((logger, logger.handlers, logger.propagate))
        logger.handlers, logger.propagate = [gather], False
    sys.unraisablehook = lambda unraisable: said.append(str(unraisable.exc_value))
    try:
        with contextlib.redirect_stdout(text), contextlib.redirect_stderr(text):
            yield said
    finally:
        if collect:  # a half-built object's __del__ runs now, under the quiet hook
            import gc

            gc.collect()
        sys.unraisablehook = hook
        for logger, handlers, propagate in saved:
            logger.handlers, logger.propagate = handlers, propagate
        said[:0] = [line for line in text.getvalue().splitlines() if line.strip()]


def check_exists(path: Path) -> None:
    """FileNotFoundError for a missing file (before a library reports it its own way)."""
    if not path.is_file():
        raise FileNotFoundError(2, "No such file or directory", str(path))


@dataclass
class Stream:
    """One table of a file on its own time axis, before it becomes a source.

    Parameters
    ----------
    name
        The stream's name in the file (a topic, a message, a group).
    columns
        Column name -> 1-D array, all of one length; ``time_s`` (seconds) among them
        when the stream has a time axis of its own.
    metadata
        Metadata of the stream (``sample_rate_hz`` where the file states it, ``extra``).
    """

    name: str
    columns: dict[str, Any]
    metadata: dict[str, Any] = field(default_factory=dict)

    def rows(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0


def streams(path: Path, found: Sequence[Stream], fmt: str, separator: str,
            metadata: Mapping[str, Any] | None = None) -> list[TableSource]:
    """Sources of the streams ``found`` in a file: one as it is, several on request.

    Parameters
    ----------
    path
        The file.
    found
        Its streams; empty ones are left out.
    fmt
        The format's name (``Source.format``).
    separator
        Between a stream's name and its columns' (``"."`` or ``"/"``).
    metadata
        The file's metadata, under each stream's own.

    Raises
    ------
    RecordingError
        No stream with rows, or several streams and one without ``time_s``.
    """
    kept = [s for s in found if s.columns and s.rows() > 0]
    if not kept:
        raise RecordingError(f"{path}: the {fmt} file holds no table of values (no channel "
                             "with samples); nothing to read")
    base = dict(metadata or {})

    def merged(stream: Stream) -> dict[str, Any]:
        extra = {**base.get("extra", {}), **stream.metadata.get("extra", {})}
        return {**base, **stream.metadata, "extra": extra}

    if len(kept) == 1:
        source = TableSource(path, kept[0].columns, merged(kept[0]), stream=kept[0].name)
        source.format = fmt
        return [source]
    untimed = [s.name for s in kept if "time_s" not in s.columns]
    if untimed:
        raise RecordingError(
            f"{path}: the {fmt} file holds {len(kept)} tables of different lengths and "
            f"{', '.join(repr(n) for n in untimed[:5])} has no time axis of its own, so they "
            "cannot be put on one time axis; give each table its own time (time_s, or "
            "waveform timing) or save the channels of one rate alone")
    sources = []
    for stream in kept:
        columns = {("time_s" if name == "time_s" else f"{stream.name}{separator}{name}"): values
                   for name, values in stream.columns.items()}
        source = TableSource(path, columns, merged(stream), stream=stream.name,
                             on_request=True)
        source.format = fmt
        sources.append(source)
    return sources


def numeric(values: Any) -> np.ndarray | None:
    """A 1-D array of numbers (booleans as 0/1) or None for text, records and matrices."""
    array = np.asarray(values)
    if array.ndim != 1 or array.dtype.kind not in "fiub":
        return None
    return array.astype(np.float64) if array.dtype.kind == "b" else array


def datenum_to_datetime(days: np.ndarray) -> np.ndarray:
    """MATLAB ``datenum`` (days since the year 0, proleptic Gregorian) as datetime64[ns] (UTC).

    ``datenum(1970, 1, 1)`` is 719529, so a datenum ``d`` is the Unix time
    ``(d - 719529) * 86400`` seconds (MATLAB's documentation of ``datenum``).
    """
    seconds = (np.asarray(days, dtype=np.float64) - DATENUM_UNIX_EPOCH_DAYS) * SECONDS_PER_DAY
    return (np.round(seconds * 1e9)).astype("int64").astype("datetime64[ns]")
