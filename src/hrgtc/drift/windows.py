"""Window means of the drift-model terms over training runs, streamed chunk by chunk.

The regression of :mod:`hrgtc.drift.drift_model` runs on non-overlapping window
means (10 s by default) of the candidate terms and the measured bias: raw 200 Hz
residuals are too autocorrelated for F-tests. Each run's variables come from a
causal :class:`~hrgtc.drift.features.FeatureStream` that keeps its state across
chunks.

Time, not samples (see :mod:`hrgtc.core.timeline`):

* the warm-up is ``warmup_s`` seconds on the time axis, applied once from the run's
  first sample (a duty-cycled logger does not restart the gyro); with
  ``gaps="split"`` the filter restarts after every gap, so each segment settles for
  ``warmup_s`` again; ``restart_each_segment=True`` says each segment is a power-on;
* a *run* is a file, or the part of one after a logger restart (its clock reset to
  about zero, listed by the reader in ``metadata.extra["restarts_s"]``, see
  :func:`hrgtc.core.timeline.restart_rows`): a restart starts the df/dt filter again at
  rest and the warm-up again, and gets its own offset with ``offsets="run"``
  (:attr:`TrainingWindows.power_run`); so does every segment when the user says each
  segment is a restart (``gaps="split"`` or ``restart_each_segment=True``);
* a window never spans a gap: the partial window at the end of a segment (and of the
  run) is kept when it holds at least half a window
  (:data:`~hrgtc.core.timeline.PARTIAL_WINDOW_FRACTION`), else dropped; a window never
  reaches across samples left out as not at rest either (its partial start is dropped);
* rows left out are counted by reason in :attr:`TrainingWindows.dropped`;
* the extremes of each variable over the samples used (settled, at rest, in the file:
  spikes removed by the reader are not) are kept in :attr:`TrainingWindows.extremes`:
  the model's trained ranges, so its own training file is inside them by construction
  (the window means' extremes are narrower than the samples').
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.core.progress import Progress
from hrgtc.core.timeline import (
    RESTARTS_KEY,
    is_gap,
    min_partial_rows,
    restart_rows,
    settle_threshold_s,
)
from hrgtc.drift.features import FeatureSettings, FeatureStream, Term, variables_for
from hrgtc.drift.rate_checks import filtered_levels, rate_filter_problems, warn_rate_filter
from hrgtc.recording import Recording

RunSource = Recording | Callable[[], Iterator[Recording]]
#: Columns averaged into the windows beside the terms, where logged: the accelerometer
#: axes (orientation of each still window) and the user's orientation label.
_EXTRA_COLUMNS = ("accel_x", "accel_y", "accel_z", "orientation")


@dataclass(frozen=True)
class TrainingWindows:
    """Window means used to fit a drift model, one row per window.

    Attributes
    ----------
    time_s
        Window centre times, per run. [s]
    run
        Index of the run each window came from.
    terms
        Raw (unscaled) window means of each candidate term, shape (windows, terms).
    bias_dph
        Window means of the measured bias (rate minus input rate). [°/h]
    variables
        Window means of each variable (f [Hz], df [Hz/s], ...).
    n_samples
        Samples read from the runs.
    sources
        Name (file) of each run, in run order.
    n_not_at_rest
        Samples left out because they were not at rest (:mod:`hrgtc.drift.rest`).
    accel
        Window means of ``accel_x/y/z`` (shape (windows, 3)) when every run logs them.
    orientation
        Window means of the user's ``orientation`` label when every run logs it.
    dropped
        Reason -> samples read but in no window (``warmup``, ``partial_windows``; the
        reasons of :data:`hrgtc.core.accounting.REASONS`).
    segments
        Contiguous segments found in the runs (gaps split them).
    power_run
        Index of the power-on run of each window: a file, or the part of one after a
        logger restart (every segment, when each is said to be a restart); the groups of
        ``offsets="run"``. None: the file index :attr:`run`.
    power_runs
        Name of each power-on run (the file's, with `` run K`` for the parts of a file
        that restarted).
    extremes
        Variable -> (min, max) over the samples used: after the warm-up, at rest (NaN
        ignored; ``(inf, -inf)`` when none is finite). The trained ranges.
    """

    time_s: np.ndarray
    run: np.ndarray
    terms: np.ndarray
    bias_dph: np.ndarray
    variables: dict[str, np.ndarray]
    n_samples: int
    sources: tuple[str, ...] = ()
    n_not_at_rest: int = 0
    accel: np.ndarray | None = None
    orientation: np.ndarray | None = None
    dropped: dict[str, int] = field(default_factory=dict)
    segments: int = 0
    power_run: np.ndarray | None = None
    power_runs: tuple[str, ...] = ()
    extremes: dict[str, tuple[float, float]] = field(default_factory=dict)


class _WindowMeans:
    """Means of non-overlapping windows of ``rows`` samples over consecutive chunks.

    A window never spans a segment break (a gap): the partial window before it is kept
    when it holds at least :data:`PARTIAL_WINDOW_FRACTION` of ``rows``, else dropped and
    counted. At a cut (samples left out as not at rest) the partial window is dropped.

    Each chunk is averaged at once, whatever its number of segments (a burst file has
    thousands per chunk): the window bounds come from array arithmetic and the sums of
    every window from one ``numpy.add.reduceat``, which runs down contiguous columns
    when the block is column-major (as :func:`window_means` builds it).
    """

    def __init__(self, rows: int) -> None:
        self.rows = rows
        self.min_rows = min(rows, min_partial_rows(rows))
        self._carry: np.ndarray | None = None  # rows of the open window, from earlier chunks
        self.partial_dropped_rows = 0

    def transform(self, block: np.ndarray, breaks: Sequence[int] | np.ndarray = (),
                  cuts: Sequence[int] | np.ndarray = ()) -> np.ndarray:
        """Window means of ``block``; ``breaks``: its rows that start a new segment,
        ``cuts``: its rows that follow left-out samples (a row that is both is a break)."""
        n, width = block.shape
        breaks = _rows_inside(breaks, n)
        cuts = _rows_inside(cuts, n)
        if cuts.size:
            cuts = cuts[~np.isin(cuts, breaks, assume_unique=True)]
            starts = _rows_inside(np.concatenate([breaks, cuts]), n)
            at_break = np.isin(starts, breaks, assume_unique=True)
        else:
            starts, at_break = breaks, np.ones(breaks.size, dtype=bool)
        out = []
        if starts.size and starts[0] == 0:  # the carry's segment ends before the block
            out.append(self.flush() if at_break[0] else self.drop())
            starts, at_break = starts[1:], at_break[1:]
        carry = self._carry if self._carry is not None else np.empty((0, width))
        # segment k holds rows [begin[k], end[k]) of the block; the first starts with the
        # carry (at a negative row)
        begin = np.concatenate([[-carry.shape[0]], starts])
        end = np.append(starts, n)
        complete = (end - begin) // self.rows
        tail = begin + complete * self.rows  # the partial window at each segment's end
        # the partial windows before a break are kept when long enough, else counted;
        # those before a cut are counted; the last segment's is the new carry
        tail_rows = end[:-1] - tail[:-1]
        kept = at_break & (tail_rows > 0) & (tail_rows >= self.min_rows)
        self.partial_dropped_rows += int(tail_rows[~kept].sum())
        windows = int(complete.sum())
        offset = np.arange(windows) - np.repeat(np.cumsum(complete) - complete, complete)
        first = np.repeat(begin, complete) + offset * self.rows
        low = np.concatenate([first, tail[:-1][kept]])
        high = np.concatenate([first + self.rows, end[:-1][kept]])
        order = np.argsort(low, kind="stable")
        low, high = low[order], high[order]
        if tail[-1] >= 0:
            self._carry = block[tail[-1]:].copy()
        else:  # no window closed: the block joins the carry
            self._carry = np.concatenate([carry, block])
        if low.size:
            bounds = np.column_stack([np.maximum(low, 0), high]).ravel()
            sums = np.add.reduceat(block, bounds[bounds < n], axis=0)[::2]
            if low[0] < 0:  # the first window began in the carry
                sums[0] += carry.sum(axis=0)
            out.append(sums / (high - low)[:, None])
        out = [o for o in out if o.shape[0]]
        return np.concatenate(out) if out else np.empty((0, width))

    def drop(self) -> np.ndarray:
        """A cut: the partial window is dropped (counted); no window."""
        width = 0
        if self._carry is not None:
            self.partial_dropped_rows += self._carry.shape[0]
            width = self._carry.shape[1]
        self._carry = None
        return np.empty((0, width))

    def flush(self) -> np.ndarray:
        """End of a segment: the partial window, kept when long enough, else counted."""
        carry, self._carry = self._carry, None
        if carry is None or carry.shape[0] == 0:
            return np.empty((0, 0 if carry is None else carry.shape[1]))
        if carry.shape[0] >= self.min_rows:
            return carry.mean(axis=0, keepdims=True)
        self.partial_dropped_rows += carry.shape[0]
        return np.empty((0, carry.shape[1]))


def _rows_inside(rows: Sequence[int] | np.ndarray, n: int) -> np.ndarray:
    """The distinct ``rows`` in ``[0, n)``, sorted (without ``numpy.unique``'s hashing,
    milliseconds for the thousands of breaks of a burst file)."""
    rows = np.asarray(rows, dtype=np.int64).ravel()
    rows = rows[(rows >= 0) & (rows < n)]
    if rows.size > 1 and not np.all(rows[1:] > rows[:-1]):
        rows = np.sort(rows)
        rows = rows[np.concatenate([[True], rows[1:] != rows[:-1]])]
    return rows


def _used_rows(use: np.ndarray, columns: Sequence[Any], more: Iterator[Any],
               n_more: int) -> np.ndarray:
    """The rows where ``use`` of ``columns`` then ``more`` (``n_more`` of them; a scalar
    fills its column), as one column-major float64 block: :class:`_WindowMeans` sums it
    down contiguous columns (a row-major block strides, 5 to 20 times slower over a few
    million rows)."""
    rows = int(np.count_nonzero(use))
    first = int(np.argmax(use)) if rows else 0
    # one stretch of used rows (the warm-up left out at the start): a slice, no mask
    pick = slice(first, first + rows) if use[first:first + rows].all() else use
    block = np.empty((rows, len(columns) + n_more), order="F")
    for k, column in enumerate((*columns, *more)):
        column = np.asarray(column, dtype=np.float64)
        block[:, k] = column if column.ndim == 0 else column[pick]
    return block


def _iter_run(source: RunSource) -> Iterator[Recording]:
    if isinstance(source, Recording):
        yield source
    else:
        yield from source()


@dataclass(frozen=True)
class Windowing:
    """How the training runs are cut into windows (one settings object, passed whole).

    Attributes
    ----------
    window_s
        Window length. [s]
    extra_variables
        Variables whose window means are kept although no term uses them (their
        training ranges: ``df`` for the range warnings of a model without df terms).
    gaps
        ``"split"``: the df/dt filter restarts after every gap (and settles for
        ``warmup_s`` again); otherwise (``"bridge"``, ``"ignore"``, ``"error"``) it
        carries across. Windows never span a gap either way.
    restart_each_segment
        Each segment is a power-on: the warm-up is skipped after every gap.
    """

    window_s: float = 10.0
    extra_variables: Sequence[str] = ()
    gaps: str = "bridge"
    restart_each_segment: bool = False


def window_means(
    runs: Sequence[RunSource],
    settings: FeatureSettings,
    terms: Sequence[Term],
    windowing: Windowing = Windowing(),
    progress: Progress | None = None,
    thermometer: Any = None,
    keep: Sequence[np.ndarray | None] | None = None,
) -> TrainingWindows:
    """Window means of candidate terms and measured bias over training runs.

    Parameters
    ----------
    runs
        Each a :class:`Recording`, or a callable returning an iterator of
        consecutive chunks of one run (e.g. ``lambda: recording.iter_chunks(path)``).
    settings
        Feature settings (reference frequency, rate filter, warm-up).
    terms
        Candidate terms.
    windowing
        Window length, extra variables and gap handling (:class:`Windowing`).
    progress
        Optional ``callback(samples_done, samples_total_or_0)``.
    thermometer
        The unit's thermometer, for the gradient ``g`` (see :class:`FeatureStream`).
    keep
        Per run, True for each sample at rest (:func:`hrgtc.drift.rest.run_rest`) or
        None to use every sample: the windows are means of kept samples only and never
        reach across a left-out stretch, so every trained range comes from the samples
        actually used.
    """
    return window_means_at(runs, settings, terms, windowing, progress, thermometer, keep)[0]


class _Windows:
    """What one warm-up keeps of the pass of :func:`window_means_at`: its windows, its
    trained ranges and its counts (the rows it uses differ only by the warm-up)."""

    def __init__(self, warmup_s: float, n_variables: int) -> None:
        self.warmup_s = warmup_s
        self.threshold_s = settle_threshold_s(warmup_s)
        self.time: list[np.ndarray] = []
        self.power: list[np.ndarray] = []
        self.means: list[np.ndarray] = []  # columns bias, variables, extra, terms
        self.run: list[np.ndarray] = []
        # per variable: smallest and largest used sample (the trained ranges)
        self.lowest = np.full(n_variables, np.inf)
        self.highest = np.full(n_variables, -np.inf)
        self.warm = self.partial = self.left_out = 0
        self.averager: _WindowMeans | None = None

    def collect(self, means: np.ndarray, index: int) -> None:
        """Keep window means: columns time, power-on run, then the rest."""
        if means.shape[0]:
            self.time.append(means[:, 0])
            self.power.append(np.round(means[:, 1]).astype(np.int64))
            self.means.append(means[:, 2:])
            self.run.append(np.full(means.shape[0], index))


def window_means_at(
    runs: Sequence[RunSource],
    settings: FeatureSettings,
    terms: Sequence[Term],
    windowing: Windowing = Windowing(),
    progress: Progress | None = None,
    thermometer: Any = None,
    keep: Sequence[np.ndarray | None] | None = None,
    warmups_s: Sequence[float] | None = None,
) -> tuple[TrainingWindows, ...]:
    """:func:`window_means` for each warm-up of ``warmups_s`` (default
    ``(settings.warmup_s,)``) from one reading of the runs: the variables do not depend
    on the warm-up, only which rows are settled does, so each result is what
    :func:`window_means` gives with ``settings.warmup_s`` set to that warm-up (the drift
    fit's rate-free refit, ``warmup_s=0``, costs no second pass)."""
    window_s = windowing.window_s
    restart_each_segment = windowing.restart_each_segment
    variables = variables_for(terms)
    variables += tuple(v for v in windowing.extra_variables if v not in variables)
    if not window_s > 0:
        raise InputError(f"window_s must be a positive number of seconds, got {window_s!r}")
    warmups = (settings.warmup_s,) if warmups_s is None else tuple(warmups_s)
    split = windowing.gaps == "split"
    power_names: list[str] = []
    kept_by = [_Windows(w, len(variables)) for w in warmups]
    total = segments = 0
    sources: list[str] = []
    extra: tuple[str, ...] | None = None
    problems: list[str] = []

    for index, source in enumerate(runs):
        stream = FeatureStream(settings, variables, thermometer)
        window_rows = 0  # windows in rows at this run's own rate
        input_rate = None
        run_keep = None if keep is None else keep[index]
        row = 0
        last_time: float | None = None
        power_on: float | None = None  # time the warm-up counts from
        last_used = True  # the previous row was used (not left out as not at rest)
        power = len(power_names)  # index of the power-on run of the next row
        first_power = power
        for chunk in _iter_run(source):
            if not window_rows:
                rate_hz = chunk.metadata.sample_rate_hz
                window_rows = round(window_s * rate_hz)
                if window_rows < 1:
                    raise InputError(f"window_s={window_s:g} s holds no sample at {rate_hz:g} Hz "
                                     f"({chunk.source or 'run ' + str(index)}); pass a longer "
                                     "--window-s")
                for kept_windows in kept_by:
                    kept_windows.averager = _WindowMeans(window_rows)
                period = 1.0 / rate_hz
            if input_rate is None:
                input_rate = chunk.metadata.input_rate_dph
                sources.append(chunk.source or f"run {index}")
                power_names.append(sources[-1])
                levels = filtered_levels(chunk, variables_for(terms))
                if levels and not split:  # the terms use a rate: can the filter follow?
                    # (up to a logger restart: the filter restarts there)
                    head = restart_rows(chunk.time_s, chunk.metadata.extra.get(RESTARTS_KEY))
                    stop = int(head[0]) if head.size else len(chunk)
                    problems += rate_filter_problems(
                        chunk.time_s[:stop], {k: v[:stop] for k, v in levels.items()},
                        settings.rate_tau_s, where=chunk.source or "",
                        thermometer_source=getattr(thermometer, "source", "resonator"))
            if extra is None:  # the accelerometer and label columns, where every run has them
                extra = tuple(c for c in _EXTRA_COLUMNS if c in chunk)
            time = chunk.time_s
            if not len(time):
                continue
            starts = np.flatnonzero(is_gap(np.diff(time), period)) + 1
            if last_time is None:
                power_on = float(time[0])
                segments += 1
            elif is_gap(time[0] - last_time, period):
                starts = np.concatenate([[0], starts])
            # logger restarts (new runs): always; every segment when each is a restart
            restarts = restart_rows(time, chunk.metadata.extra.get(RESTARTS_KEY))
            if last_time is None:
                restarts = restarts[restarts > 0]
            if restarts.size:
                starts = np.union1d(starts, restarts)
            starts = starts.astype(np.int64)
            segments += starts.size
            last_time = float(time[-1])
            power_starts = starts if (split or restart_each_segment) else restarts
            fresh = starts if split else restarts  # rows where the filter restarts at rest
            if fresh.size:
                edges = [0, *fresh[fresh > 0].tolist(), len(chunk)]
                parts = []
                for k in range(len(edges) - 1):
                    if k > 0 or fresh[0] == 0:
                        stream = FeatureStream(settings, variables, thermometer)
                    parts.append(stream.transform(chunk.slice(edges[k], edges[k + 1])))
                values = {v: np.concatenate([p[v] for p in parts]) for v in parts[0]}
            else:
                values = stream.transform(chunk)
            # seconds since power-on (or since the filter restarted): the warm-up skip
            origin = np.full(len(time), power_on)
            if power_starts.size:
                lengths = np.diff(np.append(power_starts, len(time)))
                origin[power_starts[0]:] = np.repeat(time[power_starts], lengths)
                power_on = float(time[power_starts[-1]])
            elapsed = time - origin
            # the power-on run of each row (a new one at each restart)
            run_of_row = power + np.cumsum(np.bincount(power_starts, minlength=len(time)))
            power += power_starts.size
            while len(power_names) <= power:
                power_names.append(f"{sources[-1]} run {len(power_names) - first_power + 1}")
            rate = chunk["input_rate_dph"] if "input_rate_dph" in chunk else input_rate
            kept = None if run_keep is None else run_keep[row:row + len(chunk)]
            row += len(chunk)
            rested = np.ones(len(chunk), dtype=bool) if kept is None else kept.astype(bool)
            previous = np.concatenate([[last_used], rested[:-1]])
            resumed = np.flatnonzero(rested & ~previous)
            last_used = bool(rested[-1])
            cache: dict[tuple[str, int], np.ndarray] = {}
            columns = [
                chunk.time_s,
                run_of_row,
                chunk.rate_dph - rate,
                *(values[v] for v in variables),
                *(chunk[c] if c in chunk else np.nan for c in extra),
                *(t.evaluate(values, cache) for t in terms),  # the design matrix's columns
            ]
            for windows in kept_by:
                settled = elapsed >= windows.threshold_s
                if kept is not None:
                    windows.left_out += int(np.count_nonzero(~kept & settled))
                use = settled & rested
                before = np.cumsum(use) - use  # rows used before each row
                windows.warm += int(np.count_nonzero(~settled))
                block = _used_rows(use, columns, iter(()), 0)
                if block.shape[0]:  # down the block's contiguous columns; NaN ignored
                    used = block[:, 3:3 + len(variables)]
                    np.fmin(windows.lowest, np.fmin.reduce(used, axis=0), out=windows.lowest)
                    np.fmax(windows.highest, np.fmax.reduce(used, axis=0), out=windows.highest)
                assert windows.averager is not None
                windows.collect(windows.averager.transform(block, before[starts],
                                                           before[resumed]), index)
            total += len(chunk)
            if progress is not None:
                progress(total, 0)
        if not window_rows:  # a run without rows
            continue
        for windows in kept_by:
            assert windows.averager is not None
            windows.collect(windows.averager.flush(), index)
            windows.partial += windows.averager.partial_dropped_rows
        if power > first_power:  # the file restarted: name its first run too
            power_names[first_power] = f"{sources[-1]} run 1"
    warn_rate_filter(problems)
    return tuple(_training_windows(w, windowing, variables, extra or (), total,
                                   sources, segments, power_names)
                 for w in kept_by)


def _training_windows(windows: _Windows, windowing: Windowing,
                      variables: tuple[str, ...], extra: tuple[str, ...], total: int,
                      sources: list[str], segments: int,
                      power_names: list[str]) -> TrainingWindows:
    """The :class:`TrainingWindows` of one warm-up's windows."""
    split, window_s, warmup_s = windowing.gaps == "split", windowing.window_s, windows.warmup_s
    if not windows.time:
        restart = " after every gap (--gaps split restarts the filter)" if split else ""
        raise CalibrationError(
            f"the drift runs hold no complete {window_s:g} s window after the "
            f"{warmup_s:g} s filter warm-up{restart}; give longer runs"
            + (", or --gaps bridge for a burst logger" if split else "")
        )
    dropped = {k: v for k, v in (("warmup", windows.warm), ("partial_windows", windows.partial))
               if v}
    means = np.concatenate(windows.means)
    first = 1 + len(variables)
    columns = means[:, first:first + len(extra)]
    named = {c: columns[:, k] for k, c in enumerate(extra) if np.all(np.isfinite(columns[:, k]))}
    accel = None
    if all(c in named for c in _EXTRA_COLUMNS[:3]):
        accel = np.column_stack([named[c] for c in _EXTRA_COLUMNS[:3]])
    return TrainingWindows(
        n_not_at_rest=windows.left_out,
        accel=accel,
        orientation=named.get("orientation"),
        time_s=np.concatenate(windows.time),
        run=np.concatenate(windows.run),
        terms=np.ascontiguousarray(means[:, first + len(extra):]),
        bias_dph=np.ascontiguousarray(means[:, 0]),
        variables={v: np.ascontiguousarray(means[:, 1 + k]) for k, v in enumerate(variables)},
        n_samples=total,
        sources=tuple(sources),
        dropped=dropped,
        segments=segments,
        power_run=np.concatenate(windows.power),
        power_runs=tuple(power_names),
        extremes={v: (float(windows.lowest[k]), float(windows.highest[k]))
                  for k, v in enumerate(variables)},
    )
