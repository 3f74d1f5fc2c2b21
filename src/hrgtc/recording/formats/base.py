"""What every file format provides: a source (a reader of streams), a sink (a writer), a ``Format``.

A file format is one module of this package (or of a lab's own package, found through
the ``hrgtc.formats`` entry point group) that declares one :class:`Format`: its name,
its suffixes, a sniff of the file's first bytes, a reader and, where it has one, a
writer. :mod:`hrgtc.recording.formats.registry` collects the formats; everything that
picks a format by suffix or content asks it.

A reader opens a file as one or more *streams*. A stream is a :class:`Source`: a table
of columns on its own time axis (the column :attr:`Source.time_column`), its raw
metadata, and reading of the columns asked for as :class:`pyarrow.Table` objects, whole
or in batches, without loading more than a batch. A logger that writes its channels at
different rates gives one stream per rate; :mod:`hrgtc.recording.align` joins them onto
one time axis (one stream: nothing to do). :class:`TableSource` is a stream over columns
already in memory, all a small reader needs to return.

A *sink* writes float64 columns chunk by chunk to a (temporary) path;
:mod:`hrgtc.recording.writing` makes that atomic.
"""

from __future__ import annotations

import bisect
import json
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from hrgtc.core.errors import RecordingError
from hrgtc.recording.axes import base_name, split_axis
from hrgtc.recording.schema import COLUMNS, Metadata

#: Bytes of the head of a file given to each format's sniff.
SNIFF_BYTES = 4096
#: The kind of a numeric column of a stream that is read only when the column mapping names
#: it (:attr:`Source.on_request`): not taken in among "the file's other numeric columns".
ON_REQUEST = "numeric on request"


def kind_of(dtype: pa.DataType) -> str:
    """``"numeric"``, ``"string"``, ``"timestamp"`` or ``"other"`` for an Arrow type."""
    if (
        pa.types.is_integer(dtype)
        or pa.types.is_floating(dtype)
        or pa.types.is_boolean(dtype)
        or pa.types.is_decimal(dtype)
        or pa.types.is_null(dtype)
    ):
        return "numeric"
    if pa.types.is_string(dtype) or pa.types.is_large_string(dtype):
        return "string"
    if pa.types.is_timestamp(dtype) or pa.types.is_date(dtype):
        return "timestamp"
    return "other"


