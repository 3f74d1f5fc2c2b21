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

It also holds what every stage needs and that depends on nothing else of hrgtc:

* :mod:`hrgtc.core.errors` -- the exception and warning classes (one ``HrgtcError``,
  one ``HrgtcWarning`` at the root);
* :mod:`hrgtc.core.meta` -- the version and the paper's reference;
* :mod:`hrgtc.core.files` -- atomic output files, never overwritten without ``force``;
* :mod:`hrgtc.core.progress` -- the progress callback of long library functions;
* :mod:`hrgtc.core.process` -- facts about the running process (peak memory).

``core`` imports nothing from the other hrgtc stages. Its names are loaded on first use
(PEP 562), so ``from hrgtc.core.errors import HrgtcError`` costs no numpy import and the
command line starts at once.
"""

from __future__ import annotations

from hrgtc.core.lazy import lazy_names

#: Public name -> the core module that defines it (loaded on first access).
_NAMES = {
    "REASONS": "accounting", "Accounting": "accounting",
    "TimeDiagnosis": "time_steps", "TimeEvent": "time_steps", "classify_time_steps": "time_steps",
    **{name: "timeline" for name in (
        "GAP_FACTOR", "GAP_TOLERANCE", "Timeline", "TimelineBuilder", "gap_limit_s", "is_gap",
        "median_period_s", "parse_time_bound", "seconds_since_power_on", "segment_bounds",
        "slice_rows", "time_blocks", "windows",
    )},
}

__all__ = sorted(_NAMES)


__getattr__, __dir__ = lazy_names(__name__, _NAMES, globals())
