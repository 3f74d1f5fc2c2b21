"""A recording's time axis as an ordered set of contiguous segments.

Real loggers pause, restart and run duty-cycled (bursts of a few seconds every few
minutes). A *gap* is a time step longer than :data:`GAP_FACTOR` times the sample
period (with the relative slack :data:`GAP_TOLERANCE`, so a step of exactly two
periods -- one missing sample -- is not a gap whatever the rounding of the times).
The rows between gaps form a *segment*. This module is the one place that says so:
the validator, :func:`hrgtc.recording.split_at_gaps` and the compensator call
:func:`is_gap`.

Every parameter with a time meaning is in seconds and applied on this axis:

* :func:`seconds_since_power_on` -- the warm-up skip is applied once, from the
  start of the recording, unless each segment is a restart;
* :func:`windows` -- windows of ``W`` seconds that never span a gap; a partial
  window at the end of a segment is kept when it holds at least
  :data:`PARTIAL_WINDOW_FRACTION` of a window, else dropped, and both are counted;
* :func:`slice_rows` / :func:`parse_time_bound` -- ``--start/--end`` in seconds since
  the file's start or as ISO clock times;
* :func:`time_blocks` -- contiguous blocks of the time axis (cut at segment bounds
  where possible) for held-out splits and leave-one-block-out cross-validation.

Times are in seconds (``time_s``), rows are numbered from 0.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.records import Count
from hrgtc.core.summary import Figure, Summary, escape

GAP_FACTOR = 2.0  # a time step longer than this many sample periods is a gap
#: Relative slack of the gap threshold: one missing sample (a step of exactly 2 periods)
#: is not a gap whatever the rounding of the times.
GAP_TOLERANCE = 1e-6
#: A partial window at the end of a segment is kept when it holds at least this fraction
#: of a full window (its mean is then as good as a window of that length); else dropped.
PARTIAL_WINDOW_FRACTION = 0.5


def min_partial_rows(rows: int) -> int:
    """Samples a window of ``rows`` cut short by a gap must hold to be kept: half a window
    (:data:`PARTIAL_WINDOW_FRACTION`) less one sample, so a burst of exactly half a window
    that lost one sample (a spike removed) still counts; never fewer than two.

    >>> min_partial_rows(500), min_partial_rows(3)
    (249, 2)
    """
    return max(2, math.ceil(PARTIAL_WINDOW_FRACTION * rows) - 1)


def is_bursty(segments: int, length_s: float, period_s: float) -> bool:
    """A duty-cycled logger: three segments or more, their (median) length much shorter
    than the (median) time from one segment's start to the next's.

    >>> is_bursty(25, 5.0, 300.0), is_bursty(3, 900.0, 1000.0), is_bursty(2, 5.0, 300.0)
    (True, False, False)
    """
    return segments >= 3 and length_s < 0.5 * period_s


def gap_limit_s(period_s: float, gap_factor: float = GAP_FACTOR) -> float:
    """Longest time step that is not a gap. [s]

    Parameters
    ----------
    period_s
        Sample period. [s]
    gap_factor
        A step longer than this many periods is a gap.

    Examples
    --------
    >>> gap_limit_s(0.02) > 0.04
    True
    """
    if not (period_s > 0.0 and math.isfinite(period_s)):
        raise InputError(f"the sample period must be positive and finite, got {period_s!r} s")
    if not gap_factor > 1.0:
        raise InputError(f"gap_factor must be above 1 sample period, got {gap_factor!r}")
    return gap_factor * period_s * (1.0 + GAP_TOLERANCE)


def is_gap(step_s: np.ndarray | float, period_s: float,
           gap_factor: float = GAP_FACTOR) -> np.ndarray:
    """True where a time step is a gap: longer than ``gap_factor`` periods (with the slack).

    The one gap test of the package. A step of exactly two periods (one missing
    sample) is not a gap; NaN steps are not gaps (other checks report them).

    Examples
    --------
    >>> is_gap(np.array([0.02, 0.04, 0.04000001, 0.05]), 0.02).tolist()
    [False, False, False, True]
    """
    limit = gap_limit_s(period_s, gap_factor)
    with np.errstate(invalid="ignore"):
        return np.asarray(step_s, dtype=np.float64) > limit


def median_period_s(time_s: np.ndarray) -> float:
    """Median positive finite time step, NaN when there is none. [s]"""
    step = np.diff(np.asarray(time_s, dtype=np.float64))
    step = step[np.isfinite(step) & (step > 0)]
    return float(np.median(step)) if step.size else math.nan


def segment_bounds(time_s: np.ndarray, period_s: float | None = None,
                   gap_factor: float = GAP_FACTOR,
                   restarts: np.ndarray | list[int] = ()) -> np.ndarray:
    """Row bounds of the contiguous segments, shape (segments, 2): ``[start, stop)``.

    Parameters
    ----------
    time_s
        Increasing sample times. [s]
    period_s
        Sample period (default: the median step). [s]
    gap_factor
        A step longer than this many periods starts a new segment.
    restarts
        Extra rows that start a segment (a logger reset, see
        :func:`hrgtc.core.time_steps.classify_time_steps`).
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    n = time_s.size
    if n == 0:
        return np.empty((0, 2), dtype=np.int64)
    period = median_period_s(time_s) if period_s is None else float(period_s)
    starts = np.flatnonzero(is_gap(np.diff(time_s), period, gap_factor)) + 1 if (
        n > 1 and math.isfinite(period)) else np.empty(0, dtype=np.int64)
    extra = np.asarray(list(restarts), dtype=np.int64)
    starts = np.unique(np.concatenate([[0], starts, extra[(extra > 0) & (extra < n)]]))
    stops = np.append(starts[1:], n)
    return np.column_stack([starts, stops]).astype(np.int64)


