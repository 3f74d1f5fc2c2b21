"""HDF5 recordings: one 1-D dataset per column, in a group.

Layout written by hrgtc: a group ``/recording`` with one 1-D float64 dataset per column
(its unit in the attribute ``unit``) and the metadata as attributes of the group
(``extra`` as a JSON string). Foreign files: the group ``recording`` if present, else
the root if it holds 1-D datasets, else the only group; a file of several groups that
each hold their own time axis (a 1-D ``time_s`` dataset), such as a logger writing its
fast and slow channels apart, is read as one stream per group, joined by
:mod:`hrgtc.recording.align`. A dataset named like a recording column that is not 1-D
(an (N, 3) matrix, a scalar) and a compound table are refused, never skipped (issue 21).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from hrgtc.core.errors import RecordingError
from hrgtc.recording.axes import axis_names
from hrgtc.recording.formats.base import (
    Format,
    Sink,
    Source,
    column_unit,
    is_column_name,
    loads_json,
    metadata_json,
)
from hrgtc.recording.schema import Metadata

HDF5_GROUP = "recording"
HDF5_CHUNK_ROWS = 1 << 16
#: The HDF5 format signature (at byte 0, 512, 1024, 2048 ... of the file).
SIGNATURE = b"\x89HDF\r\n\x1a\n"


class Hdf5Source(Source):
    format = "hdf5"

    def __init__(self, path: Path, handle: Any = None, group_name: str | None = None) -> None:
        import h5py

        super().__init__(path)
        self._file = _open_file(path) if handle is None else handle
        group = self._pick_group(h5py) if group_name is None else self._file[group_name]
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
        attributes = dict(group.attrs) if group_name is None else {
            **self._file.attrs, **group.attrs}  # one stream of several: the file's, then its own
        self.metadata = {k: _attr_value(v) for k, v in attributes.items()}
        self.stream = group_name or ""
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


def _open_file(path: Path) -> Any:
    import h5py

    if not path.exists():
        raise FileNotFoundError(2, "No such file or directory", str(path))
    try:
        return h5py.File(path, "r")
    except OSError as exc:
        raise RecordingError(f"{path}: not a readable HDF5 file ({exc})") from None


def stream_groups(root: Any) -> list[str] | None:
    """The groups of a file of several streams, each with its own ``time_s``; else None.

    Only a file without a group ``recording`` and without 1-D datasets at the root, whose
    groups holding datasets (at least two) each hold a 1-D ``time_s``.
    """
    import h5py

    if HDF5_GROUP in root or any(isinstance(o, h5py.Dataset) for o in root.values()):
        return None
    holding = [name for name, o in root.items() if isinstance(o, h5py.Group)
               and any(isinstance(d, h5py.Dataset) for d in o.values())]
    timed = [name for name in holding if isinstance(root[name].get("time_s"), h5py.Dataset)
             and root[name]["time_s"].ndim == 1]
    return timed if len(holding) >= 2 and timed == holding else None


def open_hdf5(path: Path) -> Source | list[Source]:
    """The file's stream, or one stream per group for a file of groups on their own time axes."""
    handle = _open_file(path)
    try:
        groups = stream_groups(handle)
        if groups is None:
            return Hdf5Source(path, handle)
        return [Hdf5Source(path, handle, name) for name in groups]
    except BaseException:
        handle.close()
        raise


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


class Hdf5Sink(Sink):
    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        import h5py

        super().__init__(path, metadata, names)
        metadata_json(metadata)
        self._file = h5py.File(path, "w")
        group = self._file.create_group(HDF5_GROUP, track_order=True)
        self._group = group
        self.set_metadata(metadata)
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

    def set_metadata(self, metadata: Metadata) -> None:
        metadata_json(metadata)
        for key, value in metadata.to_dict().items():
            self._group.attrs[key] = json.dumps(value) if key == "extra" else value

    def close(self) -> None:
        self._file.close()

    def abort(self) -> None:
        self._file.close()


def sniff(head: bytes) -> bool:
    """True for the HDF5 signature at the start of the file or after a user block."""
    return any(head[at:at + 8] == SIGNATURE for at in (0, 512, 1024, 2048))


FORMAT = Format("hdf5", (".h5", ".hdf5"), open_hdf5, sniff, Hdf5Sink, output_name="h5",
                description="HDF5, one 1-D dataset per channel in a group")
