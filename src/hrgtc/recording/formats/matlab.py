"""MATLAB ``.mat`` files: v4 and v5 (up to v7) with scipy.io, v7.3 (HDF5) with h5py
(both dependencies of hrgtc; ``pip install 'hrgtc[matlab]'`` names them).

A ``.mat`` file holds variables. hrgtc reads as a table of columns:

* the file's column vectors (N×1 or 1×N, numbers or logicals), each a column named by
  its variable;
* a struct of column vectors (``log.t``, ``log.rate``, ``log.temp``), each field a column;
* a table-like matrix (N×k) with a names variable of k texts (a cell array of char
  vectors or a char matrix) named ``<matrix>_names``, ``names``, ``columns``,
  ``colnames``, ``labels`` or ``header``; without one, columns ``<matrix>_1`` ...
  ``<matrix>_k`` (1-based, as MATLAB counts them).

A file of one such table (vectors of one length, or one struct or matrix) is one stream
with those names. A file of several (a struct per rate, vectors of different lengths) is
one stream per table, columns named ``<table>.<column>``, each table with its own time
column (``time_s``, ``time``, ``t``, ``Time``, ``timestamp``, or a datenum; in seconds),
put on one time axis by :mod:`hrgtc.recording.align` when the column mapping names them.
MATLAB conventions handled:

* **v7.3 arrays are transposed** in the HDF5 file (MATLAB stores column-major): an N×k
  matrix is a k×N dataset, read back as N×k;
* **datenum times**: a column whose name contains ``datenum`` holds days since the year 0
  (``datenum(1970,1,1) = 719529``): read as clock times, so ``--col time_s=<it>`` gives
  seconds since the first sample with the date kept as ``extra["time_origin"]``;
* scalar variables are kept in ``extra["matlab_scalars"]``; one named ``fs`` or
  ``sample_rate_hz`` is the sample rate. Text, cells of numbers, sparse and complex
  arrays and MATLAB objects (``datetime``, ``table``) are not columns: save a table with
  ``s = table2struct(T, 'ToScalar', true)`` and datetimes with ``datenum``.

Files written by hrgtc (:class:`MatlabSink`, ``hrgtc simulate --format mat``) are MAT v5
files of one column vector (N×1 double) per column, named by the column (``load run.mat;
plot(time_s, rate_dph)``), and a struct ``hrgtc_metadata`` of the recording's metadata
(``sample_rate_hz``, ``unit``, ``input_rate_dph``, ``profile``, ``schema`` and
``extra_json``, its extra as JSON text), which the reader takes as the file's metadata.
"""

from __future__ import annotations

import json
import re
import shutil
import struct
import sys
import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from hrgtc.core.errors import RecordingError
from hrgtc.recording.formats.base import Format, Sink, Source, loads_json, metadata_json
from hrgtc.recording.formats.logs import (
    Stream,
    check_exists,
    datenum_to_datetime,
    numeric,
    output_path,
    require,
    streams,
    unreadable,
)
from hrgtc.recording.schema import Metadata

#: Names of a names variable of a matrix, after ``<matrix>_names``.
NAMES_VARIABLES = ("names", "columns", "colnames", "labels", "header", "headers")
#: Names of a table's time column.
TIME_NAMES = ("time_s", "time", "t", "Time", "timestamp", "Timestamp")
#: Plausible datenums: years 1900 to 2200. [days]
DATENUM_RANGE = (693962.0, 803535.0)
#: The text at the start of a v5 or v7.3 MAT-file header.
HEADER = b"MATLAB "
#: The struct of the recording's metadata in the files hrgtc writes.
METADATA_VARIABLE = "hrgtc_metadata"
#: A MATLAB variable name (``isvarname``: a letter, then letters, digits, underscores;
#: at most ``namelengthmax`` = 63 characters).
VARIABLE_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")
#: MATLAB's limit on the bytes of one variable of a v5 (``-v7``) file: 2^31. [bytes]
V5_VARIABLE_BYTES = 2**31
#: MAT v5 data types and the class of a double array (MATLAB's "MAT-File Format", 2024).
MI_INT8, MI_INT32, MI_UINT32, MI_DOUBLE, MI_MATRIX, MX_DOUBLE_CLASS = 1, 5, 6, 9, 14, 6


