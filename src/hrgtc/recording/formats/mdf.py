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

Files written by hrgtc (:class:`MdfSink`, ``hrgtc simulate --format mf4``) are MDF 4.10
with one channel group ``recording``: ``time_s`` its master channel (``time``, s), the
other columns float64 channels with their units; the header's comment holds the profile
as its text and the recording's metadata as JSON in the property ``hrgtc`` of its
``common_properties``, which the reader takes as the file's metadata.
"""

from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from collections.abc import Iterator, Mapping, Sequence
from datetime import UTC
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape

import numpy as np
import pyarrow as pa

from hrgtc.core.errors import RecordingError
from hrgtc.recording.axes import axis_names
from hrgtc.recording.formats.base import (
    Format,
    Sink,
    Source,
    column_unit,
    metadata_json,
    metadata_object,
)
from hrgtc.recording.formats.logs import check_exists, output_path, quiet, require, unreadable
from hrgtc.recording.schema import Metadata

#: The identification block of MDF 3 and 4 ("MDF     "; "UnFinMF " for an unfinished one).
MAGICS = (b"MDF     ", b"UnFinMF ")
#: ``sync_type`` of a master channel that is a time.
SYNC_TIME = 1
#: The property of the header's comment that holds hrgtc's metadata (JSON).
METADATA_PROPERTY = "hrgtc"
#: The channel group of the files hrgtc writes.
GROUP = "recording"
#: The MDF version written.
VERSION = "4.10"


class MdfGroupSource(Source):
    """One channel group of an MDF file, read in batches of records."""

    format = "mdf"

    def __init__(self, path: Path, mdf: Any, index: int, prefix: str, owner: bool,
                 written: Mapping[str, Any] | None = None) -> None:
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
        self.metadata: dict[str, Any] = {"extra": extra} if written is None else dict(written)
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
        written = _written_metadata(path, getattr(mdf.header, "comment", ""))
        return [MdfGroupSource(path, mdf, i, prefix, owner=k == 0, written=written)
                for k, (i, prefix) in enumerate(zip(kept, group_prefixes(names), strict=True))]
    except BaseException:
        mdf.close()
        raise


def _written_metadata(path: Path, comment: str) -> dict[str, Any] | None:
    """The metadata hrgtc wrote in the header's comment; None in other files."""
    if not comment or METADATA_PROPERTY not in comment:
        return None
    try:
        found = ElementTree.fromstring(comment).find(
            f"common_properties/e[@name='{METADATA_PROPERTY}']")
    except ElementTree.ParseError:
        return None  # a comment of plain text that mentions hrgtc
    if found is None:
        return None
    return metadata_object(found.text or "",
                           f"{path}: the header comment's property {METADATA_PROPERTY!r}")


def header_comment(metadata: Metadata) -> str:
    """The MDF4 header comment (``HDcomment`` XML) of a recording: its profile as the text,
    its metadata as JSON in the property ``hrgtc``."""
    return (f"<HDcomment><TX>{escape(metadata.profile or 'hrgtc recording')}</TX>"
            f"<common_properties><e name=\"{METADATA_PROPERTY}\" type=\"string\">"
            f"{escape(metadata_json(metadata))}</e></common_properties></HDcomment>")


class MdfSink(Sink):
    """Writes a recording as an MDF 4.10 file (asammdf): one channel group, its master the
    ``time_s`` column (``i / sample rate`` without one), the other columns float64 channels.

    asammdf appends each chunk's records to the group (``MDF.extend``) in a temporary file
    of its own, and :meth:`close` saves the measurement: the rows are never in memory
    together.
    """

    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        super().__init__(path, metadata, names)
        self._asammdf = require("asammdf", "mdf", "MDF", output_path(path), "writing")
        self._rate_hz = float(metadata.sample_rate_hz)
        axes = axis_names(names)
        self._channels = [n for n in names if n != "time_s"]
        self._units = {n: column_unit(n, axes) or "" for n in self._channels}
        self._mdf = self._asammdf.MDF(version=VERSION)
        self._index: int | None = None
        self._rows = 0
        self.set_metadata(metadata)

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        rows = len(columns[self.names[0]])
        time = (np.asarray(columns["time_s"], dtype=np.float64) if "time_s" in columns else
                np.arange(self._rows, self._rows + rows, dtype=np.float64) / self._rate_hz)
        with quiet(("asammdf",)):
            if self._index is None:
                signals = [self._asammdf.Signal(np.asarray(columns[n], dtype=np.float64), time,
                                                name=n, unit=self._units[n])
                           for n in self._channels]
                self._index = self._mdf.append(signals, acq_name=GROUP,
                                               comment="hrgtc recording")
            else:
                self._mdf.extend(self._index, [(time, None)] + [
                    (np.asarray(columns[n], dtype=np.float64), None) for n in self._channels])
        self._rows += rows

    def set_metadata(self, metadata: Metadata) -> None:
        self._mdf.header.comment = header_comment(metadata)
        origin = metadata.extra.get("time_origin")
        if isinstance(origin, str):
            try:
                start = np.datetime64(origin, "us").astype(object)
            except ValueError:
                return
            self._mdf.header.start_time = start.replace(tzinfo=UTC)

    def close(self) -> None:
        if self._index is None:
            self.write({n: np.zeros(0) for n in self.names})
        try:
            with open(self.path, "wb") as handle, quiet(("asammdf",)):
                self._mdf.save(handle, overwrite=True)
        finally:
            self._mdf.close()

    def abort(self) -> None:
        self._mdf.close()


def sniff(head: bytes) -> bool:
    """True for the MDF identification block."""
    return head.startswith(MAGICS)


FORMAT = Format("mdf", (".mf4", ".mdf"), read_mdf, sniff, MdfSink, output_name="mf4",
                description="ASAM MDF 3/4, a stream per channel group (asammdf)")