def metadata_json(metadata: Metadata) -> str:
    """The metadata as JSON text (RecordingError if ``extra`` is not JSON)."""
    try:
        return json.dumps(metadata.to_dict(), allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise RecordingError(f"metadata cannot be stored as JSON ({exc}); use JSON types") from None


def _reject_constant(name: str) -> Any:
    raise ValueError(f"{name} is not allowed in hrgtc metadata")


def loads_json(text: str | bytes) -> Any:
    """``json.loads`` that refuses NaN and Infinity (metadata must stay strict JSON)."""
    return json.loads(text, parse_constant=_reject_constant)


def metadata_object(text: str | bytes, where: str) -> dict[str, Any]:
    """hrgtc's metadata as a format keeps it (JSON text in a property or comment): the
    object, or a :class:`RecordingError` naming ``where`` (file and place) and what is
    wrong."""
    try:
        found = loads_json(text)
    except ValueError:
        raise RecordingError(f"{where} (hrgtc's metadata) is not valid JSON") from None
    if not isinstance(found, dict):
        raise RecordingError(f"{where} (hrgtc's metadata) is not a JSON object")
    return found


def first_failing(array: pa.Array | pa.ChunkedArray, convert: Callable[[Any], Any]) -> int:
    """Index of the first element for which ``convert`` raises (bisection on prefixes)."""
    low, high = 0, len(array)  # prefix [:low] converts, [:high] fails

    def fails(n: int) -> bool:
        try:
            convert(array.slice(0, n))
        except (pa.ArrowInvalid, pa.ArrowTypeError, ValueError):
            return True
        return False

    return bisect.bisect_left(range(low, high + 1), True, key=fails) - 1



# -- sources -------------------------------------------------------------------
class Source:
    """One stream of an open recording file: column names, raw metadata and batched reading.

    A subclass sets :attr:`names`, :attr:`metadata` and :attr:`total_rows` in its
    ``__init__`` and implements :meth:`kinds` and :meth:`read`; :meth:`iter_tables`
    slices :meth:`read` unless the format can read in batches (it should, for files of
    millions of rows). A file of several streams names each (:attr:`stream`) and its time
    column (:attr:`time_column`, in seconds times :attr:`time_unit_s`).
    """

    format = ""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.names: list[str] = []
        self.metadata: dict[str, Any] = {}
        self.total_rows: int | None = None
        #: Name of the stream within the file ("" for a file of one stream).
        self.stream = ""
        #: The column of the stream's time axis.
        self.time_column = "time_s"
        #: Seconds per unit of :attr:`time_column` (1e-6 for a logger's µs counter).
        self.time_unit_s = 1.0
        #: True for one stream of a log of many (a ULog topic, a DataFlash message, a TDMS
        #: or MDF group): its columns are read only when the column mapping names one, and
        #: the alignment takes its time axis from the streams so named
        #: (:mod:`hrgtc.recording.align`).
        self.on_request = False

    def kinds(self) -> dict[str, str]:
        """Column name -> kind (see :func:`kind_of`)."""
        raise NotImplementedError

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        """The columns ``names`` (those in ``as_text`` as text where that matters)."""
        raise NotImplementedError

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        """The same, in consecutive tables of at most about ``rows`` rows."""
        table = self.read(names, as_text)
        for start in range(0, table.num_rows, max(int(rows), 1)):
            yield table.slice(start, rows)

    def count_rows(self) -> int:
        """Number of data rows."""
        return int(self.total_rows or 0)

    def position(self) -> tuple[float, float]:
        """(done, total) of the reading so far, for progress callbacks."""
        return (0.0, float(self.total_rows or 0))

    def close(self) -> None:
        """Release the file."""

    def __enter__(self) -> Source:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def is_column_name(name: str) -> bool:
    """True for a recording contract column, per-axis ones (``rate_dph_x``) included."""
    base, axis = split_axis(name)
    return name in COLUMNS or (axis is not None and base in COLUMNS)


def column_unit(name: str, axes: Sequence[str] = ()) -> str | None:
    """Unit of a contract column, per-axis ones (``rate_dph_x`` of ``axes``) included; else None."""
    base = base_name(name, axes)
    return COLUMNS[base][0] if base in COLUMNS else None


class TableSource(Source):
    """A stream over columns already in memory: what a small reader returns.

    Parameters
    ----------
    path
        The file the columns were read from (named in messages).
    columns
        Column name -> 1-D array (numbers, or text for clock times), all of one length;
        or a :class:`pyarrow.Table`.
    metadata
        The file's raw metadata (``sample_rate_hz``, ``unit``, ``extra`` ...).
    stream, time_column, time_unit_s, on_request
        See :class:`Source`.
    """

    format = "table"

    def __init__(self, path: str | Path, columns: Mapping[str, Any] | pa.Table,
                 metadata: Mapping[str, Any] | None = None, *, stream: str = "",
                 time_column: str = "time_s", time_unit_s: float = 1.0,
                 on_request: bool = False) -> None:
        super().__init__(Path(path))
        self._table = columns if isinstance(columns, pa.Table) else pa.table(
            {name: pa.array(np.asarray(values) if not isinstance(values, pa.Array) else values)
             for name, values in columns.items()})
        self.names = list(self._table.column_names)
        self.metadata = dict(metadata or {})
        self.total_rows = self._table.num_rows
        self.stream, self.time_column, self.time_unit_s = stream, time_column, float(time_unit_s)
        self.on_request = on_request
        self._done = 0

    def kinds(self) -> dict[str, str]:
        return {f.name: kind_of(f.type) for f in self._table.schema}

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        self._done = self._table.num_rows
        return self._table.select(list(names))

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        table = self._table.select(list(names))
        for start in range(0, table.num_rows, max(int(rows), 1)):
            self._done = min(start + rows, table.num_rows)
            yield table.slice(start, rows)

    def position(self) -> tuple[float, float]:
        return (float(self._done), float(self.total_rows or 0))


Reader = Callable[[Path], "Source | Sequence[Source]"]
Sniff = Callable[[bytes], bool]


@dataclass(frozen=True)
class Format:
    """A file format: its name, suffixes, sniff, reader and (optional) writer.

    Parameters
    ----------
    name
        Short name, shown by ``hrgtc info`` and in messages (``"csv"``).
    suffixes
        File suffixes, lower case with the dot (``(".csv",)``); the first is the one
        written.
    reader
        ``reader(path)`` opens the file: a :class:`Source`, or a list of them for a
        file whose channels are on several time axes (joined by
        :func:`hrgtc.recording.align.align`). A missing file raises FileNotFoundError,
        an unreadable one :class:`~hrgtc.core.errors.RecordingError` naming the file.
    sniff
        ``sniff(head)``: True when the first :data:`SNIFF_BYTES` bytes of a file are
        certainly this format (a signature); None: the format is known by its suffix
        only. A file of unknown suffix is read by the format whose sniff accepts it.
    sink
        Writer class (``Sink(path, metadata, names)``) or None if the format is read only.
    output_name
        The name of the format for ``--format`` of the commands that write
        (``"h5"`` for HDF5); default :attr:`name`.
    description
        One line for listings.
    within
        The name of the format this one is a kind of, whose sniff also accepts its files
        (``"hdf5"`` for MATLAB v7.3): of the two, a file of unknown suffix is read by this one.
    """

    name: str
    suffixes: tuple[str, ...]
    reader: Reader
    sniff: Sniff | None = None
    sink: type[Sink] | None = None
    output_name: str = ""
    description: str = ""
    within: str = ""

    def __post_init__(self) -> None:
        if not self.name or not self.suffixes:
            raise ValueError(f"a file format needs a name and at least one suffix, got "
                             f"{self.name!r} {self.suffixes!r}")
        bad = [s for s in self.suffixes if not s.startswith(".") or s != s.lower()]
        if bad:
            raise ValueError(f"format {self.name!r}: suffixes must be lower case and start "
                             f"with a dot, got {bad}")
        if not self.output_name:
            object.__setattr__(self, "output_name", self.name)

    def open(self, path: str | Path) -> list[Source]:
        """The file's streams (one for most formats)."""
        opened = self.reader(Path(path))
        streams = [opened] if isinstance(opened, Source) else list(opened)
        if not streams:
            raise RecordingError(f"{path}: the {self.name} reader found no stream of columns")
        return streams

    def accepts(self, head: bytes) -> bool:
        """True when :attr:`sniff` recognises ``head`` (never raises)."""
        if self.sniff is None:
            return False
        try:
            return bool(self.sniff(head))
        except Exception:  # a plugin's sniff must not break the choice of another format
            return False


# -- sinks ---------------------------------------------------------------------
class Sink:
    """Writes float64 columns chunk by chunk to ``path``."""

    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        self.path = path
        self.names = list(names)

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError

    def set_metadata(self, metadata: Metadata) -> None:
        """The metadata the file ends with, replacing that it was opened with (called before
        :meth:`close`; e.g. the restarts of a logger, known only once every row is read)."""
        raise NotImplementedError(f"{type(self).__name__} cannot change its metadata")

    def abort(self) -> None:
        """Discard what was written (the caller removes the file)."""
        self.close()
