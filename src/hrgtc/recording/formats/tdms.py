"""NI TDMS files (``.tdms``, LabVIEW and DAQmx data logging), read with npTDMS
(``pip install 'hrgtc[tdms]'``).

A TDMS file holds groups of channels. Each group is one stream; its channels are its
columns, named as in the file for a file of one group and ``<group>/<channel>`` for a
file of several, whose groups are then read when the column mapping names one of their
channels and put on one time axis by :mod:`hrgtc.recording.align` (a LabVIEW log of the
full-rate data beside its decimated levels, a fast gyro group beside a slow temperature
group). Conventions handled:

* **waveform timing**: a group whose channels carry ``wf_increment`` (the sample period,
  s) has ``time_s = wf_start_offset + i * wf_increment`` plus its ``wf_start_time`` after
  the earliest ``wf_start_time`` of the file, which is kept as ``extra["time_origin"]``
  (LabVIEW's zero time, 1904-01-01, marks a relative time: no origin); the sample rate
  is ``1 / wf_increment``. A group without waveform timing has no ``time_s``: map its
  time channel (``--col time_s=Time``, with ``--time-unit``), which a timestamp channel
  needs no unit for;
* **DAQmx raw data and NI scaling**: channels stored as raw counts with ``NI_Scale``
  properties are read scaled (npTDMS applies the scales), so values are in the
  channel's ``unit_string`` (kept in ``extra["tdms_units"]``);
* a file of one group holding a channel named ``time_s`` is read on that channel (the
  times as logged), its waveform timing giving the sample rate;
* large files are read in batches (``TdmsFile.open``), never whole.

Files written by hrgtc (:class:`TdmsSink`, ``hrgtc simulate --format tdms``) hold one
group ``recording`` of float64 channels, each with LabVIEW's waveform properties
(``wf_start_time``, ``wf_start_offset``, ``wf_increment``, ``wf_samples``) and its unit
(``unit_string``), and the recording's metadata as JSON in the file property ``hrgtc``
(as Parquet's), which the reader takes as the file's metadata.
"""

from __future__ import annotations

import sys
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
    metadata_json,
    metadata_object,
)
from hrgtc.recording.formats.logs import check_exists, output_path, quiet, require, unreadable
from hrgtc.recording.schema import Metadata

#: The lead-in tag of a TDMS segment ("TDSm"; "TDSh" in the .tdms_index file).
TAG = b"TDSm"
#: LabVIEW's zero time: a ``wf_start_time`` there is a relative time axis.
LABVIEW_EPOCH = np.datetime64("1904-01-01T00:00:00", "us")
#: The file property of hrgtc's metadata (JSON) in the files it writes.
METADATA_PROPERTY = "hrgtc"
#: The group of the files hrgtc writes.
GROUP = "recording"


def _timing(channel: Any) -> tuple[float, float, np.datetime64 | None] | None:
    """``(wf_increment, wf_start_offset, wf_start_time or None)`` of a waveform channel."""
    props = channel.properties
    increment = props.get("wf_increment")
    if increment is None or not float(increment) > 0:
        return None
    start = props.get("wf_start_time")
    start = np.datetime64(start, "us") if start is not None else None
    if start is not None and start == LABVIEW_EPOCH:
        start = None
    return float(increment), float(props.get("wf_start_offset", 0.0) or 0.0), start


