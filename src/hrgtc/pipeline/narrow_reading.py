"""The drift fit's later passes over a training file read only the columns they take.

``calibrate`` reads each training file whole once (a soak for its plateaus and at-rest
pass, a drift run for its at-rest pass): every column decoded, converted and validated.
The drift fit's window pass reads it again; it takes only the time, the rate, the
thermometer, the housing thermistor and the accelerometer (:data:`NARROW_COLUMNS`), and
decoding the file's other columns (a chamber log, a simulator's truth) is time spent for
nothing (``docs/benchmarks.md``). A later pass reads only those columns
(:func:`~hrgtc.recording.io.iter_chunks`'s ``only``) when it is sure to give the same
chunks: the whole pass's chunks are fingerprinted (per chunk and column: length, first
and last value, sum, as the spike filter's memo knows a piece), and each chunk of the
narrow pass is compared before it is given on. A reader can drop a row because of a
column not read (``--spikes drop``, a slow channel's gap, a duplicated row told from a
duplicated time); then a fingerprint differs, and the pass goes on from that chunk with
every column read (the chunks before it were the same).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from typing import Any

import numpy as np

from hrgtc.drift.variables.registry import DRIFT_VARIABLES
from hrgtc.recording import ReadOptions, Recording
from hrgtc.recording.io import iter_chunks
from hrgtc.recording.motion import ACCEL_COLUMNS
from hrgtc.recording.validated import known_report, validation_key

#: What the drift fit's passes take from a chunk (the at-rest detector's columns, the
#: window means' and every drift variable's; ``temperature_c``: a sensor thermometer).
NARROW_COLUMNS = tuple(dict.fromkeys((
    "time_s", "rate_dph", "input_rate_dph", "freq_hz", "temperature_c", "housing_c",
    *ACCEL_COLUMNS, "orientation",
    *(c for v in DRIFT_VARIABLES for c in v.columns))))


def _fingerprint(chunk: Recording) -> tuple[Any, ...]:
    """The chunk's source, metadata and, per column of :data:`NARROW_COLUMNS` it holds,
    length, first and last value and sum (a NaN equals itself: compared as bytes)."""
    parts: list[Any] = [chunk.source, chunk.metadata]
    for name in NARROW_COLUMNS:
        if name in chunk:
            values = np.asarray(chunk[name])
            head = (values[0], values[-1], np.sum(values)) if len(values) else ()
            parts.append((name, len(values), np.array(head, dtype=np.float64).tobytes()))
    return tuple(parts)


def _same(a: tuple[Any, ...], b: tuple[Any, ...]) -> bool:
    try:
        return bool(a == b)
    except (ValueError, TypeError):  # metadata holding arrays: not known to be the same
        return False


class PassPrints:
    """Each file's whole pass, fingerprinted chunk by chunk, and the narrow passes after it."""

    def __init__(self) -> None:
        self.files: dict[str, list[tuple[Any, ...]]] = {}

    def whole(self, path: Any, chunks: Iterator[Recording]) -> Iterator[Recording]:
        """``chunks`` (a pass over ``path`` with every column), fingerprinted; kept only
        when the pass runs to the file's end."""
        prints = []
        for chunk in chunks:
            prints.append(_fingerprint(chunk))
            yield chunk
        self.files[str(path)] = prints

    def chunks(self, options: ReadOptions, path: Any,
               dropped: dict[str, int]) -> Iterator[Recording]:
        """The chunks of ``options.chunks(path, dropped=dropped)``: narrow when the file
        was read whole and validated with these options before, else whole (and
        fingerprinted)."""
        if not self._narrows(options, path):
            return self.whole(path, options.chunks(path, dropped=dropped))
        return self._narrow(options, path, dropped)

    def _narrows(self, options: ReadOptions, path: Any) -> bool:
        if (str(path) not in self.files or type(options) is not ReadOptions
                or options.axis is not None or options.spikes == "drop"):
            return False
        key = validation_key(path, dataclasses.replace(options, chunk_rows=1))
        return known_report(key) is not None  # its report repeated, as a whole pass does

    def _narrow(self, options: ReadOptions, path: Any,
                dropped: dict[str, int]) -> Iterator[Recording]:
        prints = self.files[str(path)]
        narrow = iter_chunks(path, options, only=NARROW_COLUMNS, dropped=dropped)
        done = 0
        try:
            for chunk in narrow:
                if done >= len(prints) or not _same(_fingerprint(chunk), prints[done]):
                    break
                yield chunk
                done += 1
            else:
                if done == len(prints):
                    return
        finally:
            narrow.close()
        dropped.clear()  # the whole pass counts the spikes again
        whole = options.chunks(path, dropped=dropped)
        for number, chunk in enumerate(whole):
            if number >= done:
                yield chunk
