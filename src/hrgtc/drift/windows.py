"""Window means of the drift-model terms over training runs, streamed chunk by chunk.

The regression of :mod:`hrgtc.drift.drift_model` runs on non-overlapping window
means (10 s by default) of the candidate terms and the measured bias: raw 200 Hz
residuals are too autocorrelated for F-tests. Each run's variables come from a
causal :class:`~hrgtc.drift.features.FeatureStream` that keeps its state across
chunks; the first ``warmup_s`` of each run is left out while the filter settles.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.drift.features import FeatureSettings, FeatureStream, Term, design_matrix, variables_for
from hrgtc.errors import CalibrationError, InputError
from hrgtc.progress import Progress
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
        Samples that went into the windows.
    sources
        Name (file) of each run, in run order.
    n_not_at_rest
        Samples left out because they were not at rest (:mod:`hrgtc.drift.rest`).
    accel
        Window means of ``accel_x/y/z`` (shape (windows, 3)) when every run logs them.
    orientation
        Window means of the user's ``orientation`` label when every run logs it.
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


class _WindowMeans:
    """Means of non-overlapping windows of ``rows`` samples over consecutive chunks."""

    def __init__(self, rows: int, skip: int) -> None:
        self.rows = rows
        self.skip = skip
        self._carry: np.ndarray | None = None

    def push(self, block: np.ndarray, keep: np.ndarray | None = None) -> np.ndarray:
        """Means of the windows completed by ``block``; rows where ``keep`` is False are
        left out, and a window never reaches across them (its partial start is dropped)."""
        if self.skip:
            dropped = min(self.skip, block.shape[0])
            block = block[dropped:]
            keep = None if keep is None else keep[dropped:]
            self.skip -= dropped
        if keep is not None and not keep.all():
            out = []
            edges = np.diff(np.concatenate([[0], keep.astype(np.int8), [0]]))
            starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
            for a, b in zip(starts, stops, strict=True):
                if a > 0:
                    self._carry = None  # a break: the partial window before it is dropped
                out.append(self.push(block[a:b]))
            if stops.size == 0 or stops[-1] < block.shape[0]:
                self._carry = None
            return np.concatenate(out) if out else np.empty((0, block.shape[1]))
        if self._carry is not None and self._carry.shape[0]:
            block = np.concatenate([self._carry, block])
        complete = block.shape[0] // self.rows
        self._carry = block[complete * self.rows :].copy()
        if complete == 0:
            return np.empty((0, block.shape[1]))
        used = block[: complete * self.rows]
        return used.reshape(complete, self.rows, block.shape[1]).mean(axis=1)


def _iter_run(source: RunSource) -> Iterator[Recording]:
    if isinstance(source, Recording):
        yield source
    else:
        yield from source()


def window_means(
    runs: Sequence[RunSource],
    settings: FeatureSettings,
    terms: Sequence[Term],
    window_s: float = 10.0,
    progress: Progress | None = None,
    thermometer: Any = None,
    extra_variables: Sequence[str] = (),
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
    window_s
        Window length. [s]
    progress
        Optional ``callback(samples_done, samples_total_or_0)``.
    thermometer
        The unit's thermometer, for the gradient ``g`` (see :class:`FeatureStream`).
    extra_variables
        Variables whose window means are kept although no term uses them (their
        training ranges: ``df`` for the range warnings of a model without df terms).
    keep
        Per run, True for each sample at rest (:func:`hrgtc.drift.rest.run_rest`) or
        None to use every sample: the windows are means of kept samples only and never
        reach across a left-out stretch, so every trained range comes from the samples
        actually used.
    """
    variables = variables_for(terms)
    variables += tuple(v for v in extra_variables if v not in variables)
    window_rows = round(window_s * settings.sample_rate_hz)
    if window_rows < 1:
        raise InputError(f"window_s={window_s} s holds no sample at {settings.sample_rate_hz} Hz")
    skip = round(settings.warmup_s * settings.sample_rate_hz)
    out_terms, out_bias, out_time, out_run = [], [], [], []
    out_vars: dict[str, list[np.ndarray]] = {v: [] for v in variables}
    out_extra: list[np.ndarray] = []
    total = 0
    left_out = 0
    sources: list[str] = []
    extra: tuple[str, ...] | None = None
    for index, source in enumerate(runs):
        stream = FeatureStream(settings, variables, thermometer)
        averager = _WindowMeans(window_rows, skip)
        input_rate = None
        run_keep = None if keep is None else keep[index]
        row = 0
        for chunk in _iter_run(source):
            settings.check_sample_rate(chunk)
            if input_rate is None:
                input_rate = chunk.metadata.input_rate_dph
                sources.append(chunk.source or f"run {index}")
            if extra is None:  # the accelerometer and label columns, where every run has them
                extra = tuple(c for c in _EXTRA_COLUMNS if c in chunk)
            values = stream.process(chunk)
            rate = chunk["input_rate_dph"] if "input_rate_dph" in chunk else input_rate
            block = np.column_stack(
                [
                    chunk.time_s,
                    chunk.rate_dph - rate,
                    *(values[v] for v in variables),
                    *(chunk[c] if c in chunk else np.full(len(chunk), np.nan) for c in extra),
                    design_matrix(terms, values),
                ]
            )
            kept = None if run_keep is None else run_keep[row:row + len(chunk)]
            if kept is not None:
                left_out += int(np.count_nonzero(~kept))
            row += len(chunk)
            means = averager.push(block, kept)
            if means.shape[0]:
                out_time.append(means[:, 0])
                out_bias.append(means[:, 1])
                for k, v in enumerate(variables):
                    out_vars[v].append(means[:, 2 + k])
                first = 2 + len(variables)
                out_extra.append(means[:, first:first + len(extra)])
                out_terms.append(means[:, first + len(extra):])
                out_run.append(np.full(means.shape[0], index))
            total += len(chunk)
            if progress is not None:
                progress(total, 0)
    if not out_time:
        raise CalibrationError(
            f"the drift runs hold no complete {window_s:g} s window after the "
            f"{settings.warmup_s:g} s filter warm-up; give longer runs"
        )
    columns = np.concatenate(out_extra) if out_extra else np.empty((0, 0))
    named = {c: columns[:, k] for k, c in enumerate(extra or ())
             if np.all(np.isfinite(columns[:, k]))}
    accel = None
    if all(c in named for c in _EXTRA_COLUMNS[:3]):
        accel = np.column_stack([named[c] for c in _EXTRA_COLUMNS[:3]])
    return TrainingWindows(
        n_not_at_rest=left_out,
        accel=accel,
        orientation=named.get("orientation"),
        time_s=np.concatenate(out_time),
        run=np.concatenate(out_run),
        terms=np.concatenate(out_terms),
        bias_dph=np.concatenate(out_bias),
        variables={v: np.concatenate(x) for v, x in out_vars.items()},
        n_samples=total,
        sources=tuple(sources),
    )
