"""CSV recordings: ``# key: value`` metadata header (or a JSON sidecar) and a fast parser.

Reading uses pyarrow's multi-threaded CSV parser (whole files) or its streaming
reader (chunks), the columns forced to float64, so millions of rows take
seconds; its errors are translated into messages that name the file, column,
line or row, the bad value and the fix. Writing uses pyarrow's CSV writer, whose
floats are the shortest strings that round-trip (as exact as ``%.17g``).

Layout written by hrgtc::

    # hrgtc recording (schema 1)
    # sample_rate_hz: 200.0
    # unit: paper-unit
    # input_rate_dph: 9.67
    # profile: soak -10 C
    # schema: 1
    # extra: {"seed": 1}
    time_s,freq_hz,rate_dph
    0,4424.9,9.71
    ...

Strings are written bare when that reads back unchanged, else as JSON. Foreign
files: comment lines of other forms are ignored, ``key: value`` lines of other
keys go to ``extra``, the delimiter (``,``, ``;`` or tab) is sniffed from the
header, and a file without a header gets columns ``column_1``, ``column_2``, ...
Delimiters at the end of the lines (empty trailing columns) are left out. Refused,
each with its own message: lines ending in CR alone, values separated by spaces,
a column without a name, two columns of the same name (issue 21).
A sidecar ``<file>.json`` (e.g. ``run.csv.json``) adds to or overrides the header.
A gzip-compressed file (``run.csv.gz``) is read through a decompressor, with the same
checks and messages; it is never written (compress a written ``.csv`` afterwards).
"""

from __future__ import annotations

import gzip
import json
import os
import re
import shutil
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np
import pyarrow as pa
import pyarrow.csv as pa_csv

from hrgtc.core.errors import RecordingError
from hrgtc.core.files import forget_temporary, temporary_beside
from hrgtc.recording.formats.base import (
    Format,
    Sink,
    Source,
    first_failing,
    kind_of,
    loads_json,
    metadata_json,
)
from hrgtc.recording.schema import Metadata

#: Bytes per block of the CSV reader (pyarrow's block size).
CSV_BLOCK_BYTES = 8 << 20
#: Bytes of a CSV file's start that estimate its bytes per row (for the progress bar).
SAMPLE_BYTES = 1 << 20
#: Bytes per block when a CSV file's lines are counted.
COUNT_BLOCK_BYTES = 4 << 20
_STRING_KEYS = ("unit", "profile")


