"""One evaluation of a run for a model of one axis or many: :func:`evaluate`.

The run is read once for every axis: each chunk's single-axis views
(:func:`hrgtc.recording.axis_view`, no copies) go to one
:class:`~hrgtc.evaluation.run_pass.RunPass` per axis, so an instrument of three axes costs
one reading, not three; a single-axis model is the one-axis case (its pass sees the chunks
as they are). Samples not at rest are found before (``motion`` other than ``"keep"``): the
detector's window is centred and its guard time reaches forward, so whether a sample counts
depends on later samples; that pass reads only the detector's columns, for every axis at
once. A rate-table run of a model with a scale factor also gets its scale-factor check
(:mod:`hrgtc.evaluation.scale_check`). The result, :class:`RunEvaluation`, holds one
:class:`~hrgtc.evaluation.Evaluation` per axis (``.axis`` for a single-axis model).
``hrgtc evaluate``, ``calibrate --validate``, the report and the demo all use it.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import CompensationWarning, InputError, RecordingError
from hrgtc.core.progress import Progress
from hrgtc.core.records import Record, Statistic
from hrgtc.core.summary import Summary
from hrgtc.drift.rest import run_rest
from hrgtc.evaluation.evaluation_result import Evaluation, EvaluationRecord, Fraction
from hrgtc.evaluation.instrument_figures import evaluation_tables
from hrgtc.evaluation.plot_blocks import block_rows
from hrgtc.evaluation.run_pass import RunPass, RunPlan, count_dropped
from hrgtc.evaluation.scale_check import ScaleFactorCheck, check_scale_factor
from hrgtc.model import Model
from hrgtc.model_fit import (
    check_recording_noise,
    check_thermometer_kind,
    plausible_frequency_band,
    with_model_band,
)
from hrgtc.recording import ReadOptions, Recording, axis_view, count_rows
from hrgtc.recording.io import check_axis_band
from hrgtc.recording.marks import compensation_mark, describe_mark, refuse_compensated
from hrgtc.recording.motion import ACCEL_COLUMNS
from hrgtc.settings.compensation import EvaluationSettings

__all__ = ["AxisSummaryRecord", "InstrumentEvaluationRecord", "RunEvaluation", "evaluate",
           "warn_worse_than_raw", "worse_than_raw"]

#: The columns the at-rest detector reads (:func:`hrgtc.drift.rest.run_rest`).
REST_COLUMNS = ("time_s", "rate_dph", "freq_hz", "input_rate_dph", *ACCEL_COLUMNS)


class AxisSummaryRecord(Record):
    """One axis of an instrument's evaluation: 10 s bias stability raw and compensated,
    the improvement, mean and RMS of the compensated output, shares beyond the trained
    ranges. [°/h]"""

    axis: str
    raw_10s_dph: Statistic
    compensated_10s_dph: Statistic
    improvement_10s: Statistic
    compensated_mean_dph: Statistic
    compensated_rms_dph: Statistic
    out_of_range_fraction: Fraction
    rate_out_of_range_fraction: Fraction


class InstrumentEvaluationRecord(Record):
    """The record of :class:`~hrgtc.evaluation.run_evaluation.RunEvaluation` of a
    multi-axis model (its ``to_dict``): the unit, each axis's evaluation and a summary."""

    unit: str
    axes: dict[str, EvaluationRecord]
    summary: list[AxisSummaryRecord]


