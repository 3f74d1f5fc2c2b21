"""One time axis from several streams: the alignment step of reading.

A reader returns one or more streams (:mod:`hrgtc.recording.formats`), each a table on
its own time axis: a logger that writes its gyro at 10 Hz and its temperatures at 1 Hz
into separate tables gives two. :func:`align` joins them onto the time axis of the
stream with the most rows, by the rule of the slow channels of one table
(:mod:`hrgtc.recording.resample`), as ``--slow-channels`` and ``--hold-max-s`` say:

``hold`` (default)
    each row takes a channel's last value at or before its time;
``interpolate``
    linear in time between the values on either side (after the last one, held);
``error``
    streams on different time axes are refused.

A value is used for at most ``--hold-max-s`` seconds (default
:data:`~hrgtc.recording.resample.DEFAULT_MAX_AGE_PERIODS` periods of the channel); a
row farther than that from a value of a channel, or before its first value, is
dropped as a gap in the channel (counted, reported by a
:class:`~hrgtc.core.errors.SlowChannelWarning` like the slow channels of one table). So two
streams at 10 Hz and 1 Hz give the same recording as one 10 Hz table whose 1 Hz
channel is empty between its values.

One stream is returned as it is: the single-stream case costs nothing. The fastest
stream is read in chunks as usual; the others (the slow ones) are read whole when the
first rows are asked for.

A log of many streams (the topics of a ULog, the messages of a DataFlash log, the groups
of a TDMS or MDF4 file) marks them *on request* (:attr:`Source.on_request`): their
columns are read only when the column mapping names them, and the time axis is that of
the stream with the most rows among the streams whose columns are asked for (the gyro's
topic when its rate and temperature are mapped), not of the log's busiest topic.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np
import pyarrow as pa

from hrgtc.core.errors import RecordingError
from hrgtc.recording.formats.base import ON_REQUEST, Source
from hrgtc.recording.resample import (
    DEFAULT_MAX_AGE_PERIODS,
    ChannelFill,
    SlowChannels,
    channel_period,
    check_slow_mode,
    resample_channel,
)

__all__ = ["AlignedSource", "align", "warn_alignment"]


def align(streams: Sequence[Source], mode: str = "hold",
          max_age_s: float | None = None) -> Source:
    """One stream from the streams of a file (the only one as it is).

    Parameters
    ----------
    streams
        The streams of one file (:meth:`hrgtc.recording.formats.Format.open`).
    mode
        ``"hold"``, ``"interpolate"`` or ``"error"`` (``--slow-channels``).
    max_age_s
        Longest time a value of a slower stream is used for; None:
        :data:`~hrgtc.recording.resample.DEFAULT_MAX_AGE_PERIODS` periods of each
        channel (``--hold-max-s``). [s]

    Raises
    ------
    RecordingError
        ``mode="error"`` and several streams, a column in two streams, or a time axis
        that is not numbers.
    """
    check_slow_mode(mode)
    if len(streams) == 1:
        return streams[0]
    return AlignedSource(streams, mode, max_age_s)


def warn_alignment(source: Source) -> None:
    """Report what the alignment of ``source`` did (nothing for a single stream)."""
    if isinstance(source, AlignedSource):
        source.slow.warn()


class AlignedSource(Source):
    """The streams of a file as one, on the time axis of the stream with the most rows.

    Reads like any :class:`~hrgtc.recording.formats.Source`; the columns of the other
    streams are resampled onto each table read, the rows too far from their values
    dropped. :attr:`slow` holds what was done (a
    :class:`~hrgtc.recording.resample.SlowChannels`).
    """

    def __init__(self, streams: Sequence[Source], mode: str = "hold",
                 max_age_s: float | None = None) -> None:
        base = max(streams, key=lambda s: s.count_rows())  # the first of equal lengths
        super().__init__(base.path)
        self.format = base.format
        self.streams = list(streams)
        self.base = base
        self.others = [s for s in streams if s is not base]
        label = {id(s): s.stream or f"stream {i + 1}" for i, s in enumerate(streams)}
        self._label = label
        if mode == "error" and not any(s.on_request for s in streams):
            self.close()
            self._refuse(streams)
        self.owner: dict[str, Source] = {name: base for name in base.names}
        for other in self.others:
            for name in other.names:
                if name == other.time_column:
                    continue
                if name in self.owner:
                    first = self.owner[name]
                    self.close()
                    raise RecordingError(
                        f"{base.path}: column {name!r} is in the streams {label[id(first)]} "
                        f"and {label[id(other)]}; hrgtc cannot tell which one is meant: "
                        "rename one of them")
                self.owner[name] = other
        self.names = list(self.owner)
        self.skipped = {k: v for s in streams for k, v in getattr(s, "skipped", {}).items()}
        self._mode, self._max_age_s = mode, max_age_s
        self._use_base(base)
        self._offset = 0

    def _use_base(self, base: Source) -> None:
        """Put the others on the time axis of ``base`` (the one stream whose time is kept)."""
        self.owner.pop(self.base.time_column, None)
        self.owner[base.time_column] = base
        self.base, self.others = base, [s for s in self.streams if s is not base]
        self.format = base.format
        self.metadata = dict(base.metadata)
        self.total_rows = base.total_rows
        self.stream, self.time_column, self.time_unit_s = "", base.time_column, base.time_unit_s
        self.slow = SlowChannels(self._mode, self._max_age_s, str(base.path))
        self._samples: dict[str, tuple[np.ndarray, np.ndarray]] = {}

    def _refuse(self, streams: Sequence[Source]) -> None:
        raise RecordingError(
            f"{self.path}: the file holds {len(streams)} streams on their own time axes "
            f"({', '.join(self._label[id(s)] for s in streams)}) and --slow-channels is "
            "'error'; pass --slow-channels hold or interpolate to put them on one time axis")

    def _choose_base(self, names: Sequence[str]) -> None:
        """With streams on request: the base is the stream of most rows among those whose
        columns are asked for (the first of equal lengths)."""
        if not any(s.on_request for s in self.streams):
            return
        asked = {id(self.owner[n]) for n in names if n in self.owner and n != self.time_column}
        candidates = [s for s in self.streams if id(s) in asked]
        if not candidates and all(s.on_request for s in self.streams):
            self.close()
            raise RecordingError(self._nothing_named())
        if candidates:
            base = max(candidates, key=lambda s: s.count_rows())
            if base is not self.base:
                self._use_base(base)

    def _nothing_named(self) -> str:
        """The refusal of a read that names no column of a log of streams on request."""
        def listed(stream: Source) -> str:
            columns = [n for n in stream.names if n != stream.time_column]
            shown = ", ".join(columns[:8]) + (", ..." if len(columns) > 8 else "")
            return f"{stream.stream} ({stream.count_rows()} rows: {shown})"

        sensors = [s for s in self.streams
                   if any(k in s.stream.lower() for k in ("gyr", "imu", "temp", "baro"))]
        others = [s.stream for s in self.streams if s not in sensors]
        shown = [listed(s) for s in sensors[:8]]
        if others:
            shown.append(f"{f'and {len(others)} more: ' if shown else ''}"
                         f"{', '.join(others[:40])}{', ...' if len(others) > 40 else ''}")
        names = [n for s in [*sensors, *self.streams] for n in s.names if n != s.time_column]
        example = next((n for n in names if n.lower().endswith(("gyrx", ".x", "/x",
                                                                  "gyro_rad[0]"))), names[0])
        return (f"{self.path}: the file holds {len(self.streams)} streams on their own time "
                "axes, read when the column mapping names their columns, and none is named; "
                f"map yours with --col, e.g. --col rate_dph={example}. "
                f"Streams: {'; '.join(shown)}")

    def kinds(self) -> dict[str, str]:
        kinds: dict[str, str] = {}
        for stream in self.streams:
            stream_kinds = stream.kinds()
            kinds.update({n: (ON_REQUEST if stream.on_request and k == "numeric"
                              and n != stream.time_column else k)
                          for n, k in stream_kinds.items() if self.owner.get(n) is stream})
        return kinds

    # -- the slower streams, read whole --------------------------------------------------
    def _load(self, names: Sequence[str]) -> None:
        """Read the columns ``names`` of the other streams (once each) with their times [s]."""
        wanted: dict[int, list[str]] = {}
        for name in names:
            owner = self.owner[name]
            if owner is not self.base and name not in self._samples:
                wanted.setdefault(id(owner), []).append(name)
        for other in self.others:
            columns = wanted.get(id(other))
            if not columns:
                continue
            table = other.read([other.time_column, *columns], set())
            time_s = self._seconds(other, table.column(other.time_column))
            for name in columns:
                values = _numbers(table.column(name), other, name)
                keep = np.isfinite(values) & np.isfinite(time_s)
                sample_time, sample_values = time_s[keep], values[keep]
                if sample_time.size > 1 and np.any(np.diff(sample_time) < 0):
                    order = np.argsort(sample_time, kind="stable")
                    sample_time, sample_values = sample_time[order], sample_values[order]
                self._samples[name] = (sample_time, sample_values)
                period = channel_period(sample_time)
                if self._max_age_s is None and not period > 0:
                    where = f" of the stream {other.stream!r}" if other.stream else ""
                    raise RecordingError(
                        f"{other.path}: column {name!r}{where} has {sample_time.size} value(s) "
                        "at distinct times fewer than 2, so its period, and how long a value "
                        "may be held, is unknown; give --hold-max-s SECONDS")
                age = (self._max_age_s if self._max_age_s is not None
                       else DEFAULT_MAX_AGE_PERIODS * period)
                self.slow.channels[name] = ChannelFill(name, period, float(age))

    def _seconds(self, stream: Source, column: pa.ChunkedArray) -> np.ndarray:
        values = _numbers(column, stream, stream.time_column)
        return values * stream.time_unit_s if stream.time_unit_s != 1.0 else values

    def _joined(self, table: pa.Table, names: Sequence[str]) -> pa.Table:
        """The base stream's ``table`` with the other streams' columns, too old rows dropped."""
        n = table.num_rows
        slow = [name for name in names if self.owner[name] is not self.base]
        if not slow:
            self._offset += n
            return table.select(list(names))
        if self._mode == "error":  # streams on request, columns of several asked for
            self._refuse([self.base, *dict.fromkeys(self.owner[n] for n in slow)])
        self._load(slow)
        time_s = self._seconds(self.base, table.column(self.base.time_column))
        keep = np.ones(n, dtype=bool)
        filled: dict[str, np.ndarray] = {}
        for name in slow:
            state = self.slow.channels[name]
            sample_time, sample_values = self._samples[name]
            values, too_old, exact = resample_channel(time_s, sample_time, sample_values,
                                               self.slow.mode, state.max_age_s)
            filled[name] = values
            dropped = int(np.count_nonzero(too_old))
            if dropped and state.first_dropped_row is None:
                state.first_dropped_row = self._offset + int(np.argmax(too_old))
            state.dropped += dropped
            state.filled += n - dropped - exact
            keep &= ~too_old
        self._offset += n
        arrays = []
        for name in names:
            column = (pa.array(filled[name]) if name in filled
                      else table.column(name).combine_chunks())
            arrays.append(column if keep.all() else column.filter(pa.array(keep)))
        return pa.Table.from_arrays(arrays, names=list(names))

    def _base_names(self, names: Sequence[str]) -> list[str]:
        own = [n for n in names if self.owner[n] is self.base]
        return list(dict.fromkeys([*own, self.base.time_column]))

    def read(self, names: Sequence[str], as_text: set[str]) -> pa.Table:
        self._offset = 0
        self._choose_base(names)
        return self._joined(self.base.read(self._base_names(names), as_text), names)

    def iter_tables(self, names: Sequence[str], as_text: set[str], rows: int) -> Iterator[pa.Table]:
        self._offset = 0
        self._choose_base(names)
        for table in self.base.iter_tables(self._base_names(names), as_text, rows):
            yield self._joined(table, names)

    def count_rows(self) -> int:
        return self.base.count_rows()

    def position(self) -> tuple[float, float]:
        return self.base.position()

    def close(self) -> None:
        for stream in self.streams:
            stream.close()


def _numbers(column: Any, stream: Source, name: str) -> np.ndarray:
    """A column of a stream as float64, or RecordingError naming it."""
    try:
        return np.asarray(column.cast(pa.float64()).to_numpy(zero_copy_only=False),
                          dtype=np.float64)
    except (pa.ArrowInvalid, pa.ArrowNotImplementedError, pa.ArrowTypeError):
        where = f" of the stream {stream.stream!r}" if stream.stream else ""
        raise RecordingError(
            f"{stream.path}: column {name!r}{where} holds {column.type} values, not numbers; "
            "streams on their own time axes are aligned by numeric times and values") from None
