"""The time axis as it is read: the repair of odd steps and the ``--start/--end`` slice.

:func:`hrgtc.recording.read` and :func:`hrgtc.recording.iter_chunks` pass every part of
a file through :func:`_repair_time` (wrapped counters unwrapped, resets shifted into a
new segment, duplicated rows dropped; see :mod:`hrgtc.core.time_steps`) and then
:class:`_TimeSlice`.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Any

import numpy as np

from hrgtc.core.errors import GapWarning, InputError, RecordingError
from hrgtc.core.time_steps import TimeRepairStream
from hrgtc.core.timeline import RESTARTS_KEY, parse_time_bound
from hrgtc.recording.file_rows import ROW_KEY


def _time_repairer(plan: Any) -> TimeRepairStream:
    # clock times read in a --tz zone are UTC: no daylight saving step is left to name
    naive = plan.time_is_timestamp and getattr(plan, "tz", None) is None
    repairer = TimeRepairStream(plan.units.get("time", "s"), naive_clock=naive)
    repairer.source = str(plan.source.path)  # for the daylight saving error
    return repairer


def _repair_time(part: dict[str, np.ndarray], repairer: TimeRepairStream,
                 plan: Any = None) -> dict[str, np.ndarray]:
    """``part`` with its time axis repaired (unwrapped, resets shifted, duplicates out)."""
    time = part.get("time_s")
    if time is None or not len(time):
        return part
    if getattr(plan, "time_aware", False):  # UTC or an offset in each time: no DST step
        repairer.naive_clock = False
    others = [values for name, values in part.items()  # the file row is no value
              if name not in ("time_s", ROW_KEY)]
    repaired, keep = repairer.repair(time, others)
    dst = next((e for e in repairer.events if e.kind == "dst"), None) if (
        repairer.naive_clock) else None
    if dst is not None:  # forward too (a gap to the validator): --tz is the fix
        where = repairer.source
        raise RecordingError(f"{where + ': ' if where else ''}column 'time_s', {dst.message}")
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
            zone = getattr(self.plan, "tz", None)  # --tz: the bounds are clock times there
            self.low = parse_time_bound(bound_in_utc(self.start, zone), origin)
            self.high = parse_time_bound(bound_in_utc(self.end, zone), origin)
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


def warn_restarts(repairer: TimeRepairStream) -> None:
    """Say, once per reading, that the logger restarted (each restart starts a new run: the
    df/dt filter settles again and its warm-up is left out again)."""
    event = next((e for e in repairer.events if e.kind == "reset"), None)
    if event is not None:
        where = repairer.source
        warnings.warn(GapWarning(
            f"{where + ': ' if where else ''}column 'time_s', {event.message}; the df/dt "
            "filter settles again after it"), stacklevel=3)


def with_restarts(metadata: Any, repairer: TimeRepairStream) -> Any:
    """``metadata`` with the logger restarts found so far (each a new run)."""
    restarts = _restarts_extra(repairer)
    return replace(metadata, extra={**metadata.extra, **restarts}) if restarts else metadata


def _restarts_extra(repairer: TimeRepairStream) -> dict[str, Any]:
    """``{"restarts_s": [...]}``: the times where the logger restarted (each starts a new
    run: its own warm-up, df/dt filter and, with ``--offsets run``, offset); empty if none."""
    return {RESTARTS_KEY: list(repairer.restart_times_s)} if repairer.restart_times_s else {}


def check_zone(zone: str | None) -> str | None:
    """``--tz``: an IANA time zone name (``Europe/Berlin``, ``UTC``), or None."""
    if zone is None:
        return None
    import zoneinfo

    try:
        zoneinfo.ZoneInfo(str(zone))
    except (zoneinfo.ZoneInfoNotFoundError, ValueError):
        raise InputError(f"--tz {zone!r} is not a time zone of the IANA database; give the zone "
                         "the clock times were written in, e.g. --tz Europe/Berlin or --tz "
                         "America/New_York (--tz UTC for clock times in UTC)") from None
    return str(zone)


class ZoneClock:
    """Naive clock times written in a time zone (``--tz``) read as UTC, chunk by chunk.

    When daylight saving time ends, the clock goes back one hour and the hour before
    it is written twice: those times are ambiguous. They are resolved in order: the
    first pass is daylight saving time, and from the step back (the clock time going
    back within the repeated hour) on, standard time; the state is carried across
    chunks. A clock time that does not exist in the zone (in the hour skipped when
    daylight saving time begins) is an error naming the row.

    Parameters
    ----------
    zone
        IANA time zone name.
    source
        The file, for the messages.
    """

    def __init__(self, zone: str, source: str = "") -> None:
        self.zone = zone
        self.source = source
        self._last_naive: int | None = None  # the previous row's clock time [ns]
        self._late = False  # the previous row was in the second pass of a repeated hour

    def utc_ns(self, naive: Any, theirs: str, row_offset: int) -> np.ndarray:
        """UTC [ns since the epoch] of the naive timestamps ``naive`` (a pyarrow array
        of ``timestamp("ns")``, nulls allowed: returned as 0, the caller masks them)."""
        import pyarrow as pa
        import pyarrow.compute as pc

        from hrgtc.recording.formats import first_failing

        def convert(ambiguous: str) -> np.ndarray:
            def localise(array: Any) -> Any:
                return pc.assume_timezone(array, self.zone, ambiguous=ambiguous,
                                          nonexistent="raise")
            try:
                aware = localise(naive)
            except pa.ArrowInvalid:
                i = first_failing(naive, localise)
                raise RecordingError(
                    f"{self.source}: column {theirs!r}, row {row_offset + i}: "
                    f"{naive[i].as_py()} does not exist in time zone {self.zone} (the hour "
                    "skipped when daylight saving time begins); is --tz right?") from None
            ints = aware.cast(pa.timestamp("ns", tz="UTC")).cast(pa.int64()).fill_null(0)
            return np.asarray(ints.to_numpy(zero_copy_only=False), dtype=np.int64)

        early = convert("earliest")
        late = convert("latest")
        clock = np.asarray(naive.cast(pa.int64()).fill_null(0).to_numpy(zero_copy_only=False),
                           dtype=np.int64)
        ambiguous = early != late
        out = early
        if ambiguous.any():
            before = np.concatenate([[clock[0] if self._last_naive is None
                                      else self._last_naive], clock[:-1]])
            back = clock < before
            in_late = np.zeros(clock.size, dtype=bool)
            edges = np.flatnonzero(np.diff(np.concatenate([[0], ambiguous.view(np.int8), [0]])))
            for start, stop in zip(edges[::2], edges[1::2], strict=True):
                carried = start == 0 and self._late
                steps = np.flatnonzero(back[start:stop])
                first = start if carried else (start + int(steps[0]) if steps.size else stop)
                in_late[first:stop] = True
            out = np.where(in_late, late, early)
            self._late = bool(in_late[-1])
        else:
            self._late = False
        if clock.size:
            self._last_naive = int(clock[-1])
        return out


def bound_in_utc(text: Any, zone: str | None) -> Any:
    """A ``--start/--end`` clock time written in ``zone`` as a naive UTC ISO time (seconds
    and times without a zone pass unchanged)."""
    if zone is None or text is None or not isinstance(text, str):
        return text
    try:
        float(text)
        return text
    except ValueError:
        pass
    import pyarrow as pa
    import pyarrow.compute as pc

    try:
        naive = pa.array([text.strip().replace(" ", "T")]).cast(pa.timestamp("ns"))
        aware = pc.assume_timezone(naive, zone, ambiguous="earliest", nonexistent="earliest")
    except (pa.ArrowInvalid, pa.ArrowTypeError):
        return text  # not a clock time: parse_time_bound says what is wrong
    ns = int(aware.cast(pa.timestamp("ns", tz="UTC")).cast(pa.int64())[0].as_py())
    return str(np.datetime64(ns, "ns"))