@dataclass(frozen=True, eq=False)
class RunEvaluation:
    """What :func:`evaluate` measured: each axis's figures and the scale-factor check of a
    rate-table run (the result of ``hrgtc evaluate``).

    Attributes
    ----------
    model
        The model as applied (its axes those evaluated).
    axes
        Axis (``""`` for a single-axis model) -> :class:`~hrgtc.evaluation.Evaluation`.
    scale_checks
        Scale-factor error at each temperature of a rate-table run, raw and compensated
        (empty unless the run has ``input_rate_dph`` columns and the model a scale factor).
    """

    model: Model
    axes: dict[str, Evaluation]
    scale_checks: tuple[ScaleFactorCheck, ...] = ()

    @property
    def axis(self) -> Evaluation:
        """The one axis's evaluation (a single-axis model's, or the one axis evaluated);
        with several axes, pick one: ``result.axes['x']``."""
        if len(self.axes) != 1:
            raise InputError(f"the evaluation has axes {', '.join(self.axes)}: pick one: "
                             f"result.axes[{next(iter(self.axes))!r}]")
        return next(iter(self.axes.values()))

    def summary(self) -> Summary:
        """The axes side by side and the scale-factor check, beside each axis's own
        (:func:`hrgtc.evaluation.instrument_figures.evaluation_tables`)."""
        return evaluation_tables(self)

    def axis_summary(self) -> list[dict[str, float | str]]:
        """One row per axis: 10 s bias stability raw and compensated, improvement, mean and
        RMS of the compensated output, shares beyond the trained ranges. [°/h]"""
        return [{"axis": axis, "raw_10s_dph": r.raw_10s,
                 "compensated_10s_dph": r.compensated_10s,
                 "improvement_10s": r.improvement_10s,
                 "compensated_mean_dph": r.mean_dph.get("compensated", float("nan")),
                 "compensated_rms_dph": r.rms_dph.get("compensated", float("nan")),
                 "out_of_range_fraction": r.out_of_range_fraction,
                 "rate_out_of_range_fraction": r.rate_out_of_range_fraction}
                for axis, r in self.axes.items()]

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (the layout of ``hrgtc evaluate --json``): a single-axis model's
        evaluation as it is (:class:`~hrgtc.evaluation.evaluation_result.EvaluationRecord`);
        else the unit, each axis and the summary (:class:`InstrumentEvaluationRecord`; NaN:
        None). Its JSON Schema: :func:`hrgtc.pipeline.documents.evaluate_json_schema`."""
        if self.model.is_single_axis:
            return self.axes[""].to_dict()
        return records.dump(self, InstrumentEvaluationRecord, unit=self.model.unit,
                            axes={a: r.to_dict() for a, r in self.axes.items()},
                            summary=self.axis_summary())

    def allan_csv(self) -> str:
        """The deviation curves of every axis as CSV (an ``axis`` column first when there
        are several): series, tau_s, deviation, lower, upper, n, edf."""
        if list(self.axes) == [""]:
            return self.axes[""].allan_csv()
        lines: list[str] = []
        for axis, result in self.axes.items():
            header, *rows = result.allan_csv().splitlines()
            if not lines:
                lines.append("axis," + header)
            lines.extend(f"{axis},{row}" for row in rows)
        return "\n".join(lines) + "\n"


def worse_than_raw(evaluation: Evaluation, axis: str = "") -> str | None:
    """What to say when compensation made ``evaluation``'s run worse: its 10 s bias
    stability compensated above the raw one, their 1σ intervals apart (None otherwise).

    The intervals of the two are each a χ² interval of their own series; raw and
    compensated share the run's noise, so intervals that are apart are a difference the
    run's noise does not explain."""
    raw, compensated = evaluation.stability("raw", 10.0), evaluation.stability("compensated",
                                                                               10.0)
    if raw is None or compensated is None or not compensated > raw:
        return None
    raw_bounds = evaluation.stability_interval("raw", 10.0)
    bounds = evaluation.stability_interval("compensated", 10.0)
    if raw_bounds is not None and bounds is not None and bounds[0] <= raw_bounds[1]:
        return None
    where = f"{evaluation.file}" + (f", axis {axis}" if axis else "")
    shares = {"of it lies beyond the trained temperatures": evaluation.out_of_range_fraction,
              "beyond the trained df/dt": evaluation.rate_out_of_range_fraction}
    why = [f"{100 * share:.1f}% {what}" for what, share in shares.items()
           if round(100 * share, 1) > 0]
    return (f"{where}: compensated, the 10 s bias stability is worse than raw "
            f"({compensated:.4g} against {raw:.4g} °/h, apart beyond their intervals): the "
            "model does not hold on this run"
            + (f" ({'; '.join(why)})" if why else "")
            + "; train on runs that cover its temperatures and rates, or do not apply the "
              "model to it")


