"""Parquet recordings: columnar, compressed, read in row groups.

Layout written by hrgtc: one float64 column per recording column; the metadata as
JSON in the schema metadata under the key ``b"hrgtc"``; each field's unit in the
field metadata (``b"unit"``).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from hrgtc.core.errors import RecordingError
from hrgtc.recording.axes import axis_names
from hrgtc.recording.formats.base import (
    Format,
    Sink,
    Source,
    column_unit,
    kind_of,
    loads_json,
    metadata_json,
)
from hrgtc.recording.schema import Metadata
from hrgtc.settings.compensation import ROW_GROUP_ROWS

METADATA_KEY = b"hrgtc"
PARQUET_ROW_GROUP_ROWS = ROW_GROUP_ROWS
#: The first and last bytes of every Parquet file.
MAGIC = b"PAR1"


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
        # the file's key-value metadata first: it holds what the writer set at close
        # (ParquetSink.set_metadata), the Arrow schema's copy what it was opened with
        raw = (self._file.metadata.metadata or {}).get(METADATA_KEY,
                                                       (schema.metadata or {}).get(METADATA_KEY))
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


def _field_metadata(name: str, axes: Sequence[str]) -> dict[bytes, bytes] | None:
    unit = column_unit(name, axes)
    return {b"unit": unit.encode()} if unit else None


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

    def set_metadata(self, metadata: Metadata) -> None:
        # the file's key-value metadata, written with the footer (the schema's is fixed)
        self._writer.add_key_value_metadata({METADATA_KEY: metadata_json(metadata)})

    def close(self) -> None:
        self._flush()
        self._writer.close()

    def abort(self) -> None:
        self._pending = []
        self._writer.close()


def sniff(head: bytes) -> bool:
    """True for the Parquet signature ``PAR1`` at the start of the file."""
    return head.startswith(MAGIC)


FORMAT = Format("parquet", (".parquet", ".pq"), ParquetSource, sniff, ParquetSink,
                description="Apache Parquet, one column per channel (hrgtc's own format)")
