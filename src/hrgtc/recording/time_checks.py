"""The validator's words on odd time steps: which kind a step back is, and where a rate changes.

The classifier itself is :mod:`hrgtc.core.time_steps` (one diagnosis for every command);
this module turns its verdict on the first bad step of a chunk into the fix a user reads
in a :class:`~hrgtc.recording.checks.Problem`.
"""

from __future__ import annotations

import numpy as np

from hrgtc.core.time_steps import classify_time_steps
from hrgtc.core.timeline import gap_limit_s
from hrgtc.recording.checks import SAMPLE_RATE_TOLERANCE
from hrgtc.recording.schema import Metadata, Recording


def _change_row(step: np.ndarray, block: int, rows: int, period: float) -> tuple[int, float]:
    """Row where the sample rate changes, and the new rate [Hz], ``block`` being the first
    block whose mean step is off the nominal ``period``.

    The new period is the median step of that block; the change is at the row before the
    first step of the new period (searched from the block before on).
    """
    limit = gap_limit_s(period)
    blk = step[block * rows:(block + 1) * rows]
    blk = blk[(blk > 0) & (blk <= limit)]
    if not blk.size:
        return block * rows, 1.0 / period
    new = float(np.median(blk))
    start = max(block - 1, 0) * rows
    window = step[start:(block + 1) * rows]
    with np.errstate(invalid="ignore", divide="ignore"):
        match = (np.abs(window / new - 1.0) <= SAMPLE_RATE_TOLERANCE / 2) & (
            np.abs(window / period - 1.0) > SAMPLE_RATE_TOLERANCE)
    at = start + int(np.argmax(match)) if match.any() else block * rows
    return max(at - 1, 0), 1.0 / new


#: What to do about each kind of step back the classifier names (the time column as read:
#: wraps, resets and duplicated rows are repaired on reading, so here they come from a
#: recording built in memory or read without the repair).
_STEP_FIX = {
    "wrap": "a 32-bit time counter wrapped: read the file with its --time-unit (us or ms) "
            "and hrgtc unwraps it",
    "reset": "the logger's clock restarted near zero: read the file with hrgtc, which starts "
             "a new segment there (or split the file at that row)",
    "duplicate": "the rows repeat earlier ones (same time, same values): reading the file with "
                 "hrgtc drops them",
    "duplicate_time": "two records with the same time and other values: drop one or fix the "
                      "time column",
    "dst": "a step of 3600 s in clock times without a time zone is daylight saving time: "
           "pass --tz with the zone they were written in (e.g. --tz Europe/Berlin)",
    "backwards": "neither a counter wrap, a reset to zero nor a duplicated block (two files "
                 "joined out of order? sorting would interleave them): split the file at "
                 "that row",
}


def _step_diagnosis(time: np.ndarray, previous: np.ndarray, i: int, period: float,
                    metadata: Metadata | None, chunk: Recording | None = None) -> str:
    """The classifier's word on the step back at ``time[i]`` (see :mod:`hrgtc.core.time_steps`).

    Looks at up to 1000 rows either side within the chunk (with the other columns, to
    tell a duplicated row from a duplicated time).
    """
    low, high = max(i - 1000, 0), i + 1000
    window = time[low:high]
    values = None
    if chunk is not None:
        others = [chunk[name][low:high] for name in chunk.names if name != "time_s"]
        values = np.column_stack(others) if others else None
    naive = bool(metadata is not None and metadata.extra.get("time_origin")
                 and not metadata.extra.get("time_zone"))
    diagnosis = classify_time_steps(window, time_unit=None, naive_clock=naive, values=values,
                                    period_s=period, rate_events=False)
    row = i - low
    event = next((e for e in diagnosis.events if e.row == row), None)
    if event is None:
        return _STEP_FIX["duplicate_time" if time[i] == previous[i] else "backwards"]
    return _STEP_FIX.get(event.kind, _STEP_FIX["backwards"])