def warn_worse_than_raw(result: RunEvaluation) -> RunEvaluation:
    """A :class:`~hrgtc.core.errors.CompensationWarning` for each axis of ``result`` that
    compensation made worse (:func:`worse_than_raw`); ``result`` returned."""
    import warnings

    for axis, evaluation in result.axes.items():
        said = worse_than_raw(evaluation, axis)
        if said is not None:
            warnings.warn(said, CompensationWarning, stacklevel=2)
    return result


def evaluate(
    model: Model,
    run: Recording | str | os.PathLike[str],
    *,
    settings: EvaluationSettings | None = None,
    read_options: ReadOptions | None = None,
    axes: Sequence[str] | None = None,
    max_points: int | None = None,
    on_output: Callable[[Recording], None] | None = None,
    progress: Progress | None = None,
    model_source: str = "",
) -> RunEvaluation:
    """Raw vs compensated bias stability, Allan noise terms and range shares of a run,
    every axis of ``model`` from one reading.

    Parameters
    ----------
    model
        The model (a single-axis model is the one-axis case). Its temperature map
        (``calibrate --temp-ref``) is applied unless ``read_options`` give their own scale
        and offset.
    run
        A recording file, read chunk by chunk, or a :class:`~hrgtc.recording.Recording`.
    settings
        What is measured (:class:`~hrgtc.settings.compensation.EvaluationSettings`; the
        defaults: bias stability at 1, 10 and 100 s, the overlapping Allan deviation and
        its noise terms, 1σ intervals).
    read_options
        How to read a file (column mapping, units, metadata, chunk size). With a
        single-axis model, ``read_options.axis`` reads that axis's view of a multi-axis
        file (the axis the model was fitted on); with several axes every axis's columns
        are read and the option is not used.
    axes
        The axes to evaluate (``--axes``); None: all of them. The model's and the run's
        axes must agree unless ``axes`` names those to evaluate
        (:func:`hrgtc.compensate.multi_axis.match_axes`).
    max_points
        Keep at most this many plotting blocks (of at least 10 s); None keeps none.
    on_output
        Called with every compensated chunk of a one-axis evaluation (the input columns
        plus ``rate_comp_dph``, ``bias_model_dph``, ``resonator_c_est``, ``in_range``),
        e.g. a :class:`~hrgtc.recording.RecordingWriter`'s ``write``.
    progress
        ``progress(rows done, rows)`` of the reading.
    model_source
        The model file's name, for the messages.

    Raises
    ------
    InputError
        A run that holds no samples or is shorter than two 10 s blocks, axes that do not
        match, or ``on_output`` with several axes.
    """
    from hrgtc.thermometry.reference import options_with_map

    options = options_with_map(read_options or ReadOptions(), model.temperature_map)
    if isinstance(run, Recording):
        return _evaluate_recording(model, run, options, settings, max_points, on_output,
                                   progress)
    check_thermometer_kind(options, model, model_source or None)  # before the run's axes
    if options.axis is None:  # (an axis read as the view of a single-axis model: that axis)
        from hrgtc.compensate.multi_axis import match_axes, recording_axes

        model = match_axes(model, recording_axes(run, options), axes, str(run), model_source)
    return _evaluate_file(model, run, options, settings, max_points, on_output, progress)


