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
(:func:`hrgtc.evaluation.instrument_pass.evaluate_axes`), one pass keeps only the
detector's columns (time, rate, known input rate, accelerometer axes),
:class:`hrgtc.drift.rest.RestPass` (:func:`~hrgtc.drift.rest.run_rest` a chunk at a
time) marks the samples, and the compensating pass then writes the flags: equal to
``run_rest``'s mask by construction.

The cost (issue 20, ``docs/benchmarks.md``): a second reading of the file, without
its validation (the compensating pass validates every sample; if the unvalidated
pass fails, the file is read again validated, so a bad file gets the validator's
error), and the detector's columns in memory, once (time and rate: 16 bytes a sample
and axis; a 3-day 1 Hz file: 260,000 rows, 4 MB). The detector's loops are compiled
(:mod:`hrgtc.recording._motion_kernel`). ``--motion keep`` skips the pass and writes
no flag; ``--motion error`` stops at the first moving sample, naming it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence

import numpy as np

from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.drift.rest import RestPass
from hrgtc.recording import Recording, axis_view
from hrgtc.recording.motion import ACCEL_COLUMNS

__all__ = ["AT_REST_COLUMN", "RestFlags", "rest_columns"]

#: The flag column of a single-axis output (``at_rest_<axis>`` per axis otherwise).
AT_REST_COLUMN = "at_rest"
#: The columns the detector reads (:func:`hrgtc.drift.rest.run_rest`).
_DETECTOR_COLUMNS = ("time_s", "rate_dph", "input_rate_dph", *ACCEL_COLUMNS)


def rest_columns(axes: Sequence[str]) -> tuple[str, ...]:
    """The flag columns for a model's axes (``""``: the single axis)."""
    return tuple(AT_REST_COLUMN if not axis else f"{AT_REST_COLUMN}_{axis}" for axis in axes)


class RestFlags:
    """The at-rest flags of every axis of a file, found in one pass, handed out by chunk.

    Parameters
    ----------
    chunks
        The file's chunks, read with the options of the compensating pass (the same rows),
        unvalidated.
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
        passes = {axis: RestPass(self._policy, name=self._name, rows=self._rows)
                  for axis in self.axes}
        for chunk in chunks:
            for axis, rest in passes.items():
                view = axis_view(chunk, axis) if axis else chunk
                rest.partial_fit(Recording({k: view[k] for k in _DETECTOR_COLUMNS if k in view},
                                           view.metadata, view.source))
        return {axis: rest.finish().keep for axis, rest in passes.items()}

    @property
    def n_not_at_rest(self) -> int:
        """Samples not at rest on any axis (the accounting's ``motion``, flagged)."""
        still = np.logical_and.reduce([self.still[a] for a in self.axes])
        return int(still.size - np.count_nonzero(still))

    def take(self, rows: int) -> dict[str, np.ndarray]:
        """The flags (1.0 at rest, 0.0 not) of the next ``rows`` samples, by column."""
        start, stop = self.rows, self.rows + rows
        flags = {}
        for axis, column in zip(self.axes, self.columns, strict=True):
            still = self.still[axis]
            if stop > still.size:
                raise InputError(
                    f"the recording gave {stop} rows to compensate but {still.size} to the "
                    "motion detector's pass; it changed while it was read")
            flags[column] = still[start:stop].astype(np.float64)
        self.rows = stop
        return flags