class TdmsGroupSource(Source):
    """One group of a TDMS file, read in batches.

    Parameters
    ----------
    path
        The file.
    handle
        The open ``nptdms.TdmsFile`` (closed by the first stream of the file).
    group
        The group.
    prefix
        ``"<group>/"`` in a file of several groups, else ``""``.
    origin
        The file's earliest absolute ``wf_start_time`` (None: times are relative).
    """

    format = "tdms"

    def __init__(self, path: Path, handle: Any, group: Any, prefix: str,
                 origin: np.datetime64 | None, owner: bool,
                 written: Mapping[str, Any] | None = None) -> None:
        super().__init__(path)
        self._file, self._owner = handle, owner
        channels = list(group.channels())
        lengths = {c.name: len(c) for c in channels}
        if len(set(lengths.values())) > 1:
            raise RecordingError(
                f"{path}: the channels of the TDMS group {group.name!r} have different lengths "
                f"{lengths}; hrgtc reads a group as one table: log the channels of each rate "
                "in a group of their own")
        self._channels = {f"{prefix}{c.name}": c for c in channels}
        self.total_rows = next(iter(lengths.values()), 0)
        self.stream = group.name
        self.on_request = bool(prefix)
        timings = {_timing(c) for c in channels}
        self._time: tuple[float, float] | None = None
        units = {name: str(c.properties["unit_string"]) for name, c in self._channels.items()
                 if c.properties.get("unit_string")}
        extra: dict[str, Any] = {"tdms_group": group.name}
        if units:
            extra["tdms_units"] = units
        self.metadata: dict[str, Any] = {"extra": extra}
        if len(timings) == 1 and None not in timings:
            increment, offset, start = next(iter(timings))
            shift = 0.0 if start is None or origin is None else float(
                (start - origin) / np.timedelta64(1, "us")) * 1e-6
            self._time = (increment, offset + shift)
            self.metadata["sample_rate_hz"] = 1.0 / increment
            if origin is not None:
                extra["time_origin"] = str(origin)
        if not prefix and "time_s" in self._channels:
            self._time = None  # the times as logged, not rebuilt from the waveform timing
        if written is not None:  # a file hrgtc wrote: its metadata as it was written
            self.metadata = dict(written)
        self.names = (["time_s"] if self._time else []) + list(self._channels)
        self._done = 0

    def kinds(self) -> dict[str, str]:
        kinds = {"time_s": "numeric"} if self._time else {}
        for name, channel in self._channels.items():
            dtype = np.dtype(channel.dtype) if channel.dtype is not None else np.dtype("O")
            kinds[name] = ("numeric" if dtype.kind in "fiub" else "timestamp"
                           if dtype.kind == "M" else "string" if dtype.kind in "OSU" else "other")
        return kinds

    def _table(self, names: Sequence[str], start: int, stop: int) -> pa.Table:
        arrays = {}
        for name in names:
            if name == "time_s" and self._time:
                increment, offset = self._time
                arrays[name] = pa.array(offset + increment * np.arange(start, stop,
                                                                        dtype=np.float64))
                continue
            failure: Exception | None = None
            with quiet(_loggers(sys.modules["nptdms"])) as said:
                try:
                    values = self._channels[name].read_data(start, stop - start)
                except Exception as exc:  # npTDMS raises what the bytes give
                    failure = exc
            if failure is not None or said:
                raise unreadable(self.path, "TDMS", failure or ValueError(said[0]))
            values = np.asarray(values)
            if values.dtype.kind == "M":
                values = values.astype("datetime64[ns]")
            arrays[name] = pa.array(values if values.dtype.kind != "O" else list(values))
        return pa.table(arrays)

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        self._done = int(self.total_rows or 0)
        return self._table(names, 0, self._done)

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        total = int(self.total_rows or 0)
        for start in range(0, total, max(int(rows), 1)):
            self._done = min(start + rows, total)
            yield self._table(names, start, self._done)

    def position(self) -> tuple[float, float]:
        return (float(self._done), float(self.total_rows or 0))

    def close(self) -> None:
        if self._owner:
            self._file.close()


def _loggers(nptdms: Any) -> list[str]:
    """npTDMS's loggers (each with its own console handler)."""
    manager = getattr(getattr(nptdms, "log", None), "log_manager", None)
    return [*getattr(manager, "loggers", {}), "nptdms"]


def read_tdms(path: Path) -> list[Source]:
    """The groups of a TDMS file that hold samples, one stream each."""
    check_exists(path)
    nptdms = require("nptdms", "tdms", "TDMS", path)
    fix = "copy the .tdms (and its .tdms_index) from the logging PC again"
    failure: Exception | None = None
    with quiet(_loggers(nptdms)) as said:
        try:
            handle = nptdms.TdmsFile.open(str(path))
            groups = [g for g in handle.groups() if g.channels() and len(g.channels()[0]) > 0]
        except Exception as exc:  # npTDMS raises what the bytes give
            failure = exc
    if failure is None and said:  # npTDMS reads a cut file up to the cut, with a warning
        handle.close()
        failure = ValueError(f"npTDMS: {said[0]}")
    if failure is not None:
        raise unreadable(path, "TDMS", failure, fix)
    try:
        if not groups:
            raise RecordingError(f"{path}: the TDMS file holds no channel with samples; "
                                 "nothing to read")
        written = _written_metadata(path, handle)
        starts = [t[2] for g in groups for t in map(_timing, g.channels())
                  if t is not None and t[2] is not None]
        origin = min(starts) if starts else None
        prefix = len(groups) > 1
        return [TdmsGroupSource(path, handle, g, f"{g.name}/" if prefix else "", origin,
                                owner=i == 0, written=written) for i, g in enumerate(groups)]
    except BaseException:
        handle.close()
        raise