@dataclass(frozen=True)
class Timeline(records.Dumped):
    """The time axis of one recording: its segments, span and burst structure.

    Attributes
    ----------
    bounds
        Row bounds ``[start, stop)`` of each segment, shape (segments, 2).
    start_s, stop_s
        Time of each segment's first and last sample. [s]
    period_s
        Median sample period. [s]
    gap_factor
        A step longer than this many periods is a gap.
    """

    #: Its record (:data:`TimelineRecord`): the summary, not every bound (written, not
    #: read back).
    not_written = ("bounds", "start_s", "stop_s")
    required = ("gap_factor",)
    file_names = (("n_segments", "segments"), ("n_samples", "samples"),
                  ("is_bursty", "bursty"))
    record_order = ("n_segments", "n_samples", "period_s", "gap_factor", "span_s",
                    "recorded_s", "burst_length_s", "burst_period_s", "is_bursty")

    bounds: np.ndarray
    start_s: np.ndarray
    stop_s: np.ndarray
    period_s: float | None = math.nan
    gap_factor: float = GAP_FACTOR

    @classmethod
    def from_time(cls, time_s: np.ndarray, period_s: float | None = None,
                  gap_factor: float = GAP_FACTOR,
                  restarts: np.ndarray | list[int] = ()) -> Timeline:
        """The timeline of sample times ``time_s`` [s] (see :func:`segment_bounds`)."""
        time_s = np.asarray(time_s, dtype=np.float64)
        period = median_period_s(time_s) if period_s is None else float(period_s)
        bounds = segment_bounds(time_s, period, gap_factor, restarts)
        if bounds.shape[0] == 0:
            return cls(bounds, np.empty(0), np.empty(0), period, gap_factor)
        return cls(bounds, time_s[bounds[:, 0]], time_s[bounds[:, 1] - 1], period, gap_factor)

    @records.derived
    def n_segments(self) -> Count:
        """Number of contiguous segments."""
        return int(self.bounds.shape[0])

    @records.derived
    def n_samples(self) -> Count:
        """Number of samples."""
        return int(self.bounds[-1, 1]) if self.n_segments else 0

    @property
    def samples_per_segment(self) -> np.ndarray:
        """Samples in each segment."""
        return self.bounds[:, 1] - self.bounds[:, 0]

    @property
    def durations_s(self) -> np.ndarray:
        """Recorded duration of each segment: its samples times the period. [s]"""
        return self.samples_per_segment * self.period_s

    @records.derived
    def span_s(self) -> float:
        """Time from the first to the last sample. [s]"""
        return float(self.stop_s[-1] - self.start_s[0]) if self.n_segments else 0.0

    @records.derived
    def recorded_s(self) -> float:
        """Time covered by samples: their number times the period (a burst file: far less
        than the span). [s]"""
        return float(self.n_samples * self.period_s) if math.isfinite(self.period_s) else 0.0

    @records.derived(default=None)
    def burst_length_s(self) -> float | None:
        """Median recorded duration of a segment. [s]"""
        return float(np.median(self.durations_s)) if self.n_segments else math.nan

    @records.derived(default=None)
    def burst_period_s(self) -> float | None:
        """Median time from a segment's start to the next one's (NaN for one segment). [s]"""
        if self.n_segments < 2:
            return math.nan
        return float(np.median(np.diff(self.start_s)))

    @records.derived
    def is_bursty(self) -> bool:
        """Several segments, each much shorter than the time between their starts."""
        return is_bursty(self.n_segments, self.burst_length_s, self.burst_period_s)

    def segment_of(self, rows: np.ndarray) -> np.ndarray:
        """Index of the segment of each row."""
        return np.searchsorted(self.bounds[:, 0], np.asarray(rows), side="right") - 1

    def summary(self) -> Summary:
        """Span, recorded duration, segments and the burst structure (its text one line)."""
        figures = [Figure("span_s", "span", self.span_s, "s",
                          definition="Time from the first to the last sample."),
                   Figure("recorded_s", "recorded", self.recorded_s, "s",
                          definition="Samples times the sample period."),
                   Figure("segments", "segments", self.n_segments,
                          definition="Contiguous runs of samples between gaps.")]
        line = (f"span {_duration_field('span_s', self.span_s)}, recorded "
                f"{_duration_field('recorded_s', self.recorded_s)} in {{segments}} segment(s)")
        if self.n_segments > 1:
            figures += [Figure("burst_length_s", "segment length (median)",
                               self.burst_length_s, "s",
                               definition="Median recorded duration of a segment."),
                        Figure("burst_period_s", "segment period (median)",
                               self.burst_period_s, "s", definition="Median time from a "
                               "segment's start to the next one's.")]
            line += (f"; segments of {_duration_field('burst_length_s', self.burst_length_s)}"
                     f" (median) every {_duration_field('burst_period_s', self.burst_period_s)}")
        return Summary("time axis", (("time axis", tuple(figures)),), layout=(line,))


