"""The checks of a recording's time axis, chunk by chunk: order, gaps and the sample rate.

Part of :class:`hrgtc.recording.validation.RecordingValidator` (see there for the whole
contract): time must increase strictly (a step back or a duplicate is diagnosed by
:func:`~hrgtc.recording.time_checks._step_diagnosis`), a step longer than
:data:`~hrgtc.recording.gaps.GAP_PERIODS` sample periods is a gap (listed, an error or not
by the gap policy), and the mean step of every block of
:data:`~hrgtc.recording.checks.RATE_CHECK_ROWS` rows (gaps left out) must agree with the
metadata's sample rate (the row where it changes is found by
:func:`~hrgtc.recording.time_checks._change_row`). The state carries across chunks, so
rows are numbered over the whole recording.
"""

from __future__ import annotations

import math
from typing import Self

import numpy as np

from hrgtc.core.timeline import gap_limit_s, is_bursty, is_gap
from hrgtc.recording.checks import (
    RATE_CHECK_ROWS,
    SAMPLE_RATE_TOLERANCE,
    Problem,
    finite_extremes,
)
from hrgtc.recording.gaps import MAX_LISTED_GAPS, Gap
from hrgtc.recording.schema import Metadata, Recording
from hrgtc.recording.time_checks import _change_row, _step_diagnosis

__all__ = ["TimeContinuity"]


