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
    restart_rows,
    settle_threshold_s,
)
from hrgtc.drift.features import FeatureSettings, FeatureStream, Term, variables_for
from hrgtc.drift.rate_checks import filtered_levels, rate_filter_problems, warn_rate_filter
from hrgtc.drift.run_windows import read_in_workers, workers_for
from hrgtc.drift.window_averager import _WindowMeans
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
    job = WindowJob(settings, terms, windowing, progress, thermometer, keep, warmups_s)
    result = window_means_jointly(runs, [job])[0]
    if isinstance(result, BaseException):
        raise result
    return result


def window_means_jointly(runs: Sequence[RunSource], jobs: Sequence[WindowJob]
                         ) -> list[tuple[TrainingWindows, ...] | Exception]:
    """The results of several :func:`window_means_at` on the same runs from one reading of
    them (the drift model and the housing baseline: one pass, not one per fit). Each job's
    result is what its own :func:`window_means_at` gives, or the error it raised (the
    first job's error is raised at once: the later ones are never needed without it).
    Runs read from large files are read in worker processes, one run each
    (:mod:`hrgtc.drift.run_windows`), with the same result."""
    out: list[tuple[TrainingWindows, ...] | Exception | None] = [None] * len(jobs)
    live = list(range(len(jobs)))

    def each(step: Callable[[WindowJob], None]) -> None:
        for k in list(live):
            try:
                step(jobs[k])
            except Exception as exc:  # the job's own error, given back
                if k == 0:
                    raise
                out[k] = exc
                live.remove(k)

    workers = workers_for(runs)
    if workers > 1:  # each run's pass in a worker process (every core)
        read_in_workers(runs, jobs, live, out, workers, _iter_run)
    for index, source in enumerate(runs if workers < 2 else ()):
        each(lambda job, index=index: job.start_run(index))
        for chunk in _iter_run(source):
            each(lambda job, chunk=chunk: job.add(chunk))
            if not live:
                break
        each(lambda job: job.end_run())
    each(lambda job: out.__setitem__(jobs.index(job), job.finish()))
    return out  # type: ignore[return-value]


