"""The evaluation's cut of the df/dt filter's settling time, on the time axis.

Training leaves out the first ``warmup_s`` seconds after power-on (and after every gap
when the filter restarts there, ``--gaps split``); the evaluation's figures leave out
the same samples (:class:`SettlingCut`).
"""

from __future__ import annotations

from typing import Any, Self

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.timeline import is_gap, restart_rows, settle_threshold_s
from hrgtc.evaluation.series_stats import SeriesStatistics


class SettlingCut:
    """Series statistics fed only with samples past the df/dt filter's settling time.

    Settling is time on the axis (:mod:`hrgtc.core.timeline`), as in training: the
    first ``warmup_s`` seconds after the run's first sample and, when the filter
    restarts after every gap (``gaps="split"``), after every gap too. A run with fewer
    than ``minimum`` settled samples keeps its last ``minimum`` samples (two 10 s
    blocks) instead -- except when the filter restarts at gaps: then no sample is a
    fair one and :meth:`finish` raises, naming ``--gaps bridge``. Until that is decided
    the rows are held back; then they are fed in order.
    """

    def __init__(self, series: dict[str, SeriesStatistics], warmup_s: float, period_s: float,
                 minimum: int, restart_at_gaps: bool = False, keep_mask: bool = False,
                 name: str = "run") -> None:
        self.series = series
        self.name = name  # the run, in the error of :meth:`finish`
        self.warmup_s = float(warmup_s)
        self.period_s = float(period_s)
        self.minimum = minimum
        self.restart_at_gaps = restart_at_gaps
        self.held: dict[str, list[np.ndarray]] = {key: [] for key in series}
        self.held_masks: list[np.ndarray] = []
        self.held_times: list[np.ndarray] = []
        self._last_kept: float | None = None
        self.masks: list[np.ndarray] | None = [] if keep_mask else None
        self.rows = 0
        self.settled_rows = 0
        self.cut = 0
        self.flushed = False
        self._origin: float | None = None
        self._last: float | None = None

    def _settled(self, time: np.ndarray, restarts_s: Any = ()) -> np.ndarray:
        if self._origin is None:
            self._origin = float(time[0])
        origin = np.full(time.size, self._origin)
        starts = restart_rows(time, restarts_s)  # a logger restart: a new run settles again
        if self.restart_at_gaps:
            gaps = np.flatnonzero(is_gap(np.diff(time), self.period_s)) + 1
            if self._last is not None and is_gap(time[0] - self._last, self.period_s):
                gaps = np.concatenate([[0], gaps])
            starts = np.union1d(starts, gaps).astype(np.int64)
        if starts.size:
            lengths = np.diff(np.append(starts, time.size))
            origin[starts[0]:] = np.repeat(time[starts], lengths)
            self._origin = float(time[starts[-1]])
        self._last = float(time[-1])
        return time - origin >= settle_threshold_s(self.warmup_s)

    def partial_fit(self, values: dict[str, np.ndarray], time: np.ndarray,
             restarts_s: Any = ()) -> Self:
        """The next rows of every series (one length) and their times [s]; ``restarts_s``:
        times of logger restarts (``metadata.extra["restarts_s"]``), where the df/dt filter
        settles again."""
        if not time.size:
            return self
        mask = self._settled(time, restarts_s)
        self.rows += time.size
        if self.flushed:
            self._feed(values, mask, time)
            return self
        for key, array in values.items():
            self.held[key].append(array)
        self.held_masks.append(mask)
        self.held_times.append(time)
        self.settled_rows += int(mask.sum())
        if self.settled_rows >= self.minimum:
            self._flush(np.concatenate(self.held_masks))
        return self

    def _feed(self, values: dict[str, np.ndarray], mask: np.ndarray, time: np.ndarray) -> None:
        self.cut += int(mask.size - np.count_nonzero(mask))
        if self.masks is not None:
            self.masks.append(mask)
        kept = time[mask]
        if not kept.size:
            return
        # where the samples fed are not contiguous (a gap): τ-blocks and Allan differences
        # restart there
        breaks = np.flatnonzero(is_gap(np.diff(kept), self.period_s)) + 1
        if self._last_kept is not None and is_gap(kept[0] - self._last_kept, self.period_s):
            breaks = np.concatenate([[0], breaks])
        self._last_kept = float(kept[-1])
        for key, array in values.items():
            self.series[key].partial_fit(array[mask], breaks.tolist(), kept)

    def finish(self) -> int:
        """Feed what is still held back; the number of samples left out (settling)."""
        if not self.flushed:
            if self.restart_at_gaps and self.settled_rows < self.minimum:
                raise InputError(
                    f"{self.name}: only {self.settled_rows} of {self.rows} samples are past the "
                    f"df/dt filter's {self.warmup_s:g} s settling time: --gaps split restarts the "
                    "filter after every gap and the segments are shorter than that; use --gaps "
                    "bridge (the filter carries across gaps, e.g. a burst logger)")
            mask = np.zeros(self.rows, dtype=bool)
            mask[max(self.rows - self.minimum, 0):] = True
            self._flush(mask)
        return self.cut

    def kept(self) -> np.ndarray:
        """Mask of the rows fed (only with ``keep_mask``)."""
        return np.concatenate(self.masks) if self.masks else np.empty(0, dtype=bool)

    def _flush(self, mask: np.ndarray) -> None:
        held = {key: np.concatenate(parts) if parts else np.empty(0)
                for key, parts in self.held.items()}
        time = np.concatenate(self.held_times) if self.held_times else np.empty(0)
        self.held, self.held_masks, self.held_times = {}, [], []
        self.flushed = True
        self._feed(held, mask, time)
