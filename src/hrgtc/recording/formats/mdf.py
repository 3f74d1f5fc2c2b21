"""ASAM MDF files (``.mf4``, ``.mdf``: Vector CANape, ETAS INCA, rate-table and automotive
loggers), read with asammdf (``pip install 'hrgtc[mdf]'``).

An MDF file holds channel groups, each recorded at its own rate with its own master
channel (the time, in seconds from the measurement's start, which is kept as
``extra["time_origin"]``). Each group is one stream with its master as ``time_s``; its
channels are columns named as in the file for a file of one group and
``<group>/<channel>`` for a file of several (the group by its acquisition name, else
its number), whose groups are read when the column mapping names one of their channels
and put on one time axis by :mod:`hrgtc.recording.align`. Values are physical (asammdf
applies the channels' conversions); a channel converted to text, an array channel and a
group whose master is not a time (an angle, a distance) are listed but not numbers.
Large groups are read in batches of records, never whole.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from datetime import UTC
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa

from hrgtc.core.errors import RecordingError
from hrgtc.recording.formats.base import Format, Source
from hrgtc.recording.formats.logs import check_exists, quiet, require, unreadable

#: The identification block of MDF 3 and 4 ("MDF     "; "UnFinMF " for an unfinished one).
MAGICS = (b"MDF     ", b"UnFinMF ")
#: ``sync_type`` of a master channel that is a time.
SYNC_TIME = 1


class MdfGroupSource(Source):
    """One channel group of an MDF file, read in batches of records."""

    format = "mdf"

    def __init__(self, path: Path, mdf: Any, index: int, prefix: str, owner: bool) -> None:
        super().__init__(path)
        self._mdf, self._index, self._owner = mdf, index, owner
        group = mdf.groups[index]
        master = mdf.masters_db.get(index)
        self.total_rows = int(group.channel_group.cycles_nr)
        self.stream = prefix.rstrip("/") or str(group.channel_group.acq_name or index)
        self.on_request = bool(prefix)
        self._timed = master is not None and group.channels[master].sync_type == SYNC_TIME
        self._columns: dict[str, int] = {}
        units: dict[str, str] = {}
        for j, channel in enumerate(group.channels):
            if j == master and self._timed:
                continue
            name = f"{prefix}{channel.name}"
            if name not in self._columns and name != "time_s":
                self._columns[name] = j
                if channel.unit:
                    units[name] = str(channel.unit)
        self.names = (["time_s"] if self._timed else []) + list(self._columns)
        extra: dict[str, Any] = {"mdf_group": self.stream}
        if units:
            extra["mdf_units"] = units
        start = getattr(mdf.header, "start_time", None)
        if start is not None and self._timed:
            extra["time_origin"] = np.datetime_as_string(
                np.datetime64(start.astimezone(UTC).replace(tzinfo=None), "us"))
        self.metadata: dict[str, Any] = {"extra": extra}
        self._kinds: dict[str, str] | None = None
        self._done = 0

    def _values(self, name: str, start: int, count: int) -> np.ndarray:
        try:
            if name == "time_s":
                return np.asarray(self._mdf.get_master(self._index, record_offset=start,
                                                       record_count=count), dtype=np.float64)
            signal = self._mdf.get(group=self._index, index=self._columns[name],
                                   record_offset=start, record_count=count)
        except Exception as exc:  # asammdf raises what the blocks give
            raise unreadable(self.path, "MDF", exc) from None
        return np.asarray(signal.samples)

    def _record_bytes(self) -> int:
        group = self._mdf.groups[self._index].channel_group
        return max(int(group.samples_byte_nr) + int(getattr(group, "invalidation_bytes_nr", 0)),
                   1)

    def _first(self, name: str) -> np.ndarray:
        """The first few samples of a column, from the first fragment only."""
        self._mdf.configure(read_fragment_size=16 * self._record_bytes())
        master = self._mdf.masters_db.get(self._index)
        part = self._mdf.iter_get(group=self._index, samples_only=True,
                                  index=master if name == "time_s" else self._columns[name])
        try:
            with quiet(("asammdf",)):
                return np.asarray(next(part)[0])
        except StopIteration:
            return np.zeros(0)
        except Exception as exc:  # asammdf raises what the blocks give
            raise unreadable(self.path, "MDF", exc) from None
        finally:
            part.close()

    def kinds(self) -> dict[str, str]:
        if self._kinds is None:
            self._kinds = {}
            for name in self.names:
                first = self._first(name)  # a get() of one record reads them all
                char = first.dtype.kind
                self._kinds[name] = ("numeric" if char in "fiub" and first.ndim == 1 else
                                     "string" if char in "SUO" else "other")
        return self._kinds

    def _table(self, names: Sequence[str], start: int, stop: int) -> pa.Table:
        return pa.table({name: pa.array(_one_value_per_record(
            self.path, name, self._values(name, start, stop - start))) for name in names})

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        self._done = int(self.total_rows or 0)
        return self._table(names, 0, self._done)

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        """Tables of the records of each fragment of about ``rows`` records that asammdf
        reads (``read_fragment_size``), every column from the same fragment: the memory of
        one fragment, never of the file (a ``get`` with ``record_offset`` reads the records
        before the offset too)."""
        self._mdf.configure(read_fragment_size=max(int(rows), 1) * self._record_bytes())
        master = self._mdf.masters_db.get(self._index)
        indexes = [master if name == "time_s" else self._columns[name] for name in names]
        parts = [self._mdf.iter_get(group=self._index, index=j, samples_only=True)
                 for j in indexes]
        self._done = 0
        while True:
            try:
                with quiet(("asammdf",)):
                    fragment = [next(part)[0] for part in parts]
            except StopIteration:
                return
            except Exception as exc:  # asammdf raises what the blocks give
                raise unreadable(self.path, "MDF", exc) from None
            arrays = {}
            for name, values in zip(names, fragment, strict=True):
                values = np.asarray(values)
                arrays[name] = pa.array(_one_value_per_record(self.path, name, values))
            self._done += len(fragment[0]) if fragment else 0
            yield pa.table(arrays)

    def position(self) -> tuple[float, float]:
        return (float(self._done), float(self.total_rows or 0))

    def close(self) -> None:
        if self._owner:
            self._mdf.close()


def _one_value_per_record(path: Path, name: str, values: np.ndarray) -> np.ndarray:
    """A channel's samples as one value per record (text decoded), or RecordingError."""
    if values.ndim != 1:
        raise RecordingError(f"{path}: MDF channel {name!r} holds arrays of shape "
                             f"{values.shape[1:]} per record, not one value; map another "
                             "channel")
    return np.char.decode(values, "latin-1") if values.dtype.kind == "S" else values


