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
error), and the detector's columns in memory, once (time and rate: 16 bytes a sample
and axis; a 3-day 1 Hz file: 260,000 rows, 4 MB). The pass reads the next chunk on a
thread while it gathers this one; the detector's loops are C
(:mod:`hrgtc.recording._motion_kernel`). ``--motion keep`` skips the pass and writes
no flag; ``--motion error`` stops at the first moving sample, naming it.

The pass reads only the detector's columns (:data:`DETECTOR_COLUMNS`, ``iter_chunks(...,
only=)``), and the spike filter's flags, which change no row, are not computed in it.
Reading fewer columns can give other rows: the reader drops a row because of a column
the pass does not read (a gap of a slow channel, ``--spikes drop``, a duplicated row
told from a duplicated time by its other values). So the flags are never trusted to
line up: :meth:`RestFlags.take` compares the detector's columns of each chunk the
compensating pass reads with those the detector saw at the same rows, bit for bit, and
the row counts at the end (the rate as the detector read it: minus the known input rate,
which the pass subtracts in place); equal columns give the detector the same input,
hence the same flags. A difference raises :class:`FlagsMisaligned`, on which
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
from hrgtc.recording.motion import ACCEL_COLUMNS, detector_rate

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
        self._seen: dict[str, dict[str, np.ndarray]] = {}  # the detector's columns by axis
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
        for chunk in _read_ahead(chunks):
            for axis, rest in passes.items():
                view = axis_view(chunk, axis) if axis else chunk
                rest.partial_fit(Recording({k: view[k] for k in DETECTOR_COLUMNS if k in view},
                                           view.metadata, view.source))
        self._seen = {axis: rest.columns for axis, rest in passes.items()}  # for take()
        self._input = {axis: rest.input_rate for axis, rest in passes.items()}
        return {axis: rest.finish().keep for axis, rest in passes.items()}

    @property
    def n_not_at_rest(self) -> int:
        """Samples not at rest on any axis (the accounting's ``motion``, flagged)."""
        still = np.logical_and.reduce([self.still[a] for a in self.axes])
        return int(still.size - np.count_nonzero(still))

    def take(self, chunk: Recording) -> dict[str, np.ndarray]:
        """The flags (1.0 at rest, 0.0 not) of the next chunk's samples, by column.

        Raises :class:`FlagsMisaligned` unless the chunk's detector columns are, bit for
        bit, those the detector saw at the same rows.
        """
        start, stop = self.rows, self.rows + len(chunk)
        flags = {}
        for i, (axis, column) in enumerate(zip(self.axes, self.columns, strict=True)):
            still, seen = self.still[axis], self._seen[axis]
            view = axis_view(chunk, axis) if axis else chunk
            if stop > still.size:
                self._misaligned(f"{stop} rows to compensate but {still.size} to the detector")
            theirs = {k for k in DETECTOR_COLUMNS if k in view}
            if theirs != set(seen):
                self._misaligned(f"columns {sorted(theirs)} to compensate but {sorted(seen)} "
                                 "to the detector")
            for name, values in seen.items():
                if (name != "time_s" or i == 0) and not _same(
                        self._read(view, name, axis, start), values[start:stop]):
                    self._misaligned(f"other values of {name} in rows {start}-{stop - 1}")
            flags[column] = still[start:stop].astype(np.float64)
        self.rows = stop
        return flags

    def _read(self, view: Recording, name: str, axis: str, start: int) -> np.ndarray:
        """A detector column of the chunk as the detector read it: the rate minus the input
        rate (the pass subtracted it in place, ``RestPass(in_place=True)``)."""
        if name != "rate_dph":
            return view[name]
        seen = self._seen[axis].get("input_rate_dph")
        known = self._input[axis] if seen is None else seen[start:start + len(view)]
        rate = np.asarray(view[name], dtype=np.float64)
        return detector_rate(rate, known)

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


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two float64 columns hold the same bits (NaN included)."""
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and bool(np.array_equal(a.view(np.int64), b.view(np.int64)))