#: The record of :class:`Timeline`, generated from its fields and figures.
TimelineRecord = records.record_of(
    Timeline, doc="The record of :class:`Timeline` (``null``: a figure that is not defined, "
    "e.g. the\nburst period of one segment).")


def _duration_field(name: str, seconds: float) -> str:
    """A duration figure in a layout: ``{name:.6g} s``, hours beside it from an hour on,
    ``?`` when it is not finite."""
    if not math.isfinite(seconds):
        return "?"
    hours = escape(f" ({seconds / 3600.0:.3g} h)") if seconds >= 3600.0 else ""
    return "{" + name + ":.6g} s" + hours


#: Key of a recording's ``metadata.extra`` listing the times [s] where the logger restarted
#: (its clock reset to about zero, :mod:`hrgtc.core.time_steps`): each starts a new run.
RESTARTS_KEY = "restarts_s"


def restart_rows(time_s: np.ndarray, restarts_s: Any = ()) -> np.ndarray:
    """Rows of ``time_s`` that start a new run after a logger restart.

    ``restarts_s`` are the (repaired) times of the restarts' first samples, as the reader
    lists them in ``metadata.extra["restarts_s"]`` (:data:`RESTARTS_KEY`); a chunk holds
    the rows of those that fall in it.

    Examples
    --------
    >>> restart_rows(np.array([0.0, 1.0, 50.0, 51.0]), [50.0]).tolist()
    [2]
    """
    times = np.asarray(list(restarts_s or ()), dtype=np.float64)
    if not times.size:
        return np.empty(0, dtype=np.int64)
    return np.flatnonzero(np.isin(np.asarray(time_s, dtype=np.float64), times))