# -- variables of the file -----------------------------------------------------
def _v73_value(obj: Any, root: Any) -> Any:
    """A v7.3 variable as scipy's ``simplify_cells`` would give it (arrays transposed back)."""
    import h5py

    if isinstance(obj, h5py.Group):
        if obj.attrs.get("MATLAB_class", b"") not in (b"struct", "struct"):
            return None
        return {k: _v73_value(v, root) for k, v in obj.items()}
    kind = obj.attrs.get("MATLAB_class", b"")
    kind = kind.decode() if isinstance(kind, bytes) else str(kind)
    if obj.attrs.get("MATLAB_empty"):
        return np.zeros(0)
    data = np.asarray(obj[()])
    if kind == "char":
        rows = np.atleast_2d(data.T)
        texts = ["".join(map(chr, row)).rstrip("\x00") for row in rows]
        return texts[0] if len(texts) == 1 else texts
    if kind == "cell":
        return [_v73_value(root[ref], root) for ref in data.T.ravel()]
    if data.dtype.names is not None or kind not in {
            "double", "single", "logical", "int8", "uint8", "int16", "uint16", "int32",
            "uint32", "int64", "uint64"}:
        return None  # complex (a compound), sparse, objects
    value = data.T
    return value.squeeze() if value.ndim == 2 and 1 in value.shape else value


def variables(path: Path) -> dict[str, Any]:
    """The variables of a .mat file, structs as dicts and cells as lists (scipy's
    ``simplify_cells``), v7.3 files through h5py."""
    scipy_io = require("scipy.io", "matlab", "MATLAB", path)
    try:
        major, _ = scipy_io.matlab.matfile_version(str(path))
    except Exception as exc:  # scipy raises what the header gives
        raise unreadable(path, "MATLAB", exc, "save it again with save(..., '-v7') or "
                         "'-v7.3'") from None
    if major == 2:
        h5py = require("h5py", "matlab", "MATLAB v7.3", path)
        try:
            with h5py.File(path, "r") as root:
                return {name: _v73_value(obj, root) for name, obj in root.items()
                        if not name.startswith("#")}
        except Exception as exc:  # h5py raises what the file gives
            raise unreadable(path, "MATLAB v7.3 (HDF5)", exc, "save it again with "
                             "save(..., '-v7.3')") from None
    try:
        found = scipy_io.loadmat(str(path), simplify_cells=True)
    except Exception as exc:  # scipy raises what the stream gives
        raise unreadable(path, "MATLAB", exc, "save it again with save(..., '-v7')") from None
    return {k: v for k, v in found.items() if not k.startswith("__")}


# -- tables of columns ---------------------------------------------------------
def _texts(value: Any) -> list[str] | None:
    if isinstance(value, list | tuple | np.ndarray) and len(value) and all(
            isinstance(v, str) for v in value):
        return [str(v).strip() for v in value]
    return None


def _matrix_names(name: str, k: int, found: Mapping[str, Any]) -> list[str]:
    for candidate in (f"{name}_names", f"{name}names", *NAMES_VARIABLES):
        texts = _texts(found.get(candidate))
        if texts is not None and len(texts) == k:
            return texts
    return [f"{name}_{j + 1}" for j in range(k)]


def _by_length(name: str, columns: dict[str, np.ndarray]) -> list[Stream]:
    lengths = sorted({len(v) for v in columns.values()}, reverse=True)
    return [Stream(name if len(lengths) == 1 else f"{name}_{n}" if name else f"length_{n}",
                   {k: v for k, v in columns.items() if len(v) == n}) for n in lengths]


def tables(found: Mapping[str, Any]) -> tuple[list[Stream], dict[str, float]]:
    """The tables of columns among the variables ``found``, and the scalar variables."""
    vectors: dict[str, np.ndarray] = {}
    scalars: dict[str, float] = {}
    out: list[Stream] = []
    for name, value in found.items():
        if isinstance(value, dict):
            fields = {}
            for key, field in value.items():
                array = np.asarray(field) if isinstance(field, np.ndarray) else None
                if array is not None and array.ndim == 2 and 1 in array.shape:
                    array = array.ravel()
                if array is not None and array.ndim == 1 and array.size > 1:
                    column = numeric(array)
                    if column is not None:
                        fields[key] = column
            out += _by_length(name, fields) if fields else []
            continue
        if isinstance(value, int | float | np.number) and not isinstance(value, bool):
            scalars[name] = float(value)
            continue
        array = np.asarray(value) if isinstance(value, np.ndarray) else None
        if array is None or array.dtype.kind not in "fiub":
            continue
        if array.ndim == 1 and array.size > 1:
            vectors[name] = numeric(array)
        elif array.ndim == 2 and min(array.shape) > 1:
            names = _matrix_names(name, array.shape[1], found)
            out.append(Stream(name, {n: numeric(array[:, j]) for j, n in enumerate(names)}))
        elif array.ndim == 0:
            scalars[name] = float(array)
    if vectors:
        out = _by_length("", vectors) + out
    return out, scalars