class CsvSource(Source):
    format = "csv"

    def __init__(self, path: Path) -> None:
        super().__init__(path)
        _refuse_cr_only(path)
        self._offset, header, comments = _csv_head(path)
        self.metadata = _parse_comment_metadata(comments)
        if not header:
            raise RecordingError(f"{path}: no header line (only comments or nothing); the "
                                 "first line that is not a '#' comment must name the columns")
        self.delimiter = _sniff_delimiter(header)
        _refuse_space_separated(path, header)
        fields = [f.strip().strip('"').strip() for f in header.split(self.delimiter)]
        # delimiters at the end of every line (a logger's line end, a spreadsheet's padding
        # of empty columns) are not columns without a name: read under placeholders, left out
        trailing = 0
        while len(fields) - trailing > 1 and fields[-1 - trailing] == "":
            trailing += 1
        fields = fields[:len(fields) - trailing]
        self._header_rows = 1
        if all(_is_number(f) for f in fields):
            fields = [f"column_{i + 1}" for i in range(len(fields))]
            self._header_rows = 0
        _refuse_bad_names(path, fields, self.delimiter)
        self.names = fields
        self._file_names = [*fields, *(f"{TRAILING_COLUMN} {i}" for i in range(trailing))]
        sidecar = Path(f"{path}.json")
        if sidecar.exists():
            try:
                extra = loads_json(sidecar.read_text(encoding="utf-8"))
            except (ValueError, UnicodeDecodeError) as exc:
                raise RecordingError(f"{sidecar}: not valid JSON ({exc})") from None
            if not isinstance(extra, dict):
                raise RecordingError(f"{sidecar}: expected a JSON object of metadata")
            self.metadata.update(extra)
        self._size = text_bytes(path)
        _refuse_cut_tail(path, self.delimiter, self._offset)
        self._streams: list[pa.NativeFile] = []
        self._rows_done = 0
        with open_bytes(path) as handle:  # bytes per row from the first MiB, for progress
            handle.seek(self._offset)
            sample = handle.read(SAMPLE_BYTES)
        self._bytes_per_row = len(sample) / max(sample.count(b"\n"), 1)

    def _options(self, names: Sequence[str], as_text: set[str], block: int) -> dict[str, Any]:
        types = {n: pa.string() if n in as_text else pa.float64() for n in names}
        return {
            "read_options": pa_csv.ReadOptions(
                column_names=self._file_names, skip_rows=self._header_rows, block_size=block
            ),
            "parse_options": pa_csv.ParseOptions(delimiter=self.delimiter),
            "convert_options": pa_csv.ConvertOptions(
                include_columns=list(names), column_types=types
            ),
        }

    def _open(self) -> pa.NativeFile:
        if is_gzip(self.path):
            stream = pa.input_stream(str(self.path), compression="gzip")
            stream.read(self._offset)  # a compressed stream cannot seek: read past the head
        else:
            stream = pa.OSFile(str(self.path))  # not a memory map: its pages count as RSS
            stream.seek(self._offset)
        self._streams.append(stream)
        return stream

    def kinds(self) -> dict[str, str]:
        options = {
            "read_options": pa_csv.ReadOptions(
                column_names=self._file_names, skip_rows=self._header_rows,
                block_size=1 << 16
            ),
            "parse_options": pa_csv.ParseOptions(delimiter=self.delimiter),
        }
        try:
            reader = pa_csv.open_csv(self._open(), **options)
        except pa.ArrowInvalid as exc:
            raise self._translate(exc, set()) from None
        return {f.name: kind_of(f.type) for f in reader.schema
                if not f.name.startswith(TRAILING_COLUMN)}

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        try:
            return pa_csv.read_csv(self._open(), **self._options(names, as_text, CSV_BLOCK_BYTES))
        except pa.ArrowInvalid as exc:
            raise self._translate(exc, as_text) from None

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        try:
            reader = pa_csv.open_csv(self._open(), **self._options(names, as_text, CSV_BLOCK_BYTES))
            for batch in reader:
                self._rows_done += batch.num_rows
                yield pa.Table.from_batches([batch])
        except pa.ArrowInvalid as exc:
            raise self._translate(exc, as_text) from None

    def count_rows(self) -> int:
        rows, last = 0, b"\n"  # non-empty lines; "\r" is not content
        with open_bytes(self.path) as handle:
            handle.seek(self._offset)
            while block := handle.read(COUNT_BLOCK_BYTES):
                block = block.replace(b"\r", b"")
                if not block:
                    continue
                newline = np.frombuffer(block, np.uint8) == 10
                empty = np.count_nonzero(newline[1:] & newline[:-1])
                empty += bool(newline[0]) and last == b"\n"
                rows += int(np.count_nonzero(newline)) - int(empty)
                last = block[-1:]
        return rows + (last != b"\n") - self._header_rows

    def position(self) -> tuple[float, float]:
        done = self._offset + self._rows_done * self._bytes_per_row
        return (float(min(done, self._size)), float(self._size))

    def close(self) -> None:
        for stream in self._streams:
            stream.close()
        self._streams = []

    # -- errors: name the file, column, row, value and the fix -----------------
    def _invalid_utf8(self) -> RecordingError:
        found = _first_invalid_utf8(self.path, self._offset)
        where = "" if found is None else f"row {max(found[0], 0)} holds byte {found[1]:#04x}, "
        return RecordingError(f"{self.path}: {where}not valid UTF-8 text; save the file as "
                              "UTF-8 (or remove the damaged row)")

    def _translate(self, exc: Exception, as_text: set[str]) -> RecordingError:
        text = str(exc)
        if "invalid UTF8" in text or "invalid utf8" in text.lower():
            return self._invalid_utf8()
        conversion = re.search(r"CSV column #(\d+): CSV conversion error to \w+", text)
        if conversion:
            name = self._file_names[int(conversion.group(1))]
            try:
                row, value = self._locate_bad_value(name)
            except pa.ArrowInvalid:  # the bad value is not even text
                return self._invalid_utf8()
            return RecordingError(
                f"{self.path}: column '{name}', row {row}: {value!r} is not a number; "
                f"{bad_number_hint(value)}"
            )
        fields = re.search(r"Expected (\d+) columns, got (\d+)", text)
        if fields:
            line, row, what = self._locate_bad_line()
            return RecordingError(
                f"{self.path}: line {line} (row {row}): expected {fields.group(1)} fields"
                f"{what}; repair or delete it"
            )
        return RecordingError(f"{self.path}: cannot parse the CSV ({text})")

    def _locate_bad_value(self, name: str) -> tuple[int | str, str]:
        options = self._options([name], {name}, CSV_BLOCK_BYTES)
        offset = 0
        for batch in pa_csv.open_csv(self._open(), **options):
            column = batch.column(0)
            try:
                column.cast(pa.float64())
            except (pa.ArrowInvalid, pa.ArrowTypeError):
                i = first_failing(column, lambda a: a.cast(pa.float64()))
                return offset + i, str(column[i].as_py())
            offset += batch.num_rows
        return "?", "?"

    def _locate_bad_line(self) -> tuple[int | str, int | str, str]:
        """``(line, row, what is wrong)`` of the first data line the parser cannot split
        into the header's fields: too few or too many delimiters, a carriage return inside
        the line (which ends a line for the parser, not for a text editor), or a quote
        without its closing one (the field then runs on into the lines after it)."""
        expected = len(self._file_names)
        line_no = 0
        row = -self._header_rows
        delimiter = self.delimiter.encode()
        with open_bytes(self.path) as handle:
            handle.seek(self._offset)
            line_no = _count_lines(self.path, self._offset)
            for raw in handle:
                line_no += 1
                if not raw.strip():
                    continue
                if row >= 0:
                    body = raw.rstrip(b"\r\n")
                    cr, quote = body.find(b"\r"), body.find(b'"')
                    if cr >= 0:
                        return line_no, row, ("; a carriage return (\\r) inside the line at "
                                              f"character {cr + 1} splits it")
                    if body.count(b'"') % 2:
                        return line_no, row, ("; a quote (\") without its closing one at "
                                              f"character {quote + 1} runs into the lines "
                                              "after it")
                    got = body.count(delimiter) + 1
                    if got != expected:
                        return line_no, row, (f", got {got}; the line is truncated or "
                                              "malformed")
                row += 1
        return "?", "?", ", got another number; the line is truncated or malformed"