#: Relative slack of the settling test: a sample ``warmup_s`` after the filter started is
#: settled whether its time comes from a difference of times (Python) or a sum of steps
#: (the C export's ``dt_s``), whose roundings differ in the last digits.
SETTLE_TOLERANCE = 1e-9


def settle_threshold_s(warmup_s: float) -> float:
    """Seconds since the df/dt filter (re)started from which a sample is settled: ``warmup_s``
    less a relative :data:`SETTLE_TOLERANCE`. Training, the compensator (numpy, numba, C)
    and the evaluation all compare ``elapsed >= settle_threshold_s(warmup_s)``. [s]

    >>> settle_threshold_s(50.0) < 50.0 < settle_threshold_s(50.0) + 1e-6
    True
    """
    return float(warmup_s) * (1.0 - SETTLE_TOLERANCE)


def seconds_since_power_on(time_s: np.ndarray, bounds: np.ndarray | None = None,
                           restart_each_segment: bool = False) -> np.ndarray:
    """Time since the logger (and the gyro) started, for the warm-up skip. [s]

    Parameters
    ----------
    time_s
        Sample times. [s]
    bounds
        Segment bounds (:func:`segment_bounds`); needed with ``restart_each_segment``.
    restart_each_segment
        Each segment is a power-on (the gyro was switched off between them): time is
        counted from the segment's first sample. Default: from the recording's first
        sample, once (a duty-cycled logger does not restart the gyro).

    Examples
    --------
    >>> t = np.array([0.0, 1.0, 2.0, 100.0, 101.0])
    >>> seconds_since_power_on(t).tolist()
    [0.0, 1.0, 2.0, 100.0, 101.0]
    >>> seconds_since_power_on(t, segment_bounds(t, 1.0), True).tolist()
    [0.0, 1.0, 2.0, 0.0, 1.0]
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    if time_s.size == 0:
        return time_s.copy()
    if not restart_each_segment:
        return time_s - time_s[0]
    if bounds is None:
        bounds = segment_bounds(time_s)
    first = np.repeat(time_s[bounds[:, 0]], bounds[:, 1] - bounds[:, 0])
    return time_s - first


@dataclass(frozen=True)
class Windows:
    """Windows of a time axis that never span a gap.

    Attributes
    ----------
    labels
        Window index of each row, -1 for rows in no window (a dropped partial window).
    n_windows
        Number of windows (full and kept partial).
    n_partial_kept, n_partial_dropped
        Partial windows at segment ends kept (at least
        :data:`PARTIAL_WINDOW_FRACTION` of a window) and dropped.
    rows_dropped
        Rows of the dropped partial windows.
    """

    labels: np.ndarray
    n_windows: int
    n_partial_kept: int
    n_partial_dropped: int
    rows_dropped: int

    def means(self, values: np.ndarray) -> np.ndarray:
        """Mean of ``values`` (rows, or rows × columns) in each window."""
        values = np.asarray(values, dtype=np.float64)
        keep = self.labels >= 0
        labels = self.labels[keep]
        counts = np.bincount(labels, minlength=self.n_windows).astype(np.float64)
        if values.ndim == 1:
            return np.bincount(labels, values[keep], self.n_windows) / counts
        return np.column_stack([np.bincount(labels, values[keep, k], self.n_windows) / counts
                                for k in range(values.shape[1])])


def windows(time_s: np.ndarray, window_s: float, bounds: np.ndarray | None = None,
            period_s: float | None = None,
            partial_fraction: float = PARTIAL_WINDOW_FRACTION) -> Windows:
    """Non-overlapping windows of ``window_s`` seconds inside each segment.

    A window starts at a segment's first sample (or where the previous window ended)
    and holds the samples of the next ``window_s`` seconds; it never spans a gap. The
    last, partial window of a segment is kept when its samples cover at least
    ``partial_fraction`` of a window, else its rows are dropped (counted).

    Examples
    --------
    >>> t = np.r_[np.arange(0.0, 25.0), np.arange(100.0, 104.0)]  # 1 Hz, a gap
    >>> w = windows(t, 10.0)
    >>> w.n_windows, w.n_partial_kept, w.n_partial_dropped, w.rows_dropped
    (3, 1, 1, 4)
    """
    if not (window_s > 0.0 and math.isfinite(window_s)):
        raise InputError(f"the window length must be positive and finite, got {window_s!r} s")
    time_s = np.asarray(time_s, dtype=np.float64)
    period = median_period_s(time_s) if period_s is None else float(period_s)
    if bounds is None:
        bounds = segment_bounds(time_s, period)
    labels = np.full(time_s.size, -1, dtype=np.int64)
    rows_per = max(1, round(window_s / period)) if math.isfinite(period) else 1
    need = partial_fraction * rows_per
    n = kept = dropped = rows_dropped = 0
    for start, stop in bounds:
        size = int(stop - start)
        full, rest = divmod(size, rows_per)
        if full:
            labels[start:start + full * rows_per] = n + np.arange(full).repeat(rows_per)
            n += full
        if rest:
            if rest >= need:
                labels[stop - rest:stop] = n
                n += 1
                kept += 1
            else:
                dropped += 1
                rows_dropped += rest
    return Windows(labels, n, kept, dropped, rows_dropped)


def parse_time_bound(text: str | float | None, time_origin: str | None = None) -> float | None:
    """``--start``/``--end``: seconds since the file's start, or an ISO clock time.

    Parameters
    ----------
    text
        A number of seconds (``"600"``, ``"1.5e3"``) or an ISO 8601 time
        (``"2020-03-07T16:30"``), which needs the file's clock origin.
    time_origin
        ISO time of the file's first sample (the metadata's ``time_origin`` of a file
        with clock times).

    Returns
    -------
    float or None
        Seconds since the file's first sample (None for no bound). [s]
    """
    if text is None or (isinstance(text, str) and not text.strip()):
        return None
    if isinstance(text, (int, float)):
        return float(text)
    try:
        return float(text)
    except ValueError:
        pass
    try:
        when = np.datetime64(text.strip().replace(" ", "T"), "ns")
    except ValueError:
        raise InputError(
            f"--start/--end {text!r} is neither seconds since the file's start (e.g. 600) nor "
            "an ISO clock time (e.g. 2020-03-07T16:30:00)") from None
    if time_origin is None:
        raise InputError(
            f"--start/--end {text!r} is a clock time but the file has no clock times (its time "
            "column counts seconds); give seconds since the file's start instead, e.g. --start 600")
    origin = np.datetime64(time_origin.replace(" ", "T"), "ns")
    return float((when - origin) / np.timedelta64(1, "ns")) * 1e-9


def slice_rows(time_s: np.ndarray, start_s: float | None = None,
               end_s: float | None = None) -> tuple[int, int]:
    """Rows ``[first, stop)`` with ``start_s <= time - time[0] < end_s``.

    Bounds are seconds since the file's first sample (None: open).

    Examples
    --------
    >>> slice_rows(np.arange(10.0) + 5.0, 2.0, 6.0)
    (2, 6)
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    if time_s.size == 0:
        return 0, 0
    if start_s is not None and end_s is not None and not end_s > start_s:
        raise InputError(f"--end ({end_s:g} s) must be after --start ({start_s:g} s)")
    since = time_s - time_s[0]
    first = 0 if start_s is None else int(np.searchsorted(since, start_s, side="left"))
    stop = time_s.size if end_s is None else int(np.searchsorted(since, end_s, side="left"))
    return first, max(first, stop)