class TimeContinuity:
    """Order, gaps and the sample rate of a recording's time axis, over all its chunks.

    Attributes
    ----------
    gaps
        The first :data:`~hrgtc.recording.gaps.MAX_LISTED_GAPS` gaps.
    n_gaps
        Number of gaps.
    rate_change
        ``(row, new rate [Hz])`` where the sample rate first changes, None if it holds.
    """

    def __init__(self) -> None:
        self.metadata: Metadata | None = None
        self._steps = np.empty(0)
        self._steps_start = 0
        self._history = np.empty(0)  # steps of the last complete block checked
        self._steps_usable = True  # every carried step finite, positive and no gap
        self.rate_change: tuple[int, float] | None = None
        self._last_time: float | None = None
        self._time_order: tuple[int, float, float] | None = None
        self._time_order_count = 0
        self._time_order_kind = ""
        self.gaps: list[Gap] = []
        self.n_gaps = 0
        #: Gaps by duration (for the dropouts: those no longer than ``dropout_s``). [s]
        self._gap_durations: list[np.ndarray] = []
        self._last_file_row: float | None = None

    def partial_fit(self, time: np.ndarray, offset: int, metadata: Metadata,
                    chunk: Recording | None = None, file_rows: np.ndarray | None = None,
                    ) -> Self:
        """Check the times of the next chunk, its first row ``offset`` of the recording
        (``chunk``: the chunk itself, for the diagnosis of a step back).

        ``file_rows``: the file row of each row, when the reader left rows out (spikes,
        duplicated rows). A step over rows the reader removed is judged per file row: the
        file's own time steps decide what a gap is and what the rate is, so rows the tool
        removed are never turned into gaps or a change of rate (they are counted where
        they were removed).
        """
        self.metadata = metadata
        period = 1.0 / self.metadata.sample_rate_hz
        spans = self._spans(file_rows)
        # fast path: steps all positive and no gap
        if spans is None and self._last_time is not None:
            step = np.empty_like(time)
            step[0] = time[0] - self._last_time
            np.subtract(time[1:], time[:-1], out=step[1:])
            extremes = finite_extremes(step)
            if extremes is not None and extremes[0] > 0.0 and (
                    extremes[1] <= gap_limit_s(period)):
                self._last_time = float(time[-1])
                self._check_rate(step, offset, time=time)
                return self
        self._partial_fit_spans(time, offset, period, chunk, spans)
        return self

    def finish(self) -> Self:
        """The checks of every chunk (read with :meth:`problems`, :meth:`dropouts`)."""
        return self

    def _spans(self, file_rows: np.ndarray | None) -> np.ndarray | None:
        """File rows each step of the chunk spans (1: no row left out between), None when
        no row was left out."""
        if file_rows is None or not len(file_rows):
            return None
        previous = self._last_file_row
        self._last_file_row = float(file_rows[-1])
        spans = np.empty(len(file_rows))
        spans[0] = 1.0 if previous is None else file_rows[0] - previous
        np.subtract(file_rows[1:], file_rows[:-1], out=spans[1:])
        if not (spans > 1.0).any():
            return None
        return np.maximum(spans, 1.0)

    def _partial_fit_spans(self, time: np.ndarray, offset: int, period: float,
                           chunk: Recording | None, spans: np.ndarray | None) -> None:
        """:meth:`partial_fit` step by step: order on the steps as they are, gaps and rate
        on each step divided by the file rows it spans (``spans``; None: one each)."""
        previous = np.empty_like(time)
        previous[0] = np.nan if self._last_time is None else self._last_time
        previous[1:] = time[:-1]
        self._last_time = float(time[-1])
        with np.errstate(invalid="ignore"):
            step = time - previous
            backwards = step <= 0
        if backwards.any():
            self._time_order_count += int(backwards.sum())
            if self._time_order is None:
                i = int(np.argmax(backwards))
                self._time_order = (offset + i, float(time[i]), float(previous[i]))
                self._time_order_kind = _step_diagnosis(time, previous, i, period,
                                                        self.metadata, chunk)
        per_row = step
        if spans is not None:  # a step over removed rows, as long as those rows took
            with np.errstate(invalid="ignore"):  # (a duplicated row took no time)
                rows_taken = np.clip(np.round(step / period), 1.0, spans)
            per_row = np.where(np.isfinite(rows_taken), step / rows_taken, step)
        with np.errstate(invalid="ignore"):
            long = np.flatnonzero(is_gap(per_row, period) & np.isfinite(per_row))
        self.n_gaps += long.size
        if long.size:
            self._gap_durations.append(step[long].copy())
        self._check_rate(per_row, offset)
        room = MAX_LISTED_GAPS - len(self.gaps)
        self.gaps += [
            Gap(float(previous[i]), float(step[i]), offset + int(i)) for i in long[:room]
        ]

    def _check_rate(self, step: np.ndarray, offset: int,
                    time: np.ndarray | None = None) -> None:
        """Mean time step of each block of :data:`RATE_CHECK_ROWS` rows (gaps left out).

        ``time``: the chunk's times, given when every step is known finite, positive
        and no gap (``step[i] = time[i] - time[i - 1]``); then a block's sum of steps
        is the difference of the times at its ends, and the steps are not summed.
        """
        if self.rate_change is not None:
            return
        rows = RATE_CHECK_ROWS
        period = 1.0 / self.metadata.sample_rate_hz
        carried = self._steps
        base = self._steps_start if carried.size else offset
        blocks = (carried.size + step.size) // rows
        new_steps = step
        if time is not None and self._steps_usable:
            ends = np.arange(1, blocks + 1) * rows - carried.size  # block ends within step
            starts = np.maximum(ends - rows, 0)
            # a block's steps add up to its last time minus the time before its first
            # step (time[0] - step[0]: the previous chunk's last), plus the carried steps
            before = np.where(starts > 0, time[np.maximum(starts - 1, 0)], time[0] - step[0])
            sums = time[ends - 1] - before
            if blocks:
                sums[0] += carried.sum()
            counts = np.full(blocks, rows)
            rest = step[ends[-1]:] if blocks else np.concatenate([carried, step])
        else:
            if carried.size:
                step = np.concatenate([carried, step])
            part = step[:blocks * rows].reshape(blocks, rows)
            with np.errstate(invalid="ignore"):
                usable = np.isfinite(part) & (part > 0) & (part <= gap_limit_s(period))
            counts = usable.sum(axis=1)
            sums = np.where(usable, part, 0.0).sum(axis=1)
            rest = step[blocks * rows:]
        if blocks:
            with np.errstate(divide="ignore", invalid="ignore"):
                measured = 1.0 / (sums / counts)
                # mostly gaps or disorder: left to those checks
                changed = (counts >= rows // 2) & (
                    np.abs(measured * period - 1.0) > SAMPLE_RATE_TOLERANCE)
            if changed.any():  # a jittery clock's skewed steps move the mean, not the median
                changed &= self._median_off(np.concatenate([carried, new_steps]), blocks,
                                            rows, period)
            if changed.any():
                k = int(np.argmax(changed))
                # the change may have begun in the block before (checked earlier, still in
                # tolerance): search from there, with the last block's steps kept
                history = self._history
                combined = np.concatenate([history, carried, new_steps])
                at, rate = _change_row(combined, k + (1 if history.size else 0), rows, period)
                self.rate_change = (base - history.size + at, rate)
                self._steps = np.empty(0)
                return
        if blocks:  # the steps of the last complete block, for the search above
            end = blocks * rows - carried.size  # its end within new_steps
            self._history = (new_steps[end - rows:end].copy() if end >= rows else
                             np.concatenate([carried, new_steps[:end]])[-rows:])
        self._steps = rest.copy()
        self._steps_start = base + blocks * rows
        with np.errstate(invalid="ignore"):
            self._steps_usable = bool(np.all(np.isfinite(rest) & (rest > 0)
                                             & (rest <= gap_limit_s(period))))

    def dropouts(self, dropout_s: float) -> tuple[int, float]:
        """Number of gaps no longer than ``dropout_s`` (bridged and counted whatever the
        policy), and the longest of them. [s]"""
        if not self._gap_durations:
            return 0, 0.0
        durations = np.concatenate(self._gap_durations)
        short = durations[durations <= dropout_s]
        return int(short.size), float(short.max()) if short.size else 0.0

    @staticmethod
    def _median_off(steps: np.ndarray, blocks: int, rows: int, period: float) -> np.ndarray:
        """For each block of ``rows`` steps: is the median of its usable steps off the
        nominal ``period`` beyond the tolerance too?"""
        part = steps[:blocks * rows].reshape(blocks, rows)
        with np.errstate(invalid="ignore"):
            usable = np.isfinite(part) & (part > 0) & (part <= gap_limit_s(period))
            medians = np.nanmedian(np.where(usable, part, np.nan), axis=1)
            return np.abs(medians / period - 1.0) > SAMPLE_RATE_TOLERANCE

    def duty_cycled(self, dropout_s: float = 0.0) -> bool:
        """A duty-cycled logger: three gaps or more longer than ``dropout_s``, its bursts
        between them much shorter than the time from one burst's start to the next's
        (:meth:`hrgtc.core.timeline.Timeline.is_bursty`'s rule). There the filters carry
        across each gap by default (``--gaps bridge``): restarting them would leave each
        burst inside the df/dt filter's warm-up."""
        long = [g for g in self.gaps if g.duration_s > dropout_s]
        if len(long) < 2:
            return False
        ends = np.array([g.start_time_s + g.duration_s for g in long[:-1]])  # a burst starts
        starts = np.array([g.start_time_s for g in long[1:]])  # the next one stops
        # the bursts between the gaps (the first and the last segments are cut by the file)
        return is_bursty(len(long) + 1, float(np.median(starts - ends)),
                         float(np.median(np.diff([g.start_time_s for g in long]))))

    def problems(self, gap_policy: str, whole_file: bool,
                 dropout_s: float = 0.0) -> list[Problem]:
        """The problems of the time axis so far. ``whole_file``: a time unit or sample
        rate wrong for the whole file (or not yet ruled out) was found, of which gaps and
        rate changes are consequences, not news; ``gap_policy`` ``"error"``: gaps longer
        than ``dropout_s`` (the dropouts change no result) are problems."""
        problems: list[Problem] = []
        if self.rate_change is not None and not whole_file:
            row, measured = self.rate_change
            nominal = self.metadata.sample_rate_hz
            now, then = _distinct(measured, nominal)
            problems.append(Problem(
                "sample_rate",
                f"column 'time_s', row {row}: the time step changes to {now} Hz but "
                f"the metadata (and the start of the file) say {then} Hz; the sample rate "
                f"changes within the file: split it at row {row} and process the parts "
                "separately (or resample)",
                column="time_s", row=row, value=now))
        if self._time_order is not None:
            row, now, before = self._time_order
            what = "a duplicate time" if now == before else "a step back in time"
            problems.append(
                Problem(
                    "time_order",
                    f"column 'time_s', row {row}: {now!r} s after {before!r} s is {what} "
                    f"(time must increase strictly; {self._time_order_count} bad step(s)); "
                    f"{self._time_order_kind}",
                    column="time_s",
                    row=row,
                    value=repr(now),
                    count=self._time_order_count,
                )
            )
        n_dropouts = self.dropouts(dropout_s)[0]
        n_long = self.n_gaps - n_dropouts
        if n_long and gap_policy == "error" and not whole_file and not self.duty_cycled(
                dropout_s):
            durations = np.concatenate(self._gap_durations)
            first = next((g for g in self.gaps if g.duration_s > dropout_s), None)
            if first is None:  # beyond the gaps listed: the first long one's duration only
                first = Gap(math.nan, float(durations[durations > dropout_s][0]), -1)
            where = (f"column 'time_s', row {first.row}: " if first.row >= 0
                     else "column 'time_s': ")
            after = ("" if math.isnan(first.start_time_s)
                     else f" after t = {first.start_time_s:.6g} s")
            total = float(durations[durations > dropout_s].sum())
            bridged = (f" ({n_dropouts} shorter dropout(s) are bridged and counted)"
                       if n_dropouts else "")
            problems.append(
                Problem(
                    "gap",
                    f"{where}{n_long} gap(s) longer than a dropout ({dropout_s:g} s; "
                    f"{total:.6g} s without samples in all), the first {first.duration_s:.6g} s"
                    f"{after}{bridged}; the choice changes the result: pass --gaps bridge "
                    "(the filters carry across each gap with its duration, e.g. a burst logger) "
                    "or --gaps split (the df/dt filter restarts after each and its warm-up is "
                    "left out again)",
                    column="time_s",
                    row=first.row if first.row >= 0 else None,
                    value=f"{first.duration_s:.6g}",
                    count=n_long,
                )
            )
        return problems


def _distinct(a: float, b: float) -> tuple[str, str]:
    """``a`` and ``b`` written with the fewest significant digits (at least 3) that tell them
    apart, so a message never says "changes to 1 Hz ... say 1 Hz".

    >>> _distinct(0.99, 1.0), _distinct(1.97728, 1.97939)
    (('0.99', '1'), ('1.977', '1.979'))
    """
    for digits in range(3, 17):
        left, right = f"{a:.{digits}g}", f"{b:.{digits}g}"
        if left != right:
            return left, right
    return f"{a!r}", f"{b!r}"