def _datenums(path: Path, stream: Stream) -> None:
    """Datenum columns as clock times (in place)."""
    for name, values in list(stream.columns.items()):
        if "datenum" not in name.lower():
            continue
        finite = values[np.isfinite(values)]
        if finite.size and (finite.min() < DATENUM_RANGE[0] or finite.max() > DATENUM_RANGE[1]):
            raise RecordingError(
                f"{path}: column {name!r} is named a datenum but holds {finite.min():.6g} .. "
                f"{finite.max():.6g}, not days of the years 1900-2200 since the year 0; "
                "rename it, or save datenum(t) for datetimes t")
        stream.columns[name] = datenum_to_datetime(values)


def _timed(path: Path, stream: Stream, origin_ns: int | None) -> None:
    """A table of a file of several: its time column as ``time_s`` [s]."""
    dated = [n for n, v in stream.columns.items() if np.asarray(v).dtype.kind == "M"]
    named = [n for n in TIME_NAMES if n in stream.columns]
    if dated and origin_ns is not None:
        stamps = np.asarray(stream.columns.pop(dated[0])).astype("int64")
        stream.columns["time_s"] = (stamps - origin_ns) * 1e-9
    elif named:
        stream.columns["time_s"] = np.asarray(stream.columns.pop(named[0]), dtype=np.float64)


def _written_metadata(path: Path, found: dict[str, Any]) -> dict[str, Any] | None:
    """The metadata hrgtc wrote as the struct ``hrgtc_metadata`` (removed from ``found``)."""
    struct_ = found.get(METADATA_VARIABLE)
    if not isinstance(struct_, dict) or "sample_rate_hz" not in struct_:
        return None
    del found[METADATA_VARIABLE]

    def text(key: str) -> str:
        value = struct_.get(key, "")
        return value if isinstance(value, str) else ""  # an empty char array: ""

    try:
        extra = loads_json(text("extra_json") or "{}")
    except ValueError:
        raise RecordingError(f"{path}: {METADATA_VARIABLE}.extra_json (hrgtc's metadata) is "
                             "not valid JSON") from None
    return {"sample_rate_hz": float(struct_["sample_rate_hz"]), "unit": text("unit"),
            "input_rate_dph": float(struct_.get("input_rate_dph", 0.0)),
            "profile": text("profile"), "schema": int(struct_.get("schema", 1)),
            "extra": extra}


def read_matlab(path: Path) -> list[Source]:
    """The tables of a .mat file: one stream, or one per table of a file of several."""
    check_exists(path)
    found_variables = variables(path)
    written = _written_metadata(path, found_variables)
    found, scalars = tables(found_variables)
    if not found:
        raise RecordingError(
            f"{path}: no column vectors, struct of column vectors or N×k matrix of numbers "
            "in the .mat file; save the channels as vectors, e.g. save(f, 't', 'rate', 'temp') "
            "or a struct s = table2struct(T, 'ToScalar', true)")
    for stream in found:
        _datenums(path, stream)
    extra: dict[str, Any] = {"matlab_scalars": scalars} if scalars else {}
    metadata: dict[str, Any] = {"extra": extra}
    rate = scalars.get("sample_rate_hz", scalars.get("fs"))
    if rate is not None and rate > 0:
        metadata["sample_rate_hz"] = rate
    if len([s for s in found if s.rows()]) > 1:
        stamps = [np.asarray(v).astype("datetime64[ns]").astype("int64")[0]
                  for s in found for v in s.columns.values() if np.asarray(v).dtype.kind == "M"]
        origin = min(stamps) if stamps else None
        if origin is not None:
            extra["time_origin"] = str(np.datetime64(int(origin), "ns"))
        for stream in found:
            _timed(path, stream, origin)
        metadata.pop("sample_rate_hz", None)  # of which table?
    return streams(path, found, "matlab", ".", metadata if written is None else written)