def time_blocks(time_s: np.ndarray, n_blocks: int, bounds: np.ndarray | None = None,
                ) -> list[tuple[int, int]]:
    """``n_blocks`` contiguous row ranges of about equal *recorded time*.

    Cuts fall on segment bounds when there are at least ``n_blocks`` segments (a
    burst is never cut in two), else inside segments. For leave-one-block-out
    cross-validation and held-out splits of one long file.

    Examples
    --------
    >>> t = np.r_[np.arange(0.0, 5.0), np.arange(300.0, 305.0), np.arange(600.0, 605.0),
    ...           np.arange(900.0, 905.0)]
    >>> time_blocks(t, 2)
    [(0, 10), (10, 20)]
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    n = time_s.size
    if n_blocks < 1 or n_blocks > max(n, 1):
        raise InputError(f"cannot cut {n} samples into {n_blocks} blocks")
    if bounds is None:
        bounds = segment_bounds(time_s)
    if bounds.shape[0] >= n_blocks:
        sizes = bounds[:, 1] - bounds[:, 0]
        cumulative = np.cumsum(sizes)
        targets = np.arange(1, n_blocks) * n / n_blocks
        # the segment end nearest each target, one per block
        ends = cumulative[:-1]
        cuts = []
        for target in targets:
            after = cuts[-1] if cuts else 0
            later = ends[ends > after]
            if later.size:  # the segment end nearest the target, after the last cut
                cut = int(later[np.argmin(np.abs(later - target))])
            else:  # no segment end left (segments of very unequal sizes): cut inside one
                cut = max(after + 1, round(float(target)))
            cuts.append(min(cut, n - (n_blocks - 1 - len(cuts))))
    else:
        cuts = [round(k * n / n_blocks) for k in range(1, n_blocks)]
    edges = [0, *cuts, n]
    return [(int(a), int(b)) for a, b in itertools.pairwise(edges)]


def holdout_rows(time_s: np.ndarray, holdout_s: float | None = None,
                 holdout_fraction: float | None = None,
                 bounds: np.ndarray | None = None) -> int:
    """First row of the held-out last part of a recording (by recorded time).

    Exactly one of ``holdout_s`` (recorded seconds at the end) and
    ``holdout_fraction`` (of the recorded time) is given. The cut moves to the
    nearest segment start, so no burst is cut in two (on a continuous file it falls
    where asked).
    """
    if (holdout_s is None) == (holdout_fraction is None):
        raise InputError("give exactly one of --holdout-s and --holdout-fraction")
    time_s = np.asarray(time_s, dtype=np.float64)
    n = time_s.size
    if bounds is None:
        bounds = segment_bounds(time_s)
    period = median_period_s(time_s)
    if holdout_fraction is not None:
        if not 0.0 < holdout_fraction < 1.0:
            raise InputError(
                f"--holdout-fraction must be between 0 and 1, got {holdout_fraction!r}")
        held = round(holdout_fraction * n)
    else:
        if not holdout_s > 0.0:
            raise InputError(f"--holdout-s must be positive, got {holdout_s!r}")
        held = round(holdout_s / period)
    cut = n - held
    if bounds.shape[0] > 2:
        starts = bounds[1:, 0]
        cut = int(starts[np.argmin(np.abs(starts - cut))])
    if not 0 < cut < n:
        raise InputError(
            f"the held-out part ({held} of {n} samples) leaves nothing to train or to test on; "
            "hold out less")
    return int(cut)

