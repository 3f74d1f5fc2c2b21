"""``compensate``'s at-rest flag: one pass of the motion detector's columns first.

``compensate`` never drops a sample; it flags. A sample not at rest (handling,
turning, shaking, clipping; :mod:`hrgtc.recording.motion`) gets ``at_rest`` 0 in the
output (``at_rest_x``, ``at_rest_y``, ... per axis of a multi-axis file; 1 at rest)
and is counted in the accounting (``motion``, flagged).

Why a pre-pass and not a streamed flag with a look-ahead buffer: the detector is not
local. Its level and variance tests compare a sample with the at-rest noise of the
*whole* recording (the robust σ of every first difference) and with a running median
of block medians centred on it; a streamed flag with a bounded delay would have to
estimate that noise from the samples seen so far, and its verdicts would differ from
those of calibration and evaluation on the same file. So, as ``evaluate`` does
(:func:`hrgtc.evaluation.evaluate`), one pass keeps only the
detector's columns (time, rate, known input rate, accelerometer axes),
:class:`hrgtc.drift.rest.RestPass` (:func:`~hrgtc.drift.rest.run_rest` a chunk at a
time) marks the samples, and the compensating pass then writes the flags: equal to
``run_rest``'s mask by construction.

The cost (issue 20, ``docs/benchmarks.md``): a second reading of the detector's
columns, without their validation (the compensating pass validates every sample; if the unvalidated
pass fails, the file is read again validated, so a bad file gets the validator's
error), and the detector's columns in memory, once, while it runs (time and rate: 16
bytes a sample and axis; a 3-day 1 Hz file: 260,000 rows, 4 MB; dropped before the
compensating pass, which holds only the flags: 150 MB less at 10 M rows). The pass
reads the next chunk on a thread while it gathers this one; the detector's loops are C
(:mod:`hrgtc.recording._motion_kernel`). ``--motion keep`` skips the pass and writes
no flag; ``--motion error`` stops at the first moving sample, naming it.

The pass reads only the detector's columns (:data:`DETECTOR_COLUMNS`, ``iter_chunks(...,
only=)``), and the spike filter's flags, which change no row, are not computed in it.
Reading fewer columns can give other rows: the reader drops a row because of a column
the pass does not read (a gap of a slow channel, ``--spikes drop``, a duplicated row
told from a duplicated time by its other values). So the flags are never trusted to
line up: :meth:`RestFlags.take` compares a digest of the bits of each detector column over
each block of rows the detector's pass read (its chunks; 64 bits, computed in C,
:func:`hrgtc.recording._motion_kernel.digest`) with the same digest of the rows the
compensating pass reads, however it cuts them, and the row counts at the end; equal
columns give the detector the same input, hence the same flags. One changed value
always changes the digest; more (a shifted row) escape it with a chance of about 2^-64
per block. A difference raises :class:`FlagsMisaligned`, on which
:func:`~hrgtc.compensate.file_pass.compensate_file` discards its output and starts again
with the pass reading every column (a slower, correct run, never misaligned flags).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.drift.rest import RestPass
from hrgtc.recording import Recording, axis_view
from hrgtc.recording import _motion_kernel as kernel
from hrgtc.recording.motion import ACCEL_COLUMNS

__all__ = ["AT_REST_COLUMN", "DETECTOR_COLUMNS", "FlagsMisaligned", "RestFlags", "rest_columns"]

#: The flag column of a single-axis output (``at_rest_<axis>`` per axis otherwise).
AT_REST_COLUMN = "at_rest"
#: The columns the detector reads (:func:`hrgtc.drift.rest.run_rest`), without their axis.
DETECTOR_COLUMNS = ("time_s", "rate_dph", "input_rate_dph", *ACCEL_COLUMNS)


class FlagsMisaligned(InputError):
    """The rows of the detector's pass are not those of the compensating pass."""


def rest_columns(axes: Sequence[str]) -> tuple[str, ...]:
    """The flag columns for a model's axes (``""``: the single axis)."""
    return tuple(AT_REST_COLUMN if not axis else f"{AT_REST_COLUMN}_{axis}" for axis in axes)