def _written_metadata(path: Path, handle: Any) -> dict[str, Any] | None:
    """The metadata hrgtc wrote in the file property ``hrgtc``; None in other files."""
    raw = handle.properties.get(METADATA_PROPERTY)
    if raw is None:
        return None
    return metadata_object(str(raw), f"{path}: the file property {METADATA_PROPERTY!r}")


class TdmsSink(Sink):
    """Writes a recording as a TDMS file LabVIEW reads: one group ``recording`` of float64
    waveform channels, a segment per chunk (never the whole table in memory).

    Each channel carries LabVIEW's waveform timing: ``wf_increment`` = 1 / the sample
    rate, ``wf_start_offset`` = the first ``time_s`` (0 without one), ``wf_start_time`` =
    ``extra["time_origin"]`` where the metadata has one, else LabVIEW's zero time
    (1904-01-01: a relative time axis), ``wf_samples`` the samples of the first write, and
    ``unit_string`` its unit. The metadata is the file property ``hrgtc`` (JSON); a
    :meth:`set_metadata` appends a segment of the file object alone, whose property
    replaces the first (TDMS readers take a property's last value).
    """

    def __init__(self, path: Path, metadata: Metadata, names: Sequence[str]) -> None:
        super().__init__(path, metadata, names)
        self._nptdms = require("nptdms", "tdms", "TDMS", output_path(path), "writing")
        self._metadata = metadata_json(metadata)
        self._increment = 1.0 / float(metadata.sample_rate_hz)
        origin = metadata.extra.get("time_origin") if isinstance(metadata.extra, dict) else None
        try:
            self._start = np.datetime64(origin, "us") if origin else LABVIEW_EPOCH
        except ValueError:
            self._start = LABVIEW_EPOCH
        self._units = {n: column_unit(n, axis_names(names)) for n in names}
        self._writer = self._nptdms.TdmsWriter(str(path))
        self._writer.open()
        self._first = True

    def _objects(self, columns: Mapping[str, np.ndarray]) -> list[Any]:
        nptdms = self._nptdms
        if not self._first:
            return [nptdms.ChannelObject(GROUP, n, columns[n]) for n in self.names]
        self._first = False
        rows = len(columns[self.names[0]])
        offset = float(columns["time_s"][0]) if "time_s" in columns and rows else 0.0
        wave = {"wf_start_time": self._start, "wf_start_offset": offset,
                "wf_increment": self._increment, "wf_samples": np.int32(rows),
                "wf_xname": "Time", "wf_xunit_string": "s"}
        root = nptdms.RootObject(properties={"name": self.path.stem,
                                             METADATA_PROPERTY: self._metadata})
        channels = [nptdms.ChannelObject(GROUP, n, columns[n], properties={
            **wave, **({"unit_string": self._units[n]} if self._units[n] else {})})
            for n in self.names]
        return [root, nptdms.GroupObject(GROUP), *channels]

    def write(self, columns: Mapping[str, np.ndarray]) -> None:
        self._writer.write_segment(self._objects(columns))

    def set_metadata(self, metadata: Metadata) -> None:
        self._metadata = metadata_json(metadata)
        if not self._first:
            self._writer.write_segment([self._nptdms.RootObject(
                properties={METADATA_PROPERTY: self._metadata})])

    def close(self) -> None:
        if self._first:  # no rows: the channels, empty, and the metadata
            self.write({n: np.zeros(0) for n in self.names})
        self._writer.close()

    def abort(self) -> None:
        self._writer.close()


def sniff(head: bytes) -> bool:
    """True for a TDMS segment's lead-in."""
    return head.startswith(TAG)


FORMAT = Format("tdms", (".tdms",), read_tdms, sniff, TdmsSink,
                description="NI TDMS (LabVIEW, DAQmx), a stream per group (npTDMS)")