class WindowJob:
    """One :func:`window_means_at` fed a chunk at a time (:func:`window_means_jointly`):
    parameters as :func:`window_means_at`'s."""

    def __init__(self, settings: FeatureSettings, terms: Sequence[Term],
                 windowing: Windowing = Windowing(), progress: Progress | None = None,
                 thermometer: Any = None, keep: Sequence[np.ndarray | None] | None = None,
                 warmups_s: Sequence[float] | None = None) -> None:
        window_s = windowing.window_s
        variables = variables_for(terms)
        variables += tuple(v for v in windowing.extra_variables if v not in variables)
        if not window_s > 0:
            raise InputError(f"window_s must be a positive number of seconds, got {window_s!r}")
        warmups = (settings.warmup_s,) if warmups_s is None else tuple(warmups_s)
        self.settings, self.terms, self.windowing = settings, terms, windowing
        self.progress, self.thermometer, self.keep = progress, thermometer, keep
        self.variables = variables
        self.split = windowing.gaps == "split"
        self.power_names: list[str] = []
        self.kept_by = [_Windows(w, len(variables)) for w in warmups]
        self.total = self.segments = 0
        self.sources: list[str] = []
        self.extra: tuple[str, ...] | None = None
        self.problems: list[str] = []
        self.run = _RunState(0, FeatureStream(settings, variables, thermometer), None, 0)

    def start_run(self, index: int) -> None:
        """Before the first chunk of run ``index``."""
        self.run = _RunState(index, FeatureStream(self.settings, self.variables,
                                                  self.thermometer),
                             None if self.keep is None else self.keep[index],
                             len(self.power_names))

    def _first_chunk(self, chunk: Recording) -> None:
        """The run's rate, windows in rows, input rate, name and rate-filter checks."""
        run = self.run
        if not run.window_rows:
            rate_hz = chunk.metadata.sample_rate_hz
            window_s = self.windowing.window_s
            run.window_rows = round(window_s * rate_hz)
            if run.window_rows < 1:
                raise InputError(f"window_s={window_s:g} s holds no sample at {rate_hz:g} Hz "
                                 f"({chunk.source or 'run ' + str(run.index)}); pass a longer "
                                 "--window-s")
            for kept_windows in self.kept_by:
                kept_windows.averager = _WindowMeans(run.window_rows)
            run.period = 1.0 / rate_hz
        if run.input_rate is None:
            run.input_rate = chunk.metadata.input_rate_dph
            self.sources.append(chunk.source or f"run {run.index}")
            self.power_names.append(self.sources[-1])
            levels = filtered_levels(chunk, variables_for(self.terms))
            if levels and not self.split:  # the terms use a rate: can the filter follow?
                # (up to a logger restart: the filter restarts there)
                head = restart_rows(chunk.time_s, chunk.metadata.extra.get(RESTARTS_KEY))
                stop = int(head[0]) if head.size else len(chunk)
                self.problems += rate_filter_problems(
                    chunk.time_s[:stop], {k: v[:stop] for k, v in levels.items()},
                    self.settings.rate_tau_s, where=chunk.source or "",
                    thermometer_source=getattr(self.thermometer, "source", "resonator"))
        if self.extra is None:  # the accelerometer and label columns, where every run has them
            self.extra = tuple(c for c in _EXTRA_COLUMNS if c in chunk)

    def _starts(self, chunk: Recording) -> tuple[np.ndarray, np.ndarray]:
        """The chunk's rows that start a segment, and those of logger restarts."""
        run, time = self.run, chunk.time_s
        starts = np.flatnonzero(is_gap(np.diff(time), run.period)) + 1
        if run.last_time is None:
            run.power_on = float(time[0])
            self.segments += 1
        elif is_gap(time[0] - run.last_time, run.period):
            starts = np.concatenate([[0], starts])
        # logger restarts (new runs): always; every segment when each is a restart
        restarts = restart_rows(time, chunk.metadata.extra.get(RESTARTS_KEY))
        if run.last_time is None:
            restarts = restarts[restarts > 0]
        if restarts.size:
            starts = np.union1d(starts, restarts)
        starts = starts.astype(np.int64)
        self.segments += starts.size
        run.last_time = float(time[-1])
        return starts, restarts

    def _values(self, chunk: Recording, fresh: np.ndarray) -> dict[str, np.ndarray]:
        """The variables of the chunk (the df/dt filter restarted at ``fresh`` rows)."""
        run = self.run
        if not fresh.size:
            return run.stream.transform(chunk)
        edges = [0, *fresh[fresh > 0].tolist(), len(chunk)]
        parts = []
        for k in range(len(edges) - 1):
            if k > 0 or fresh[0] == 0:
                run.stream = FeatureStream(self.settings, self.variables, self.thermometer)
            parts.append(run.stream.transform(chunk.slice(edges[k], edges[k + 1])))
        return {v: np.concatenate([p[v] for p in parts]) for v in parts[0]}

    def _elapsed(self, time: np.ndarray, power_starts: np.ndarray) -> tuple[np.ndarray,
                                                                              np.ndarray]:
        """Seconds since power-on (or since the filter restarted: the warm-up skip) and
        the power-on run of each row (a new one at each restart)."""
        run = self.run
        origin = np.full(len(time), run.power_on)
        if power_starts.size:
            lengths = np.diff(np.append(power_starts, len(time)))
            origin[power_starts[0]:] = np.repeat(time[power_starts], lengths)
            run.power_on = float(time[power_starts[-1]])
        run_of_row = run.power + np.cumsum(np.bincount(power_starts, minlength=len(time)))
        run.power += power_starts.size
        while len(self.power_names) <= run.power:
            self.power_names.append(
                f"{self.sources[-1]} run {len(self.power_names) - run.first_power + 1}")
        return time - origin, run_of_row

    def add(self, chunk: Recording) -> None:
        """The window means of the next chunk of the run."""
        self._first_chunk(chunk)
        run, time = self.run, chunk.time_s
        if not len(time):
            return
        starts, restarts = self._starts(chunk)
        power_starts = starts if (self.split or self.windowing.restart_each_segment) else restarts
        values = self._values(chunk, starts if self.split else restarts)
        elapsed, run_of_row = self._elapsed(time, power_starts)
        rate = chunk["input_rate_dph"] if "input_rate_dph" in chunk else run.input_rate
        kept = None if run.keep is None else run.keep[run.row:run.row + len(chunk)]
        run.row += len(chunk)
        rested = np.ones(len(chunk), dtype=bool) if kept is None else kept.astype(bool)
        previous = np.concatenate([[run.last_used], rested[:-1]])
        resumed = np.flatnonzero(rested & ~previous)
        run.last_used = bool(rested[-1])
        cache: dict[tuple[str, int], np.ndarray] = {}
        columns = [
            chunk.time_s,
            run_of_row,
            chunk.rate_dph - rate,
            *(values[v] for v in self.variables),
            *(chunk[c] if c in chunk else np.nan for c in self.extra or ()),
            *(t.evaluate(values, cache) for t in self.terms),  # the design matrix's columns
        ]
        shared: tuple[Any, ...] = ()  # the last warm-up's rows used, block and extremes
        for windows in self.kept_by:
            settled = elapsed >= windows.threshold_s
            if kept is not None:
                windows.left_out += int(np.count_nonzero(~kept & settled))
            use = settled & rested
            windows.warm += int(np.count_nonzero(~settled))
            if not shared or not np.array_equal(use, shared[0]):  # else the same rows
                block = _used_rows(use, columns, iter(()), 0)
                used = block[:, 3:3 + len(self.variables)]  # down contiguous columns
                shared = (use, np.cumsum(use) - use, block,  # rows used before each row
                          *((np.fmin.reduce(used, axis=0), np.fmax.reduce(used, axis=0))
                            if block.shape[0] else ()))  # NaN ignored
            before, block = shared[1], shared[2]
            if block.shape[0]:
                np.fmin(windows.lowest, shared[3], out=windows.lowest)
                np.fmax(windows.highest, shared[4], out=windows.highest)
            assert windows.averager is not None
            windows.collect(windows.averager.transform(block, before[starts],
                                                       before[resumed]), run.index)
        self.total += len(chunk)
        if self.progress is not None:
            self.progress(self.total, 0)

    def end_run(self) -> None:
        """After the last chunk of the run."""
        run = self.run
        if not run.window_rows:  # a run without rows
            return
        for windows in self.kept_by:
            assert windows.averager is not None
            windows.collect(windows.averager.flush(), run.index)
            windows.partial += windows.averager.partial_dropped_rows
        if run.power > run.first_power:  # the file restarted: name its first run too
            self.power_names[run.first_power] = f"{self.sources[-1]} run 1"

    def finish(self) -> tuple[TrainingWindows, ...]:
        """Each warm-up's :class:`TrainingWindows` (the rate filter's problems warned)."""
        warn_rate_filter(self.problems)
        return tuple(_training_windows(w, self.windowing, self.variables, self.extra or (),
                                       self.total, self.sources, self.segments,
                                       self.power_names)
                     for w in self.kept_by)


@dataclass
class _RunState:
    """What a :class:`WindowJob` carries from one chunk of a run to the next."""

    index: int
    stream: FeatureStream
    keep: np.ndarray | None
    power: int  # index of the power-on run of the next row
    first_power: int = 0
    window_rows: int = 0  # windows in rows at this run's own rate
    period: float = 0.0
    input_rate: float | None = None
    row: int = 0
    last_time: float | None = None
    power_on: float | None = None  # time the warm-up counts from
    last_used: bool = True  # the previous row was used (not left out as not at rest)

    def __post_init__(self) -> None:
        self.first_power = self.power


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
