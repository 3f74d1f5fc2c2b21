"""File formats of recordings: the source and sink interfaces, Parquet and HDF5.

A *source* opens a file, lists its columns and raw metadata, and reads the
columns asked for as :class:`pyarrow.Table` objects, whole or in batches, without
loading more than a batch. A *sink* writes float64 columns chunk by chunk to a
(temporary) path; :mod:`hrgtc.recording.io` makes that atomic.

Layouts written by hrgtc:

* Parquet: one float64 column per recording column; the metadata as JSON in the
  schema metadata under the key ``b"hrgtc"``; each field's unit in the field
  metadata (``b"unit"``).
* CSV: see :mod:`hrgtc.recording.csv`.
* HDF5: a group ``/recording`` with one 1-D float64 dataset per column (its unit
  in the attribute ``unit``) and the metadata as attributes of the group
  (``extra`` as a JSON string). Foreign files: the group ``recording`` if
  present, else the root if it holds 1-D datasets, else the only group. A dataset
  named like a recording column that is not 1-D (an (N, 3) matrix, a scalar) and a
  compound table are refused, never skipped (issue 21).
"""

from __future__ import annotations

import bisect
import json
import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from hrgtc.errors import RecordingError
from hrgtc.recording.axes import axis_names, base_name, split_axis
from hrgtc.recording.schema import COLUMNS, Metadata

SUFFIXES: dict[str, str] = {
    ".parquet": "parquet",
    ".pq": "parquet",
    ".csv": "csv",
    ".h5": "hdf5",
    ".hdf5": "hdf5",
}
#: Output format name (CLI ``--format``) -> suffix.
FORMAT_SUFFIXES: dict[str, str] = {"parquet": ".parquet", "csv": ".csv", "h5": ".h5"}
METADATA_KEY = b"hrgtc"
HDF5_GROUP = "recording"
PARQUET_ROW_GROUP_ROWS = 1 << 20
HDF5_CHUNK_ROWS = 1 << 16


def format_of(path: str | Path) -> str:
    """``"parquet"``, ``"csv"`` or ``"hdf5"`` from the suffix of ``path``."""
    suffix = Path(path).suffix.lower()
    if suffix not in SUFFIXES:
        known = ", ".join(SUFFIXES)
        raise RecordingError(
            f"{path}: unknown file type {suffix or '(no suffix)'!r}; use one of {known}"
        )
    return SUFFIXES[suffix]


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
    """An open recording file: column names, raw metadata and batched reading."""

    format = ""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.names: list[str] = []
        self.metadata: dict[str, Any] = {}
        self.total_rows: int | None = None

    def kinds(self) -> dict[str, str]:
        """Column name -> kind (see :func:`kind_of`)."""
        raise NotImplementedError

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        """The columns ``names`` (those in ``as_text`` as text where that matters)."""
        raise NotImplementedError

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        """The same, in consecutive tables of at most about ``rows`` rows."""
        raise NotImplementedError

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


class ParquetSource(Source):
    format = "parquet"

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        try:
            # pre_buffer off keeps batch reads small; page CRCs (written by ParquetSink) are
            # verified, so a flipped bit is an error rather than a wrong number
            self._file = pq.ParquetFile(path, pre_buffer=False, page_checksum_verification=True)
        except (pa.ArrowInvalid, OSError) as exc:
            if isinstance(exc, FileNotFoundError):
                raise
            raise RecordingError(f"{path}: not a readable Parquet file ({exc})") from None
        schema = self._file.schema_arrow
        self.names = list(schema.names)
        for i, name in enumerate(self.names):
            if name in self.names[:i]:
                self._file.close()
                raise RecordingError(
                    f"{path}: columns {self.names.index(name) + 1} and {i + 1} are both named "
                    f"{name!r}; hrgtc cannot tell which one is meant: write the file with "
                    "unique column names")
        self.total_rows = self._file.metadata.num_rows
        raw = (schema.metadata or {}).get(METADATA_KEY)
        if raw is not None:
            try:
                self.metadata = dict(loads_json(raw))
            except (ValueError, TypeError):
                raise RecordingError(f"{path}: the hrgtc metadata is not valid JSON") from None
        self._done = 0

    def kinds(self) -> dict[str, str]:
        return {f.name: kind_of(f.type) for f in self._file.schema_arrow}

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        try:
            return self._file.read(columns=list(names))
        except (pa.ArrowException, OSError) as exc:
            raise self._corrupt(exc) from None

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        batches = self._file.iter_batches(batch_size=rows, columns=list(names))
        while True:
            try:
                batch = next(batches)
            except StopIteration:
                return
            except (pa.ArrowException, OSError) as exc:
                raise self._corrupt(exc) from None
            self._done += batch.num_rows
            yield pa.Table.from_batches([batch])

    def _corrupt(self, exc: Exception) -> RecordingError:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        return RecordingError(
            f"{self.path}: the Parquet data are corrupt near row {self._done} ({first}); "
            "the file was damaged after it was written: restore it from its source")

    def position(self) -> tuple[float, float]:
        return (float(self._done), float(self.total_rows or 0))

    def close(self) -> None:
        self._file.close()


