"""Every axis of a multi-axis run evaluated from one reading of the file.

:func:`evaluate_axes` reads the recording once and hands each chunk's single-axis
views (:func:`hrgtc.recording.axis_view`, no copies) to one
:class:`~hrgtc.evaluation.run_pass.RunPass` per axis, so an instrument of three axes
costs one reading, not three. Samples not at rest are found before (``motion`` other
than ``"keep"``): the detector's window is centred and its guard time reaches forward,
so whether a sample counts depends on later samples; that pass reads only the
detector's columns, for every axis at once. The figures of each axis equal those of
:func:`hrgtc.evaluation.evaluate` on the axis's view.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from hrgtc.core.progress import Progress
from hrgtc.drift.rest import run_rest
from hrgtc.evaluation.evaluation_result import Evaluation
from hrgtc.evaluation.plot_blocks import block_rows
from hrgtc.evaluation.run_pass import RunPass, RunPlan, count_dropped
from hrgtc.model import Model
from hrgtc.model_fit import (
    check_recording_noise,
    check_thermometer_kind,
    plausible_frequency_band,
    with_model_band,
)
from hrgtc.recording import ReadOptions, Recording, axis_view, count_rows
from hrgtc.recording.io import check_axis_band
from hrgtc.recording.marks import refuse_compensated
from hrgtc.recording.motion import ACCEL_COLUMNS
from hrgtc.settings.compensation import EvaluationSettings

__all__ = ["evaluate_axes"]

#: The columns the at-rest detector reads (:func:`hrgtc.drift.rest.run_rest`).
REST_COLUMNS = ("time_s", "rate_dph", "freq_hz", "input_rate_dph", *ACCEL_COLUMNS)


def evaluate_axes(
    run: str | os.PathLike[str],
    model: Model,
    *,
    settings: EvaluationSettings | None = None,
    read_options: ReadOptions | None = None,
    max_points: int | None = None,
    progress: Progress | None = None,
) -> dict[str, Evaluation]:
    """Evaluate every axis of ``model`` on a recording file read once.

    Parameters
    ----------
    run
        The recording file (single-axis with a single-axis model, else with the
        model's axes among its columns; see
        :func:`hrgtc.compensate.multi_axis.match_axes`).
    model
        The instrument's model (its axes are those evaluated).
    settings, read_options, max_points
        As :func:`hrgtc.evaluation.evaluate`, for every axis.
    progress
        ``progress(rows done, rows of the file)`` for the one reading.

    Returns
    -------
    dict
        Axis (``""`` for a single-axis model) -> :class:`Evaluation`.
    """
    options = read_options or ReadOptions()
    check_thermometer_kind(options, model)
    single = model.is_single_axis
    if single:  # the reader checks the plausible band of the one frequency
        options = with_model_band(dataclasses.replace(options, axis=None), model)
    else:  # each axis's band on its view, below
        options = dataclasses.replace(options, axis=None, freq_band_hz=None,
                                      freq_span_hz=None)
    refuse_compensated(run)
    head = options.head(run)
    check_recording_noise(model, head, str(run))
    rows = count_rows(run)  # cheap (metadata, or a scan of a CSV's bytes); plans the pass
    name, source = Path(run).name, str(run)
    fs = head.sample_rate_hz
    keep = _rest_masks(options.chunks(run), model, options.motion, name)
    blocks = None if max_points is None else block_rows(rows, fs, max_points)
    passes = {axis: RunPass(unit, RunPlan(name, source, rows, options.gaps, blocks,
                                          keep.get(axis)), settings)
              for axis, unit in model.axes.items()}
    bands = {axis: plausible_frequency_band(unit) for axis, unit in model.axes.items()}
    done = 0
    dropped: dict[str, int] = {}  # filled by the reading: the rows of spikes removed
    for chunk in options.chunks(run, dropped=dropped):
        for axis, state in passes.items():
            view = chunk if single else axis_view(chunk, axis)
            if not single:
                check_axis_band(view, axis, bands[axis], done, source)
            state.partial_fit(view)
        done += len(chunk)
        if progress is not None:
            progress(done, rows)
    return {axis: count_dropped(state.finish(), dropped) for axis, state in passes.items()}


def _rest_masks(chunks: Iterator[Recording], model: Model, motion: str,
                name: str) -> dict[str, np.ndarray]:
    """Each axis's samples at rest, from one pass over the detector's columns (none with
    ``motion="keep"``)."""
    if motion == "keep":
        return {}
    parts: dict[str, list[Recording]] = {axis: [] for axis in model.axes}
    for chunk in chunks:
        for axis in model.axes:
            view = chunk if not axis else axis_view(chunk, axis)
            parts[axis].append(Recording({k: view[k] for k in REST_COLUMNS if k in view},
                                         view.metadata, view.source))
    return {axis: run_rest(views, motion, name=name).keep for axis, views in parts.items()}