def group_prefixes(names: Sequence[str]) -> list[str]:
    """``"<name>/"`` of each group of a file of several: its acquisition name when that names
    one group only, else its number; ``[""]`` for a file of one group."""
    if len(names) == 1:
        return [""]
    return [f"{name}/" if name and names.count(name) == 1 else f"{i}/"
            for i, name in enumerate(names)]


def read_mdf(path: Path) -> list[Source]:
    """The channel groups of an MDF file that hold records, one stream each."""
    check_exists(path)
    asammdf = require("asammdf", "mdf", "MDF", path)
    failure: RecordingError | None = None
    with quiet(("asammdf",), collect=True):  # a half-read MDF4 object complains when collected
        try:
            mdf = asammdf.MDF(str(path))
            kept = [i for i, g in enumerate(mdf.groups) if g.channel_group.cycles_nr > 0]
        except Exception as exc:  # asammdf raises what the blocks give
            failure = unreadable(path, "MDF", exc, "save the measurement again (CANape, "
                                 "INCA) or check that the logger finished writing it")
    if failure is not None:
        raise failure
    try:
        if not kept:
            raise RecordingError(f"{path}: the MDF file holds no channel group with records; "
                                 "nothing to read")
        names = [str(mdf.groups[i].channel_group.acq_name or "") for i in kept]
        return [MdfGroupSource(path, mdf, i, prefix, owner=k == 0)
                for k, (i, prefix) in enumerate(zip(kept, group_prefixes(names), strict=True))]
    except BaseException:
        mdf.close()
        raise


def sniff(head: bytes) -> bool:
    """True for the MDF identification block."""
    return head.startswith(MAGICS)


FORMAT = Format("mdf", (".mf4", ".mdf"), read_mdf, sniff,
                description="ASAM MDF 3/4, a stream per channel group (asammdf)")