class RestFlags:
    """The at-rest flags of every axis of a file, found in one pass, handed out by chunk.

    Parameters
    ----------
    chunks
        The file's chunks, read with the options of the compensating pass, unvalidated,
        perhaps only the detector's columns (:meth:`take` checks that the rows are the
        compensating pass's).
    axes
        The model's axes (``[""]`` for a single-axis model).
    policy
        ``"exclude"`` or ``"error"`` (:data:`hrgtc.recording.motion.MOTION_POLICIES`;
        ``"keep"`` needs no flags).
    name
        The file's name, for the errors.
    validated
        The same chunks, validated: read if reading or marking ``chunks`` fails.
    rows
        The file's rows if known (the detector's buffers are sized once).
    """

    def __init__(self, chunks: Iterable[Recording], axes: Sequence[str], policy: str,
                 name: str, validated: Callable[[], Iterable[Recording]] | None = None,
                 rows: int | None = None) -> None:
        self.axes = tuple(axes)
        self.columns = rest_columns(self.axes)
        self._policy, self._name, self._rows = policy, name, rows
        self._names: dict[str, set[str]] = {}  # the detector's columns by axis
        self._digests = _RowDigests()
        try:
            self.still = self._find(chunks)
        except CalibrationError:  # --motion error: a moving sample
            raise
        except Exception:
            if validated is None:
                raise
            # read unvalidated: a bad file raises what the validated reading raises
            self.still = self._find(validated())
        self.rows = 0  # rows handed out so far

    def _find(self, chunks: Iterable[Recording]) -> dict[str, np.ndarray]:
        passes = {axis: RestPass(self._policy, name=self._name, rows=self._rows,
                                 in_place=True) for axis in self.axes}
        self._digests = digests = _RowDigests()  # for take()
        for chunk in _read_ahead(chunks):
            digests.stops.append((digests.stops[-1] if digests.stops else 0) + len(chunk))
            for i, (axis, rest) in enumerate(passes.items()):
                view = axis_view(chunk, axis) if axis else chunk
                columns = {k: view[k] for k in DETECTOR_COLUMNS if k in view}
                for name, values in columns.items():
                    if name != "time_s" or i == 0:
                        digests.add((axis, name), values)
                self._names[axis] = set(columns)
                rest.partial_fit(Recording(columns, view.metadata, view.source))
        return {axis: rest.finish().keep for axis, rest in passes.items()}

    @property
    def n_not_at_rest(self) -> int:
        """Samples not at rest on any axis (the accounting's ``motion``, flagged)."""
        still = np.logical_and.reduce([self.still[a] for a in self.axes])
        return int(still.size - np.count_nonzero(still))

    def take(self, chunk: Recording) -> dict[str, np.ndarray]:
        """The flags (1.0 at rest, 0.0 not) of the next chunk's samples, by column.

        Raises :class:`FlagsMisaligned` unless the chunk's detector columns are, bit for
        bit (by their digests), those the detector saw at the same rows.
        """
        start, stop = self.rows, self.rows + len(chunk)
        flags = {}
        for i, (axis, column) in enumerate(zip(self.axes, self.columns, strict=True)):
            still, seen = self.still[axis], self._names.get(axis, set())
            view = axis_view(chunk, axis) if axis else chunk
            if stop > still.size:
                self._misaligned(f"{stop} rows to compensate but {still.size} to the detector")
            theirs = {k for k in DETECTOR_COLUMNS if k in view}
            if theirs != seen:
                self._misaligned(f"columns {sorted(theirs)} to compensate but {sorted(seen)} "
                                 "to the detector")
            for name in DETECTOR_COLUMNS:
                if name in theirs and (name != "time_s" or i == 0):
                    problem = self._digests.check((axis, name), view[name], start)
                    if problem:
                        self._misaligned(problem)
            flags[column] = still[start:stop].astype(np.float64)
        self.rows = stop
        return flags

    def finish(self) -> None:
        """Check that every row the detector saw was compensated (after the last
        :meth:`take`)."""
        size = self.still[self.axes[0]].size
        if self.rows != size:
            self._misaligned(f"{self.rows} rows compensated but {size} to the detector")

    def _misaligned(self, what: str) -> None:
        raise FlagsMisaligned(
            f"{self._name}: the motion detector's pass and the compensating pass read other "
            f"rows ({what}); the at_rest flags would not line up, none are written. Was the "
            "file changed while it was read?")


def _read_ahead(chunks: Iterable[Recording]) -> Iterator[Recording]:
    """``chunks``, the next one read on a thread while this one's columns are gathered
    (pyarrow and h5py release the GIL), as the compensating pass reads ahead."""
    iterator = iter(chunks)
    with ThreadPoolExecutor(max_workers=1) as reading:
        ahead = reading.submit(next, iterator, None)
        while (chunk := ahead.result()) is not None:
            ahead = reading.submit(next, iterator, None)
            yield chunk


class _RowDigests:
    """A digest of each detector column over each block of rows the detector's pass read
    (``stops``: the end of each block, its chunks), and the same digests of the rows the
    compensating pass reads, however it cuts them (a digest fed in pieces is the digest of
    the whole)."""

    def __init__(self) -> None:
        self.stops: list[int] = []
        self._seen: dict[tuple[str, str], list[int]] = {}  # (axis, column) -> per block
        self._fed: dict[tuple[str, str], tuple[int, np.ndarray]] = {}  # next block, state

    def add(self, key: tuple[str, str], values: np.ndarray) -> None:
        """The detector's pass: the digest of the column ``key`` over the next block."""
        state = kernel.digest_start()
        kernel.digest_update(state, np.ascontiguousarray(values, dtype=np.float64))
        self._seen.setdefault(key, []).append(kernel.digest(state))

    def check(self, key: tuple[str, str], values: np.ndarray, start: int) -> str | None:
        """Feed the compensating pass's rows ``start``, ... of the column ``key``: what
        differs (a block of other bits, named by its rows), or None."""
        values = np.ascontiguousarray(values, dtype=np.float64)
        block, state = self._fed.get(key, (0, kernel.digest_start()))
        row, end = start, start + values.size
        while row < end:
            stop = min(self.stops[block], end)
            kernel.digest_update(state, values[row - start:stop - start])
            if stop == self.stops[block]:
                if kernel.digest(state) != self._seen[key][block]:
                    first = self.stops[block - 1] if block else 0
                    return f"other values of {key[1]} in rows {first}-{stop - 1}"
                block, state = block + 1, kernel.digest_start()
            row = stop
        self._fed[key] = (block, state)
        return None