def _evaluate_file(model: Model, run: str | os.PathLike[str], options: ReadOptions,
                   settings: EvaluationSettings | None, max_points: int | None,
                   on_output: Callable[[Recording], None] | None,
                   progress: Progress | None) -> RunEvaluation:
    """:func:`evaluate` of a file, once its model's axes are matched to the run's."""
    if model.is_single_axis:  # the reader checks the plausible band of the one frequency
        options = with_model_band(options, model)
    else:  # each axis's band on its view, below
        options = dataclasses.replace(options, axis=None, freq_band_hz=None,
                                      freq_span_hz=None)
    refuse_compensated(run)
    head = options.head(run)
    check_recording_noise(model, head, str(run), options.axis)
    rows = count_rows(run)  # cheap (metadata, or a scan of a CSV's bytes); plans the pass
    name = Path(run).name
    keep = _rest_masks(options.chunks(run), model, options.motion, name)
    blocks = None if max_points is None else block_rows(rows, head.sample_rate_hz, max_points)
    plan = RunPlan(name, str(run), rows, options.gaps, blocks)
    dropped: dict[str, int] = {}  # filled by the reading: the rows of spikes removed
    results = _passes(model, options.chunks(run, dropped=dropped), plan, keep, settings,
                      on_output, progress)
    results = {axis: count_dropped(result, dropped) for axis, result in results.items()}
    checks: tuple[ScaleFactorCheck, ...] = ()
    if any(m.scale_factor is not None for m in model.axes.values()):
        if any(n == "input_rate_dph" or n.startswith("input_rate_dph_") for n in head.names):
            checks = check_scale_factor(run, model, options)
    return RunEvaluation(model, results, checks)


def _evaluate_recording(model: Model, run: Recording, options: ReadOptions,
                        settings: EvaluationSettings | None, max_points: int | None,
                        on_output: Callable[[Recording], None] | None,
                        progress: Progress | None) -> RunEvaluation:
    """:func:`evaluate` of a recording in memory (one chunk)."""
    found = compensation_mark(run.metadata.to_dict(), list(run.names))
    if found is not None:
        raise RecordingError(f"{run.source or 'recording'} is already compensated, by "
                             f"{describe_mark(found)}; evaluate the original recording")
    check_recording_noise(model, run, run.source or "")
    name = Path(run.source or "recording").name
    keep = _rest_masks(iter([run]), model, options.motion, name)
    blocks = None if max_points is None else block_rows(len(run), run.sample_rate_hz,
                                                        max_points)
    plan = RunPlan(name, run.source or "", len(run), options.gaps, blocks)
    extra = run.metadata.extra
    dropped = {"spikes": int(extra.get("spikes_dropped", 0))
               + int(extra.get("spikes_removed", 0))}
    results = _passes(model, [run], plan, keep, settings, on_output, progress)
    return RunEvaluation(model, {axis: count_dropped(result, dropped)
                                 for axis, result in results.items()})


def _passes(model: Model, chunks: Iterable[Recording], plan: RunPlan,
            keep: dict[str, np.ndarray], settings: EvaluationSettings | None,
            on_output: Callable[[Recording], None] | None,
            progress: Progress | None) -> dict[str, Evaluation]:
    """One :class:`RunPass` per axis of ``model`` over ``chunks`` (each axis on its view;
    the one axis of a single-axis model on the chunks as they are)."""
    if on_output is not None and len(model.axes) > 1:
        raise InputError("on_output takes one axis's compensated chunks; the model has axes "
                         f"{', '.join(model.axes)}: evaluate one (axes=...)")
    passes = {axis: RunPass(part, dataclasses.replace(plan, keep=keep.get(axis)), settings,
                            on_output=on_output)
              for axis, part in model.axes.items()}
    bands = {axis: plausible_frequency_band(part) for axis, part in model.axes.items()}
    done = 0
    for chunk in chunks:
        for axis, state in passes.items():
            view = chunk if not axis else axis_view(chunk, axis)
            if axis:
                check_axis_band(view, axis, bands[axis], done, plan.source)
            state.partial_fit(view)
        done += len(chunk)
        if progress is not None:
            progress(done, plan.total_rows)
    return {axis: state.finish() for axis, state in passes.items()}


def _rest_masks(chunks: Iterable[Recording], model: Model, motion: str,
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
