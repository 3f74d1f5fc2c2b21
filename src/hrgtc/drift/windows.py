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
    """

    time_s: np.ndarray
    run: np.ndarray
    terms: np.ndarray
    bias_dph: np.ndarray
    variables: dict[str, np.ndarray]
    n_samples: int
    sources: tuple[str, ...] = ()


class _WindowMeans:
    """Means of non-overlapping windows of ``rows`` samples over consecutive chunks."""

    def __init__(self, rows: int, skip: int) -> None:
        self.rows = rows
        self.skip = skip
        self._carry: np.ndarray | None = None

    def push(self, block: np.ndarray) -> np.ndarray:
        if self.skip:
            dropped = min(self.skip, block.shape[0])
            block = block[dropped:]
            self.skip -= dropped
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
    """
    variables = variables_for(terms)
    variables += tuple(v for v in extra_variables if v not in variables)
    window_rows = round(window_s * settings.sample_rate_hz)
    if window_rows < 1:
        raise InputError(f"window_s={window_s} s holds no sample at {settings.sample_rate_hz} Hz")
    skip = round(settings.warmup_s * settings.sample_rate_hz)
    out_terms, out_bias, out_time, out_run = [], [], [], []
    out_vars: dict[str, list[np.ndarray]] = {v: [] for v in variables}
    total = 0
    sources: list[str] = []
    for index, source in enumerate(runs):
        stream = FeatureStream(settings, variables, thermometer)
        averager = _WindowMeans(window_rows, skip)
        input_rate = None
        for chunk in _iter_run(source):
            settings.check_sample_rate(chunk)
            if input_rate is None:
                input_rate = chunk.metadata.input_rate_dph
                sources.append(chunk.source or f"run {index}")
            values = stream.process(chunk)
            block = np.column_stack(
                [
                    chunk.time_s,
                    chunk.rate_dph - input_rate,
                    *(values[v] for v in variables),
                    design_matrix(terms, values),
                ]
            )
            means = averager.push(block)
            if means.shape[0]:
                out_time.append(means[:, 0])
                out_bias.append(means[:, 1])
                for k, v in enumerate(variables):
                    out_vars[v].append(means[:, 2 + k])
                out_terms.append(means[:, 2 + len(variables) :])
                out_run.append(np.full(means.shape[0], index))
            total += len(chunk)
            if progress is not None:
                progress(total, 0)
    if not out_time:
        raise CalibrationError(
            f"the drift runs hold no complete {window_s:g} s window after the "
            f"{settings.warmup_s:g} s filter warm-up; give longer runs"
        )
    return TrainingWindows(
        time_s=np.concatenate(out_time),
        run=np.concatenate(out_run),
        terms=np.concatenate(out_terms),
        bias_dph=np.concatenate(out_bias),
        variables={v: np.concatenate(x) for v, x in out_vars.items()},
        n_samples=total,
        sources=tuple(sources),
    )
