"""The time axis as it is read: the repair of odd steps and the ``--start/--end`` slice.

:func:`hrgtc.recording.read` and :func:`hrgtc.recording.iter_chunks` pass every part of
a file through :func:`_repair_time` (wrapped counters unwrapped, resets shifted into a
new segment, duplicated rows dropped; see :mod:`hrgtc.core.time_steps`) and then
:class:`_TimeSlice`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hrgtc.core.time_steps import TimeRepairStream
from hrgtc.core.timeline import RESTARTS_KEY, parse_time_bound
from hrgtc.errors import InputError
from hrgtc.recording.file_rows import ROW_KEY


def _time_repairer(plan: Any) -> TimeRepairStream:
    return TimeRepairStream(plan.units.get("time", "s"), naive_clock=plan.time_is_timestamp)


def _repair_time(part: dict[str, np.ndarray], repairer: TimeRepairStream,
                 ) -> dict[str, np.ndarray]:
    """``part`` with its time axis repaired (unwrapped, resets shifted, duplicates out)."""
    time = part.get("time_s")
    if time is None or not len(time):
        return part
    others = [values for name, values in part.items()  # the file row is no value
              if name not in ("time_s", ROW_KEY)]
    repaired, keep = repairer.repair(time, others)
    if keep.all():
        return part if repaired is time else {**part, "time_s": repaired}
    return {name: repaired if name == "time_s" else values[keep]
            for name, values in part.items()}


class _TimeSlice:
    """``--start/--end``: keep the rows from ``start`` to before ``end``, seconds since the
    file's first sample or ISO clock times (a file with clock times); counts the rest."""

    def __init__(self, start: str | float | None, end: str | float | None, plan: Any) -> None:
        self.start, self.end, self.plan = start, end, plan
        self.first: float | None = None
        self.low = self.high = None
        self.dropped = 0

    @property
    def active(self) -> bool:
        return self.start is not None or self.end is not None

    def apply(self, part: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        time = part.get("time_s")
        if not self.active or time is None or not len(time):
            return part
        if self.first is None:
            self.first = float(time[0])
            origin = (None if self.plan.time_origin_ns is None
                      else str(np.datetime64(self.plan.time_origin_ns, "ns")))
            self.low = parse_time_bound(self.start, origin)
            self.high = parse_time_bound(self.end, origin)
            if self.low is not None and self.high is not None and not self.high > self.low:
                raise InputError(f"--end ({self.end}) must be after --start ({self.start})")
        since = time - self.first
        keep = np.ones(len(time), dtype=bool)
        if self.low is not None:
            keep &= since >= self.low
        if self.high is not None:
            keep &= since < self.high
        if keep.all():
            return part
        self.dropped += int(len(time) - np.count_nonzero(keep))
        return {name: values[keep] for name, values in part.items()}


def _repair_extra(repairer: TimeRepairStream) -> dict[str, Any]:
    extra: dict[str, Any] = {}
    repaired = [event.message for event in repairer.events if event.repaired]
    if repaired:
        extra["time_repairs"] = repaired
    if repairer.duplicates:
        extra["duplicates_dropped"] = repairer.duplicates
    extra.update(_restarts_extra(repairer))
    return extra


def _restarts_extra(repairer: TimeRepairStream) -> dict[str, Any]:
    """``{"restarts_s": [...]}``: the times where the logger restarted (each starts a new
    run: its own warm-up, df/dt filter and, with ``--offsets run``, offset); empty if none."""
    return {RESTARTS_KEY: list(repairer.restart_times_s)} if repairer.restart_times_s else {}
