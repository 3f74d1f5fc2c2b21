"""The core of hrgtc: the time axis of a recording and the accounting of its samples.

Every stage reads time through this package, so a warm-up, a window, a gap or a
held-out split means the same thing in ``info``, ``calibrate``, ``compensate`` and
``evaluate``:

* :mod:`hrgtc.core.timeline` -- a recording's time axis as an ordered set of
  contiguous segments (the one gap test of the package, segment bounds and
  durations, seconds since power-on, windows that never span a gap, slicing by
  seconds or clock time, time blocks for held-out splits);
* :mod:`hrgtc.core.time_steps` -- the one classifier of odd time steps (counter
  wraps, resets, daylight-saving steps, duplicates, a wrong time unit or sample
  rate, a rate that really changes) and the repair that makes each the clean file;
* :mod:`hrgtc.core.accounting` -- samples read, used, and dropped or flagged by reason.

``core`` imports nothing from the other hrgtc stages except :mod:`hrgtc.errors`.
"""

from __future__ import annotations

from hrgtc.core.accounting import REASONS, Accounting
from hrgtc.core.time_steps import TimeDiagnosis, TimeEvent, classify_time_steps
from hrgtc.core.timeline import (
    GAP_FACTOR,
    GAP_TOLERANCE,
    Timeline,
    TimelineBuilder,
    gap_limit_s,
    is_gap,
    median_period_s,
    parse_time_bound,
    seconds_since_power_on,
    segment_bounds,
    slice_rows,
    time_blocks,
    windows,
)

__all__ = [
    "GAP_FACTOR", "GAP_TOLERANCE", "REASONS", "Accounting", "TimeDiagnosis", "TimeEvent",
    "Timeline", "TimelineBuilder", "classify_time_steps", "gap_limit_s", "is_gap",
    "median_period_s", "parse_time_bound", "seconds_since_power_on", "segment_bounds",
    "slice_rows", "time_blocks", "windows",
]