class Hdf5Source(Source):
    format = "hdf5"

    def __init__(self, path: Path) -> None:
        import h5py

        super().__init__(path)
        if not path.exists():
            raise FileNotFoundError(2, "No such file or directory", str(path))
        try:
            self._file = h5py.File(path, "r")
        except OSError as exc:
            raise RecordingError(f"{path}: not a readable HDF5 file ({exc})") from None
        group = self._pick_group(h5py)
        self._datasets = {
            name: obj
            for name, obj in group.items()
            if isinstance(obj, h5py.Dataset) and obj.ndim == 1 and obj.dtype.names is None
        }
        self.skipped = {  # datasets that are not a column: named if asked for
            name: obj for name, obj in group.items()
            if isinstance(obj, h5py.Dataset) and name not in self._datasets
        }
        self._refuse_shapes()
        self.names = list(self._datasets)
        lengths = {name: ds.shape[0] for name, ds in self._datasets.items()}
        if len(set(lengths.values())) > 1:
            self._file.close()
            raise RecordingError(f"{path}: datasets of different lengths {lengths}")
        self.total_rows = next(iter(lengths.values()), 0)
        self.metadata = {k: _attr_value(v) for k, v in group.attrs.items()}
        if isinstance(self.metadata.get("extra"), str):
            try:
                self.metadata["extra"] = loads_json(self.metadata["extra"])
            except ValueError:
                pass
        self._done = 0

    def _refuse_shapes(self) -> None:
        """Refuse a recording column stored as a table, a matrix or a scalar."""
        for name, ds in self.skipped.items():
            if ds.dtype.names is not None:
                fields = ", ".join(ds.dtype.names[:8])
                why = (f"dataset {name!r} is a compound table (fields {fields}); hrgtc reads "
                       "one 1-D dataset per column: store each field as its own dataset "
                       f"(e.g. group['time_s'] = table['time_s']) in a group {HDF5_GROUP!r}")
            elif is_column_name(name):
                shape = "a scalar (shape ())" if ds.ndim == 0 else f"of shape {ds.shape}"
                why = (f"dataset {name!r} is {shape}, not a 1-D column of one value per row; "
                       "store one 1-D dataset per column (a 3-axis rate as rate_dph_x, "
                       "rate_dph_y, rate_dph_z)")
            else:
                continue
            self._file.close()
            raise RecordingError(f"{self.path}: {why}")

    def _pick_group(self, h5py: Any) -> Any:
        root = self._file
        if HDF5_GROUP in root and isinstance(root[HDF5_GROUP], h5py.Group):
            return root[HDF5_GROUP]
        if any(isinstance(o, h5py.Dataset) and o.ndim == 1 for o in root.values()):
            return root
        groups = [name for name, o in root.items() if isinstance(o, h5py.Group)]
        if len(groups) == 1:
            return root[groups[0]]
        self._file.close()
        raise RecordingError(
            f"{self.path}: no group {HDF5_GROUP!r} and no 1-D datasets at the root "
            f"(groups: {groups}); store one dataset per column in a group {HDF5_GROUP!r}"
        )

    def kinds(self) -> dict[str, str]:
        kinds = {}
        for name, ds in self._datasets.items():
            char = ds.dtype.kind
            kinds[name] = "numeric" if char in "fiub" else "string" if char in "SUO" else "other"
        return kinds

    def _table(self, names: Sequence[str], start: int, stop: int) -> pa.Table:
        arrays = {}
        for name in names:
            values = self._datasets[name][start:stop]
            if values.dtype.kind in "SO":
                values = [
                    v.decode("utf-8", "replace") if isinstance(v, bytes) else v for v in values
                ]
            arrays[name] = pa.array(values)
        return pa.table(arrays)

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        return self._table(names, 0, self.total_rows)

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        for start in range(0, self.total_rows, rows):
            stop = min(start + rows, self.total_rows)
            self._done = stop
            yield self._table(names, start, stop)

    def position(self) -> tuple[float, float]:
        return (float(self._done), float(self.total_rows or 0))

    def close(self) -> None:
        self._file.close()