#: Name (then a number) under which the empty fields after trailing delimiters are read.
TRAILING_COLUMN = "\x00trailing delimiter"


def _refuse_cr_only(path: Path) -> None:
    """Refuse a file whose lines end in a carriage return alone (classic Mac OS)."""
    with open_bytes(path) as handle:
        head = handle.read(1 << 16)
    if b"\r" in head and b"\n" not in head:
        raise RecordingError(
            f"{path}: the lines end in a carriage return alone (CR, classic Mac OS line "
            "ends), which this reader does not split; convert them to LF, e.g. "
            f"tr '\\r' '\\n' < {path.name} > fixed.csv")


def _refuse_space_separated(path: Path, header: str) -> None:
    """Refuse a header separated by spaces: hrgtc reads ',', ';' or tab separated files."""
    if any(d in header for d in (",", ";", "\t")):
        return
    words = header.split()
    if len(words) > 1:
        raise RecordingError(
            f"{path}: the header line {header[:60]!r} is separated by spaces; hrgtc reads "
            "values separated by ',', ';' or a tab: convert the file, e.g. "
            f"tr -s ' ' ',' < {path.name} > fixed.csv")


def _refuse_bad_names(path: Path, fields: Sequence[str], delimiter: str) -> None:
    """Refuse a header with a column without a name or two columns of the same name."""
    for i, name in enumerate(fields):
        if not name:
            before = f" after {fields[i - 1]!r}" if i else ""
            raise RecordingError(
                f"{path}: column {i + 1}{before} has no name in the header line (two "
                f"delimiters {delimiter!r} in a row?); give every column a name")
    seen: dict[str, int] = {}
    for i, name in enumerate(fields):
        if name in seen:
            raise RecordingError(
                f"{path}: columns {seen[name] + 1} and {i + 1} of the header are both named "
                f"{name!r}; hrgtc cannot tell which one is meant: rename one of them (or "
                "delete the copy)")
        seen[name] = i