# -- writing -------------------------------------------------------------------
def _element(kind: int, data: bytes, order: str) -> bytes:
    """A MAT v5 data element (tag and data padded to 8 bytes; 'small' when ≤ 4 bytes)."""
    if len(data) <= 4:
        return struct.pack(f"{order}HH", kind, len(data)) + data.ljust(4, b"\0")
    return struct.pack(f"{order}II", kind, len(data)) + data + b"\0" * (-len(data) % 8)


def column_header(name: str, rows: int, order: str) -> bytes:
    """The bytes of a MAT v5 N×1 double variable ``name`` before its ``8 * rows`` bytes of
    values (array flags, dimensions, name, the tag of the real part)."""
    body = (_element(MI_UINT32, struct.pack(f"{order}II", MX_DOUBLE_CLASS, 0), order)
            + _element(MI_INT32, struct.pack(f"{order}ii", rows, 1), order)
            + _element(MI_INT8, name.encode("ascii"), order)
            + struct.pack(f"{order}II", MI_DOUBLE, 8 * rows))
    return struct.pack(f"{order}II", MI_MATRIX, len(body) + 8 * rows) + body


class MatlabSink(Sink):
    """Writes a recording as a MAT v5 file MATLAB loads (``load run.mat``): a column vector
    per column and the struct ``hrgtc_metadata``.

    A v5 variable's bytes are one block whose length comes first, so each chunk's values go
    to a temporary file per column beside ``path``; :meth:`close` writes the header and the
    metadata struct with ``scipy.io.savemat``, then each column's header and its values
    copied from its temporary file in blocks: memory of one chunk, never of the file.
    """

    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        super().__init__(path, metadata, names)
        self._scipy_io = require("scipy.io", "matlab", "MATLAB", output_path(path), "writing")
        bad = [n for n in names if not VARIABLE_NAME.fullmatch(n) or n == METADATA_VARIABLE]
        if bad:
            raise RecordingError(
                f"{output_path(path)}: column(s) {bad} cannot be MATLAB variable names (a "
                "letter, then letters, digits or underscores, at most 63 characters; not "
                f"{METADATA_VARIABLE!r}); rename them or write .parquet or .h5")
        self._order = "<" if sys.byteorder == "little" else ">"
        self.set_metadata(metadata)
        self._rows = 0
        self._spills: dict[str, IO[bytes]] = {}
        try:
            for name in names:
                self._spills[name] = tempfile.TemporaryFile(dir=path.parent,
                                                            prefix=f".{path.name}.")
        except BaseException:
            self.abort()
            raise

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        rows = len(columns[self.names[0]])
        if 8 * (self._rows + rows) + 64 > V5_VARIABLE_BYTES:
            raise RecordingError(
                f"{output_path(self.path)}: a MATLAB v5 variable holds at most 2^31 bytes "
                f"({V5_VARIABLE_BYTES // 8 - 8:,} rows of doubles); write .h5 or .parquet")
        for name, spill in self._spills.items():
            np.asarray(columns[name], dtype=f"{self._order}f8").tofile(spill)
        self._rows += rows

    def set_metadata(self, metadata: Metadata) -> None:
        metadata_json(metadata)  # refuses an extra that is not JSON
        data = metadata.to_dict()
        self._struct = {"sample_rate_hz": float(data["sample_rate_hz"]), "unit": data["unit"],
                        "input_rate_dph": float(data["input_rate_dph"]),
                        "profile": data["profile"], "schema": float(data["schema"]),
                        "extra_json": json.dumps(data["extra"], allow_nan=False)}

    def close(self) -> None:
        try:
            with open(self.path, "wb") as out:
                self._scipy_io.savemat(out, {METADATA_VARIABLE: self._struct}, format="5",
                                       oned_as="column")
                for name, spill in self._spills.items():
                    out.write(column_header(name, self._rows, self._order))
                    spill.seek(0)
                    shutil.copyfileobj(spill, out, 1 << 20)
        finally:
            self.abort()

    def abort(self) -> None:
        for spill in self._spills.values():
            spill.close()
        self._spills = {}



def sniff(head: bytes) -> bool:
    """True for a v5 or v7.3 MAT-file header (v4 files have none: known by suffix)."""
    return head.startswith(HEADER) and b"MAT-file" in head[:116]


FORMAT = Format("matlab", (".mat",), read_matlab, sniff, MatlabSink, output_name="mat",
                description="MATLAB .mat v4/v5/v7 (scipy) and v7.3 (h5py), a stream per table",
                within="hdf5")
