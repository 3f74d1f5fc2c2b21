"""One classifier of odd time steps, and the repair that makes each case the clean file.

A real logger's time column goes backwards or jumps for reasons that need different
fixes, and "sort the file by time" (which would interleave two runs) fits none of
them. :func:`classify_time_steps` looks at every non-increasing or odd step and
says which it is:

``wrap``
    A 32-bit counter wrapped (a µs counter every 2³² µs = 71.6 min, a ms counter
    every 49.7 days): the step is about -2³² units. Unwrapped (2³² units added to
    every later time).
``reset``
    The logger's clock restarted near zero (a power cycle): a new run, so a new
    segment starts there (listed in :attr:`TimeDiagnosis.restarts`); later times are
    shifted to follow the earlier run after a gap.
``dst``
    A step of about ±3600 s in naive clock times: daylight saving time began or
    ended. Not repairable without the time zone: a problem naming ``--tz`` (with
    ``--tz ZONE`` the clock times are read as UTC and the step is gone).
``duplicate``
    Rows repeated with the same time and the same values (a logger that re-sent a
    block): dropped and counted.
``duplicate_time`` / ``backwards``
    The same time with other values, or a step back that is none of the above: a
    problem naming the row.
``time_unit``
    The time steps are 1000 (or 10⁶) times the sample period: ms or µs read as
    seconds (``--time-unit ms``), or 1000 times smaller: ``--time-unit ms`` given
    on seconds.
``sample_rate``
    Every step disagrees with the stated sample rate by the same factor: the
    ``--rate-hz`` given is wrong (the measured rate is named).
``rate_change``
    The rate really changes within the file: the row where it changes.

Every command reads this one diagnosis (through the recording validator), so
``info``, ``calibrate``, ``compensate`` and ``evaluate`` say the same thing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.records import Count
from hrgtc.core.timeline import GAP_FACTOR, gap_limit_s, median_period_s

#: Modulus of a 32-bit counter in seconds, per time unit of the raw column.
WRAP_MODULUS_S = {"ms": 2.0**32 * 1e-3, "us": 2.0**32 * 1e-6}
#: Longest gap (as a fraction of the counter's range) a wrap may hide in.
WRAP_GAP = 0.01
DST_STEP_S = 3600.0
#: A step back lands "near zero" (a reset) when it lands below this fraction of the
#: time it came from.
RESET_FRACTION = 0.1
#: Relative tolerance of a sample rate (a rate change, a wrong --rate-hz).
RATE_TOLERANCE = 0.01
#: Rows per block of the rate-change scan.
RATE_BLOCK_ROWS = 1000
REPAIRED = ("wrap", "reset", "duplicate")


@dataclass(frozen=True)
class TimeEvent(records.Written):
    """One kind of odd time step found in a recording.

    Attributes
    ----------
    kind
        ``wrap``, ``reset``, ``dst``, ``duplicate``, ``duplicate_time``,
        ``backwards``, ``time_unit``, ``sample_rate`` or ``rate_change``.
    row
        First row concerned (0 = first data row).
    count
        Number of steps (or rows, for duplicates) of this kind.
    message
        What it is and what was done or what to do.
    repaired
        True when the time axis was repaired (no action needed).
    """

    kind: str
    row: Count
    count: Count
    message: str
    repaired: bool


#: The record of :class:`TimeEvent` (nested in :class:`TimeDiagnosisRecord`).
TimeEventRecord = records.record_of(TimeEvent)


@dataclass(frozen=True)
class TimeDiagnosis(records.Dumped):
    """The classifier's verdict on a time column.

    Attributes
    ----------
    time_s
        The repaired times (wraps unwrapped, resets shifted), duplicates removed. [s]
    keep
        Mask of the input rows kept (False: a dropped duplicate).
    restarts
        Rows (of the repaired, kept rows) where a new run starts after a reset.
    events
        One :class:`TimeEvent` per kind found, in the order of their first row.
    period_s
        Median period of the repaired time. [s]
    offset_s
        Shift added to each input row's time by the repair (unwraps, resets). [s]
    """

    #: Its record (:data:`TimeDiagnosisRecord`; written, not read back: the arrays are not
    #: in it).
    not_written = ("time_s", "keep", "offset_s")
    record_order = ("events", "restarts", "duplicates", "period_s")

    time_s: np.ndarray
    keep: np.ndarray
    restarts: tuple[Count, ...]
    events: tuple[TimeEvent, ...] = field(default_factory=tuple)
    period_s: records.Statistic = math.nan
    offset_s: np.ndarray | None = None

    @property
    def problems(self) -> tuple[TimeEvent, ...]:
        """Events the repair cannot fix (the user must)."""
        return tuple(e for e in self.events if not e.repaired)

    @records.derived
    def duplicates(self) -> Count:
        """Rows dropped as duplicates."""
        return int((~self.keep).sum())

    def event(self, kind: str) -> TimeEvent | None:
        """The event of one kind, or None."""
        return next((e for e in self.events if e.kind == kind), None)


#: The record of :class:`TimeDiagnosis`, generated from its fields and ``duplicates``.
TimeDiagnosisRecord = records.record_of(
    TimeDiagnosis, doc="The record of :class:`TimeDiagnosis` (``duplicates``: rows dropped; "
    "``period_s``\n``null`` when unknown).")


def _same_rows(values: np.ndarray | None, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    if values is None:
        return np.ones(a.size, dtype=bool)
    return np.all((values[a] == values[b]) | (np.isnan(values[a]) & np.isnan(values[b])),
                  axis=1)


def classify_time_steps(time_s: np.ndarray, *, nominal_period_s: float | None = None,
                        time_unit: str | None = "s", naive_clock: bool = False,
                        values: np.ndarray | None = None,
                        gap_factor: float = GAP_FACTOR, period_s: float | None = None,
                        rate_events: bool = True) -> TimeDiagnosis:
    """Classify every non-increasing or odd time step and repair what can be repaired.

    Parameters
    ----------
    time_s
        Times as read, in seconds after the unit conversion (a raw ms counter / 1000). [s]
    nominal_period_s
        Sample period stated by the metadata or ``--rate-hz`` (None: inferred from the
        steps, then no ``sample_rate`` verdict). [s]
    time_unit
        Unit of the raw time column (``s``, ``ms``, ``us``, ``timestamp``): which
        counter wraps to look for, and the hints (None: unknown, both wraps looked for).
    naive_clock
        The times are clock times without a time zone (``±3600 s`` steps are daylight
        saving).
    values
        The other columns, shape (rows, columns), to tell a duplicated row from a
        duplicated time with other values (None: a repeated time is a duplicate row).
    gap_factor
        A step longer than this many periods is a gap.
    period_s
        Sample period to judge steps by (default: the median step). [s]
    rate_events
        Also judge the time unit and sample rate (``time_unit``, ``sample_rate``,
        ``rate_change``); off for the chunk-by-chunk repair.

    Returns
    -------
    TimeDiagnosis

    Examples
    --------
    >>> t = (np.arange(10) * 0.5 + 4294.0) % (2**32 * 1e-6)   # a µs counter wraps
    >>> d = classify_time_steps(t, time_unit="us")
    >>> [e.kind for e in d.events], bool(np.all(np.diff(d.time_s) > 0))
    (['wrap'], True)
    """
    raw = np.asarray(time_s, dtype=np.float64)
    step = np.diff(raw)
    period = median_period_s(raw) if period_s is None else float(period_s)
    moduli = tuple(WRAP_MODULUS_S.values()) if time_unit is None else tuple(
        m for u, m in WRAP_MODULUS_S.items() if u == time_unit)
    if naive_clock:
        moduli = ()  # clock times do not wrap; their odd steps are daylight saving
    with np.errstate(invalid="ignore"):
        odd = step <= 0
        if naive_clock and math.isfinite(period):
            limit = gap_limit_s(period, gap_factor)
            forward = np.abs(step - DST_STEP_S) <= limit
            odd |= forward
    walk = _StepWalk(raw, values, period, gap_factor, moduli, naive_clock)
    for i in np.flatnonzero(odd):
        walk.visit(int(i) + 1, float(step[i]))
    offset = np.zeros(raw.size)
    for row, value in walk.shifts:
        offset[row:] = value
    repaired = raw + offset
    keep = walk.keep
    kept_index = np.flatnonzero(keep)
    repaired = repaired[keep]
    restart_rows = tuple(int(np.searchsorted(kept_index, r)) for r in walk.restarts)
    good_period = median_period_s(repaired)
    out = [_event(kind, row, count, detail)
           for kind, (row, count, detail) in walk.events.items()]
    if rate_events:
        out += _rate_events(repaired, kept_index, good_period, nominal_period_s, gap_factor,
                            time_unit or "s")
    out.sort(key=lambda e: e.row)
    return TimeDiagnosis(repaired, keep, restart_rows, tuple(out), good_period, offset)


@dataclass
class _StepWalk:
    """The walk of :func:`classify_time_steps` over the odd steps, in row order.

    It reads the raw times, the other columns (``values``), the period the steps are
    judged by, the gap factor, the counter moduli a wrap may have and whether the times
    are naive clock times; it gathers the rows kept, the events (kind -> [first row,
    count, detail]), the rows where the clock restarted and the offsets to add from a row
    on (``shifts``), with the running offset and the first row of the raw times' current
    increasing stretch (after a wrap, ...) (``since``).
    """

    raw: np.ndarray
    values: np.ndarray | None
    period: float
    gap_factor: float
    moduli: tuple[float, ...]
    naive_clock: bool
    keep: np.ndarray = field(init=False)
    events: dict[str, list[Any]] = field(default_factory=dict)
    restarts: list[int] = field(default_factory=list)
    shifts: list[tuple[int, float]] = field(default_factory=list)
    cumulative: float = 0.0
    since: int = 0

    def __post_init__(self) -> None:
        self.keep = np.ones(self.raw.size, dtype=bool)

    def note(self, kind: str, row: int, count: int = 1, detail: Any = None) -> None:
        """Count one more event of ``kind`` (its first row and detail kept)."""
        if kind in self.events:
            self.events[kind][1] += count
        else:
            self.events[kind] = [row, count, detail]

    def visit(self, row: int, s: float) -> None:
        """Judge the odd step ``s`` [s] into ``row``: a wrap, daylight saving, a duplicate,
        a reset or a step backwards."""
        raw, n = self.raw, self.raw.size
        if not self.keep[row]:
            return
        before, after = float(raw[row - 1]), float(raw[row])
        if not (math.isfinite(before) and math.isfinite(after)):
            return  # a non-finite time is the validation's to report
        period = self.period
        limit = gap_limit_s(period, self.gap_factor) if math.isfinite(period) else 0.0
        # a wrap or a reset goes on from there: the next step is an ordinary one (a single
        # glitched time is neither)
        goes_on = row + 1 >= n or 0.0 < raw[row + 1] - after <= max(limit, 0.0) or (
            not math.isfinite(limit))
        # a wrap lands where the counter would have been: a step of one period (or a gap
        # of up to 1 % of the counter's range) past 2^32 units
        modulus = next((m for m in self.moduli if 0.0 < s + m <= max(limit, WRAP_GAP * m)),
                       None)
        if modulus is not None and goes_on:
            self.note("wrap", row, detail=modulus)
            self.since = row
            self.cumulative += modulus
            self.shifts.append((row, self.cumulative))
        elif self.naive_clock and (abs(abs(s) - DST_STEP_S) <= limit
                                   or -DST_STEP_S - limit <= s < -0.5 * DST_STEP_S):
            # the clocks going back by 1 h, on a burst logger across a pause (-3600 s +
            # the pause): the zone is missing, not the file joined out of order
            self.note("dst", row, detail=s)
            self.since = row
        elif s <= 0.0:
            self._backwards(row, s, before, after, limit, goes_on)

    def _backwards(self, row: int, s: float, before: float, after: float, limit: float,
                   goes_on: bool) -> None:
        """A step ``s`` <= 0 that is no wrap: duplicate rows, a duplicate time, a reset
        (the clock restarted near zero) or a step backwards."""
        count = _duplicate_block(self.raw, self.keep, self.values, row, self.since)
        if count:
            self.note("duplicate", row, count)
        elif s == 0.0:
            self.note("duplicate_time", row)
        elif goes_on and before > 0.0 and -limit <= after <= RESET_FRACTION * before:
            self.note("reset", row)
            self.since = row
            self.restarts.append(row)
            # follow the earlier run after a gap of 10 gap limits (its length is unknown)
            self.cumulative += before - after + 10.0 * limit
            self.shifts.append((row, self.cumulative))
        else:
            self.note("backwards", row, detail=(before, after))


def _duplicate_block(raw: np.ndarray, keep: np.ndarray, values: np.ndarray | None,
                     row: int, since: int = 0) -> int:
    """Rows from ``row`` on that repeat earlier rows (same time, same values); marks them.

    The earlier rows are looked up in ``raw[since:row]``, the stretch since the last wrap,
    reset or clock jump, where the raw times increase (a binary search over the whole
    file, whose µs counter wrapped or restarted, finds the wrong rows).
    """
    end = row
    before = raw[row - 1]
    n = raw.size
    while end < n and raw[end] <= before:
        end += 1
    earlier = since + np.searchsorted(raw[since:row], raw[row:end], side="left")
    earlier = np.minimum(earlier, row - 1)
    same = raw[earlier] == raw[row:end]
    if not same.all():
        return 0
    if not _same_rows(values, earlier, np.arange(row, end)).all():
        return 0
    keep[row:end] = False
    return end - row


def _event(kind: str, row: int, count: int, detail: Any) -> TimeEvent:
    if kind == "wrap":
        modulus = detail
        unit = next(u for u, m in WRAP_MODULUS_S.items() if m == modulus)
        return TimeEvent(kind, row, count,
                         f"row {row}: the 32-bit {unit} time counter wrapped ({count} time(s), "
                         f"every {modulus:.6g} s = {modulus / 60:.4g} min); unwrapped", True)
    if kind == "reset":
        return TimeEvent(kind, row, count,
                         f"row {row}: the time restarts near zero ({count} time(s)): the logger "
                         "was reset; a new run (segment) starts there", True)
    if kind == "duplicate":
        return TimeEvent(kind, row, count,
                         f"row {row}: {count} duplicated row(s) (same time, same values) "
                         "dropped", True)
    if kind == "dst":
        sign = "back" if detail < 0 else "forward"
        jump = ("3600 s" if abs(abs(detail) - DST_STEP_S) <= 1.0 else
                f"{abs(detail):.6g} s (1 h less a pause of {DST_STEP_S - abs(detail):.6g} s)")
        return TimeEvent(kind, row, count,
                         f"row {row}: the clock time jumps {sign} by {jump} ({count} time(s)): "
                         "daylight saving time in clock times without a time zone; pass --tz "
                         "with the zone they were written in (e.g. --tz Europe/Berlin)", False)
    if kind == "duplicate_time":
        return TimeEvent(kind, row, count,
                         f"row {row}: the same time as the row before with other values "
                         f"({count} row(s)); two records per time stamp: drop one or fix the "
                         "time column", False)
    before, after = detail
    return TimeEvent(kind, row, count,
                     f"row {row}: time steps back from {before:.9g} s to {after:.9g} s "
                     f"({count} step(s)), neither a counter wrap, a reset to zero nor a "
                     "duplicated block; two files joined out of order? split the file at "
                     f"row {row}", False)


def _rate_events(time_s: np.ndarray, kept_index: np.ndarray, period: float,
                 nominal: float | None, gap_factor: float, unit: str) -> list[TimeEvent]:
    if not math.isfinite(period):
        return []
    if nominal is not None and nominal > 0:
        ratio = period / nominal
        for factor, fix in ((1e3, "pass --time-unit ms"), (1e6, "pass --time-unit us")):
            if abs(ratio / factor - 1.0) <= 0.05:
                return [TimeEvent(
                    "time_unit", 0, 1,
                    f"the median time step {period:.6g} is {factor:g} times the sample period "
                    f"{nominal:.6g} s: the time column is in {fix[-2:]}, not seconds; {fix}",
                    False)]
        for factor, was in ((1e-3, "ms"), (1e-6, "us")):
            if abs(ratio / factor - 1.0) <= 0.05:
                return [TimeEvent(
                    "time_unit", 0, 1,
                    f"the median time step {period:.6g} s is {1 / factor:g} times shorter than "
                    f"the sample period {nominal:.6g} s: the time column is already in "
                    f"seconds; drop --time-unit {unit if unit != 's' else was}", False)]
        if abs(ratio - 1.0) > RATE_TOLERANCE:
            return [TimeEvent(
                "sample_rate", 0, 1,
                f"every time step says {1 / period:.6g} Hz (median step {period:.6g} s) but the "
                f"sample rate given is {1 / nominal:.6g} Hz; the rate does not change within "
                f"the file: fix --rate-hz (--rate-hz {1 / period:.6g})", False)]
    change = _rate_change_row(time_s, period, gap_factor)
    if change is None:
        return []
    row, old, new = change
    row = int(kept_index[row]) if row < kept_index.size else row
    return [TimeEvent(
        "rate_change", row, 1,
        f"row {row}: the sample rate changes from {old:.6g} Hz to {new:.6g} Hz; split the file "
        f"at row {row} and process the parts separately (or resample)", False)]


def _rate_change_row(time_s: np.ndarray, period: float,
                     gap_factor: float) -> tuple[int, float, float] | None:
    """First row where the local period leaves the file's start period for good."""
    step = np.diff(time_s)
    if step.size < 2 * RATE_BLOCK_ROWS // 10:
        return None
    rows = max(10, min(RATE_BLOCK_ROWS, step.size // 4))
    blocks = step.size // rows
    if blocks < 2:
        return None
    part = step[: blocks * rows].reshape(blocks, rows)
    with np.errstate(invalid="ignore"):
        medians = np.nanmedian(np.where(part > 0, part, np.nan), axis=1)
    first = medians[0]
    changed = np.abs(medians / first - 1.0) > RATE_TOLERANCE
    if not changed.any():
        return None
    k = int(np.argmax(changed))
    new = medians[k]
    start = (k - 1) * rows
    window = step[start:(k + 1) * rows]
    away = np.abs(window / first - 1.0) > RATE_TOLERANCE
    limit = gap_limit_s(max(first, new), gap_factor)
    away &= (window <= limit) & (window > 0)
    at = start + int(np.argmax(away)) + 1 if away.any() else k * rows
    return at, 1.0 / first, 1.0 / new


class TimeRepairStream:
    """The repair of :func:`classify_time_steps`, chunk by chunk, for streamed reading.

    Carries the last row of the previous chunk (so a step across a chunk boundary is
    judged), the accumulated shift (unwrapped counters, resets) and the counts. A
    duplicated block is recognised when it repeats rows of the same chunk (or the
    carried row); one reaching further back is reported as a step back.

    Parameters
    ----------
    time_unit, naive_clock
        As for :func:`classify_time_steps`.
    """

    def __init__(self, time_unit: str | None = "s", naive_clock: bool = False) -> None:
        self.time_unit = time_unit
        self.naive_clock = naive_clock
        #: The file, for the messages of the reader.
        self.source = ""
        self._shift = 0.0
        self._last: tuple[float, np.ndarray | None] | None = None
        self._period: float | None = None
        self._rows = 0  # input rows seen
        self._kept = 0  # rows kept
        self._events: dict[str, list[Any]] = {}
        self.restarts: list[int] = []
        #: Repaired time of each restart's first sample (a new run starts there). [s]
        self.restart_times_s: list[float] = []
        self.duplicates = 0

    def repair(self, time_s: np.ndarray, columns: list[np.ndarray] | None = None,
               ) -> tuple[np.ndarray, np.ndarray]:
        """Repaired times and the mask of rows kept, for the next chunk.

        ``columns``: the chunk's other columns (to tell duplicated rows from a
        duplicated time); stacked only when a step is not positive.
        """
        time_s = np.asarray(time_s, dtype=np.float64)
        if not time_s.size:
            return time_s, np.ones(0, dtype=bool)
        columns = list(columns or [])
        if self._period is None:
            period = median_period_s(time_s)
            self._period = period if math.isfinite(period) else None
        with np.errstate(invalid="ignore"):
            step = np.diff(time_s)
            clean = not self.naive_clock and not bool(np.any(step <= 0)) and (
                self._last is None or not time_s[0] <= self._last[0])
        if clean:  # the common case: nothing to classify
            keep = np.ones(time_s.size, dtype=bool)
            self._advance(time_s, columns, keep, 0.0)
            return time_s + self._shift if self._shift else time_s, keep
        pre = 0 if self._last is None else 1
        values = np.column_stack(columns) if columns else None
        if pre:
            last_time, last_values = self._last
            time_all = np.concatenate([[last_time], time_s])
            values_all = (None if values is None or last_values is None
                          else np.vstack([last_values[None, :], values]))
        else:
            time_all, values_all = time_s, values
        diagnosis = classify_time_steps(time_all, time_unit=self.time_unit,
                                        naive_clock=self.naive_clock, values=values_all,
                                        period_s=self._period, rate_events=False)
        keep = diagnosis.keep[pre:]
        repaired = time_s + diagnosis.offset_s[pre:] + self._shift
        base_row = self._rows - pre
        base_kept = self._kept - pre
        for event in diagnosis.events:
            state = self._events.get(event.kind)
            if state is None:
                self._events[event.kind] = [event, base_row + event.row, event.count]
            else:
                state[2] += event.count
        self.restarts += [base_kept + r for r in diagnosis.restarts]
        kept_times = repaired[keep]
        self.restart_times_s += [float(kept_times[r - pre]) for r in diagnosis.restarts]
        self.duplicates += int((~keep).sum())
        self._advance(time_s, columns, keep,
                      float(diagnosis.offset_s[-1]) if time_s.size else 0.0)
        return repaired[keep], keep

    def _advance(self, time_s: np.ndarray, columns: list[np.ndarray], keep: np.ndarray,
                 shift: float) -> None:
        if time_s.size:
            self._shift += shift
            last = np.array([float(c[-1]) for c in columns]) if columns else None
            self._last = (float(time_s[-1]), last)
        self._rows += time_s.size
        self._kept += int(keep.sum())

    @property
    def events(self) -> tuple[TimeEvent, ...]:
        """One event per kind found so far (first row over the whole file, total count)."""
        out = []
        for first, row, count in self._events.values():
            message = first.message.replace(f"row {first.row}", f"row {row}", 1)
            message = message.replace(f"({first.count} ", f"({count} ", 1)
            out.append(TimeEvent(first.kind, row, count, message, first.repaired))
        return tuple(sorted(out, key=lambda e: e.row))