#: Lines before the last one compared with it by :func:`_refuse_cut_tail`.
TAIL_LINES = 20


def _refuse_cut_tail(path: Path, delimiter: str, offset: int) -> None:
    """Refuse a file whose last line has no line end and a number shorter than the lines before.

    A logger killed mid-write leaves a last line like ``12.3,4428.5`` where ``4428.53112``
    was being written: a valid number, and a wrong one. A last line without a line end
    whose last field has fewer than half the characters of the same field in the lines
    before is taken as cut.
    """
    start, tail = _tail(path, offset, 64 * 1024)
    if not tail or tail.endswith((b"\n", b"\r")):
        return
    lines = tail.decode("utf-8", "replace").splitlines()
    last, before = lines[-1], [line for line in lines[-1 - TAIL_LINES:-1] if line.strip()]
    if start > offset:
        before = before[1:]  # the first line of the window may itself be cut
    if len(before) < 3:
        return
    field = last.split(delimiter)[-1].strip()
    lengths = sorted(len(line.split(delimiter)[-1].strip()) for line in before)
    typical = lengths[len(lengths) // 2]
    if len(field) * 2 < typical:
        row = _count_data_rows_before_end(path, offset)
        raise RecordingError(
            f"{path}: row {row}, the last line, ends without a line end and its last field "
            f"{field!r} is much shorter than in the lines before (typically {typical} "
            "characters): the file looks cut while it was written; remove the last line")


def is_gzip(path: Path) -> bool:
    """True for a gzip-compressed CSV (``run.csv.gz``), read through a decompressor."""
    return path.name.lower().endswith(".gz")


def open_bytes(path: Path) -> BinaryIO:
    """The file's text bytes: decompressed on the fly for ``.csv.gz``."""
    return gzip.open(path, "rb") if is_gzip(path) else open(path, "rb")


def text_bytes(path: Path) -> int:
    """Bytes of the file's text (of a ``.csv.gz``, its gzip trailer's size, modulo 4 GiB)."""
    if not is_gzip(path):
        return path.stat().st_size
    with open(path, "rb") as handle:
        handle.seek(-4, os.SEEK_END)
        return int.from_bytes(handle.read(4), "little")


def _tail(path: Path, offset: int, size: int) -> tuple[int, bytes]:
    """``(start, bytes)`` of the last ``size`` bytes of the text after ``offset``."""
    with open_bytes(path) as handle:
        handle.seek(offset)
        if not is_gzip(path):
            start = max(offset, handle.seek(0, os.SEEK_END) - size)
            handle.seek(start)
            return start, handle.read()
        tail, done = b"", offset
        while block := handle.read(COUNT_BLOCK_BYTES):
            done += len(block)
            tail = (tail + block)[-size:]
        return max(offset, done - len(tail)), tail


def _count_data_rows_before_end(path: Path, offset: int) -> int:
    with open_bytes(path) as handle:
        handle.seek(offset)
        return max(handle.read().count(b"\n") - 1, 0)


def _first_invalid_utf8(path: Path, offset: int) -> tuple[int, int] | None:
    """(data row, byte) of the first line after ``offset`` that is not UTF-8, or None."""
    with open_bytes(path) as handle:
        handle.seek(offset)
        for row, raw in enumerate(handle, start=-1):
            try:
                raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                return row, raw[exc.start]
    return None


def _csv_head(path: Path) -> tuple[int, str, list[str]]:
    """Byte offset of the header line, the header line and the comment lines."""
    comments: list[str] = []
    offset = 0
    with open_bytes(path) as handle:
        for line, raw in enumerate(handle, start=1):
            try:
                text = raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                raise RecordingError(
                    f"{path}: line {line} is not valid UTF-8 (byte {raw[exc.start]:#04x} at "
                    f"column {exc.start + 1}); save the file as UTF-8") from None
            if offset == 0 and text.startswith("\ufeff"):
                text = text[1:]
            stripped = text.strip()
            if stripped.startswith("#"):
                comments.append(stripped[1:].strip())
            elif stripped:
                return offset, stripped, comments
            offset += len(raw)
    return offset, "", comments


def _count_lines(path: Path, offset: int) -> int:
    with open_bytes(path) as handle:
        return handle.read(offset).count(b"\n")


def _sniff_delimiter(header: str) -> str:
    counts = {d: header.count(d) for d in (",", ";", "\t")}
    best = max(counts, key=counts.__getitem__)
    return best if counts[best] else ","


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def bad_number_hint(text: str) -> str:
    """How to fix a value that should be a number."""
    if re.match(r"^\s*\d{4}-\d{2}-\d{2}([T ]\d{1,2}:\d{2}.*)?$", text):
        return "if the column holds dates and times pass --time-unit timestamp"
    return "fix or remove that row"


def _parse_comment_metadata(lines: Sequence[str]) -> dict[str, Any]:
    metadata: dict[str, Any] = {}
    for line in lines:
        key, sep, raw = line.partition(":")
        key = key.strip()
        if not sep or not re.fullmatch(r"[A-Za-z_][\w .\-]*", key):
            continue
        metadata[key] = _header_value(key, raw.strip())
    return metadata


def _header_value(key: str, raw: str) -> Any:
    if key in _STRING_KEYS and not raw.startswith('"'):
        return raw
    try:
        return loads_json(raw)
    except ValueError:
        return raw


def csv_header(metadata: Metadata, names: Sequence[str]) -> bytes:
    """Comment lines with the metadata and the column header line."""
    metadata_json(metadata)  # fail early on non-JSON extra
    lines = [f"# hrgtc recording (schema {metadata.schema})"]
    for key, value in metadata.to_dict().items():
        text = value if isinstance(value, str) else json.dumps(value)
        if _header_value(key, text) != value or "\n" in text:
            text = json.dumps(value)
        lines.append(f"# {key}: {text}")
    quoted = [f'"{n}"' if any(c in n for c in ',;\t"') else n for n in names]
    lines.append(",".join(quoted))
    return ("\n".join(lines) + "\n").encode("utf-8")


class CsvSink(Sink):
    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        super().__init__(path, metadata, names)
        self._handle = open(path, "wb")  # closed in close() / abort()
        self._header = csv_header(metadata, names)
        self._final: bytes | None = None  # the header set at close (set_metadata)
        self._handle.write(self._header)
        self._schema = pa.schema([pa.field(n, pa.float64()) for n in names])
        self._writer = pa_csv.CSVWriter(
            self._handle, self._schema, write_options=pa_csv.WriteOptions(include_header=False)
        )

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        arrays = [pa.array(columns[n]) for n in self.names]
        self._writer.write_table(pa.Table.from_arrays(arrays, schema=self._schema))

    def set_metadata(self, metadata: Metadata) -> None:
        header = csv_header(metadata, self.names)
        self._final = None if header == self._header else header

    def close(self) -> None:
        self._writer.close()
        self._handle.close()
        if self._final is not None:  # the header is the file's first bytes: copy the rows
            _replace_header(self.path, len(self._header), self._final)

    def abort(self) -> None:
        try:
            self._writer.close()
        finally:
            self._handle.close()


def _replace_header(path: Path, old_bytes: int, header: bytes) -> None:
    """``path`` with its first ``old_bytes`` (the header) replaced by ``header``: the rows
    copied after it into a file beside, which then takes ``path``'s place."""
    beside = Path(temporary_beside(path))  # removed on a signal, as the writer's own
    try:
        with open(path, "rb") as source, open(beside, "wb") as target:
            target.write(header)
            source.seek(old_bytes)
            shutil.copyfileobj(source, target, COUNT_BLOCK_BYTES)
        os.replace(beside, path)
    except BaseException:
        beside.unlink(missing_ok=True)
        raise
    finally:
        forget_temporary(beside)


def sniff(head: bytes) -> bool:
    """True for a CSV file written by hrgtc (its first line); other CSV is known by its suffix."""
    return head.removeprefix(b"\xef\xbb\xbf").startswith(b"# hrgtc recording")


FORMAT = Format("csv", (".csv", ".csv.gz"), CsvSource, sniff, CsvSink,
                description="text, one column per channel, '# key: value' metadata lines")
