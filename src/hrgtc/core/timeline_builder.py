"""A :class:`~hrgtc.core.timeline.Timeline` built chunk by chunk, for a file larger than
memory (``hrgtc info`` reads the time axis this way)."""

from __future__ import annotations

import math
from typing import Self

import numpy as np

from hrgtc.core.timeline import GAP_FACTOR, Timeline, is_gap


class TimelineBuilder:
    """A :class:`Timeline` built chunk by chunk (a file larger than memory).

    Parameters
    ----------
    period_s
        Sample period. [s]
    gap_factor
        A step longer than this many periods is a gap.
    """

    def __init__(self, period_s: float, gap_factor: float = GAP_FACTOR) -> None:
        self.period_s = float(period_s)
        self.gap_factor = gap_factor
        self._rows = 0
        self._start_rows: list[np.ndarray] = []
        self._start_s: list[np.ndarray] = []
        self._stop_s: list[np.ndarray] = []
        self._last: float | None = None

    def partial_fit(self, time_s: np.ndarray) -> Self:
        """The next chunk's sample times. [s]"""
        time_s = np.asarray(time_s, dtype=np.float64)
        if not time_s.size:
            return self
        starts = np.flatnonzero(is_gap(np.diff(time_s), self.period_s, self.gap_factor)) + 1
        if self._last is None or is_gap(time_s[0] - self._last, self.period_s, self.gap_factor):
            starts = np.concatenate([[0], starts])
        if starts.size:
            stops = time_s[np.maximum(starts - 1, 0)]
            if starts[0] == 0:
                stops[0] = math.nan if self._last is None else self._last
            self._stop_s.append(stops)
            self._start_rows.append(starts + self._rows)
            self._start_s.append(time_s[starts])
        self._rows += time_s.size
        self._last = float(time_s[-1])
        return self

    def finish(self) -> Timeline:
        """The timeline of the times seen so far."""
        if not self._start_rows:
            return Timeline(np.empty((0, 2), dtype=np.int64), np.empty(0), np.empty(0),
                            self.period_s, self.gap_factor)
        starts = np.concatenate(self._start_rows).astype(np.int64)
        stops = np.append(np.concatenate(self._stop_s)[1:], self._last)
        bounds = np.column_stack([starts, np.append(starts[1:], self._rows)])
        return Timeline(bounds, np.concatenate(self._start_s), stops, self.period_s,
                        self.gap_factor)