def is_column_name(name: str) -> bool:
    """True for a recording contract column, per-axis ones (``rate_dph_x``) included."""
    base, axis = split_axis(name)
    return name in COLUMNS or (axis is not None and base in COLUMNS)


def _attr_value(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace")
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


# -- sinks ---------------------------------------------------------------------
def column_unit(name: str, axes: Sequence[str] = ()) -> str | None:
    """Unit of a contract column, per-axis ones (``rate_dph_x`` of ``axes``) included; else None."""
    base = base_name(name, axes)
    return COLUMNS[base][0] if base in COLUMNS else None


def _field_metadata(name: str, axes: Sequence[str]) -> dict[bytes, bytes] | None:
    unit = column_unit(name, axes)
    return {b"unit": unit.encode()} if unit else None


class Sink:
    """Writes float64 columns chunk by chunk to ``path``."""

    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        self.path = path
        self.names = list(names)

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        raise NotImplementedError

    def close(self) -> None:
        raise NotImplementedError


def _arrow_float64(values: np.ndarray) -> pa.Array:
    """A float64 numpy array as an Arrow array over the same memory (no pandas import)."""
    values = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(values), [None, pa.py_buffer(values)])


class ParquetSink(Sink):
    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        super().__init__(path, metadata, names)
        axes = axis_names(names)
        # Columns are declared non-nullable (a sample is a float, NaN included, never
        # missing): the writer then encodes no definition levels, which cost a third of
        # the write (151 -> 102 ms per million rows of 11 columns), and readers skip them.
        fields = [pa.field(n, pa.float64(), nullable=False, metadata=_field_metadata(n, axes))
                  for n in names]
        self._schema = pa.schema(fields, metadata={METADATA_KEY: metadata_json(metadata)})
        # Float gyro data does not compress as it is (snappy saved 0 % on simulated runs
        # and cost a third of the write speed), but with its bytes split into streams
        # (BYTE_STREAM_SPLIT: sign/exponent bytes apart from the noisy mantissa bytes) LZ4
        # halves it: 202 -> 95 MB for a 3.6 M-row run, 317 -> 165 MB compensated, read
        # twice as fast, and half the bytes to wait for at the fsync of a durable write.
        # Page checksums (CRC32) let every reader detect a flipped bit. Min/max statistics
        # are kept for time_s only (a query by time skips row groups; min/max of every
        # other column cost 12 % of the write and nothing reads them).
        self._writer = pq.ParquetWriter(
            str(path), self._schema, use_dictionary=False, compression="lz4",
            use_byte_stream_split=True, write_page_checksum=True,
            write_statistics=[n for n in names if n == "time_s"] or False)
        self._pending: list[pa.Table] = []
        self._pending_rows = 0

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        arrays = [_arrow_float64(columns[n]) for n in self.names]
        table = pa.Table.from_arrays(arrays, schema=self._schema)
        self._pending.append(table)
        self._pending_rows += table.num_rows
        if self._pending_rows >= PARQUET_ROW_GROUP_ROWS:
            self._flush()

    def _flush(self) -> None:
        if self._pending:
            self._writer.write_table(
                pa.concat_tables(self._pending), row_group_size=PARQUET_ROW_GROUP_ROWS
            )
        self._pending, self._pending_rows = [], 0

    def close(self) -> None:
        self._flush()
        self._writer.close()

    def abort(self) -> None:
        self._pending = []
        self._writer.close()


class Hdf5Sink(Sink):
    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        import h5py

        super().__init__(path, metadata, names)
        metadata_json(metadata)
        self._file = h5py.File(path, "w")
        group = self._file.create_group(HDF5_GROUP, track_order=True)
        for key, value in metadata.to_dict().items():
            group.attrs[key] = json.dumps(value) if key == "extra" else value
        self._datasets = {}
        axes = axis_names(names)
        for name in names:
            ds = group.create_dataset(
                name, shape=(0,), maxshape=(None,), dtype="f8", chunks=(HDF5_CHUNK_ROWS,)
            )
            if column_unit(name, axes):
                ds.attrs["unit"] = column_unit(name, axes)
            self._datasets[name] = ds
        self._rows = 0

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        n = len(columns[self.names[0]]) if self.names else 0
        for name, ds in self._datasets.items():
            ds.resize((self._rows + n,))
            ds[self._rows :] = columns[name]
        self._rows += n

    def close(self) -> None:
        self._file.close()

    def abort(self) -> None:
        self._file.close()
