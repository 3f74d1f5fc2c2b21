"""What a report is made of, checked once for every kind of report.

:func:`report_inputs` resolves the model (a path, a unit or an instrument), applies its
temperature map to the reading options, matches its axes to every run file and finds the
soaks; :func:`evaluate_runs` and :func:`trace_soaks` then read each file once for all the axes
(:func:`hrgtc.evaluation.evaluate`,
:func:`hrgtc.report.figures.trace_soak_axes`), counting the rows read for the progress
callback (:class:`RowCounter`). A report kind's data function (:mod:`hrgtc.report.kinds`)
takes the :class:`ReportInputs` and reads what it shows.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from hrgtc.compensate.multi_axis import match_axes, recording_axes
from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.evaluation import Evaluation
from hrgtc.evaluation.run_evaluation import evaluate
from hrgtc.model import Model, load_model
from hrgtc.model_fit import check_thermometer_kind
from hrgtc.recording import ReadOptions, count_rows
from hrgtc.report.figures import SoakTrace, trace_soak_axes
from hrgtc.settings.compensation import ReportSettings
from hrgtc.thermometry import Thermometer
from hrgtc.thermometry.reference import options_with_map

__all__ = ["ReportInputs", "RowCounter", "evaluate_runs", "report_inputs", "trace_soaks"]

PathLike = str | os.PathLike[str]


@dataclass(frozen=True)
class ReportInputs:
    """A report's inputs, checked (:func:`report_inputs`).

    Attributes
    ----------
    instrument
        The model, its axes those to show (a unit model is the one-axis instrument).
    model_path
        The model file, when the model was given as one.
    runs
        The run files and evaluations to show, in order.
    soaks, missing_soaks
        Soak recordings to read, and those the model names that are no longer on disk.
    read_options, soak_options
        How to read the runs, and the soaks (the model's own column mapping for its soaks).
    title
        The page title (None: the kind's default).
    max_points
        Most points per plotted curve.
    progress
        Optional ``callback(rows_done, rows_total)``.
    """

    instrument: Model
    model_path: str | None
    runs: tuple[PathLike | Evaluation, ...]
    soaks: tuple[str, ...]
    missing_soaks: tuple[str, ...]
    read_options: ReadOptions
    soak_options: ReadOptions
    title: str | None = None
    max_points: int = ReportSettings.max_points
    progress: Progress | None = None


def report_inputs(
    model: Model | PathLike,
    runs: Sequence[PathLike | Evaluation],
    *,
    soaks: Sequence[PathLike] | None = None,
    title: str | None = None,
    max_points: int = ReportSettings.max_points,
    read_options: ReadOptions | None = None,
    progress: Progress | None = None,
    axes: Sequence[str] | None = None,
    model_source: str = "",
) -> ReportInputs:
    """The inputs of :func:`hrgtc.report.build_report` checked, before any run is read
    (its parameters say what each is)."""
    model_path = None
    if isinstance(model, str | os.PathLike):
        model_path, instrument = str(model), load_model(model)
    else:
        instrument = model
    options = options_with_map(read_options or ReadOptions(), instrument.temperature_map)
    instrument = _check_axes(instrument, runs, options, axes, model_source or model_path or "")
    soak_paths, missing = (_soak_files(instrument) if soaks is None
                           else ([str(p) for p in soaks], []))
    if soaks is None:
        settings = instrument.provenance.get("settings", {})
        soak_options = ReadOptions(columns=settings.get("columns") or None,
                                   units=settings.get("units") or None)
    else:
        soak_options = options
    for run in runs:
        if isinstance(run, Evaluation) and (run.blocks is None or not instrument.is_single_axis):
            raise InputError(f"{run.file}: the evaluation kept no plotting blocks (or the model "
                             "has several axes); evaluate it with max_points, or pass the file")
    return ReportInputs(instrument, model_path, tuple(runs), tuple(soak_paths), tuple(missing),
                        options, soak_options, title, max_points, progress)


class RowCounter:
    """The rows read of ``paths`` so far, told to ``progress`` as ``(done, total)``."""

    def __init__(self, progress: Progress | None, paths: Sequence[PathLike]) -> None:
        self.progress = progress
        self.total = sum(count_rows(p) for p in paths)
        self.done = 0

    def advance(self, rows: int) -> None:
        self.done += rows
        if self.progress is not None:
            self.progress(self.done, self.total)

    def finish(self) -> None:
        """Every row read: ``(total, total)``."""
        if self.progress is not None:
            self.progress(self.total, self.total)


def evaluate_runs(inputs: ReportInputs, advance: Callable[[int], None]
                  ) -> dict[str, list[Evaluation]]:
    """Each axis's evaluations of the runs, in order, every axis of a run from one reading
    (an evaluation given is the single axis's as it is)."""
    evaluations: dict[str, list[Evaluation]] = {axis: [] for axis in inputs.instrument.axes}
    for run in inputs.runs:
        found = ({"": run} if isinstance(run, Evaluation) else
                 _evaluate_run(run, inputs, advance))
        for axis, result in found.items():
            evaluations[axis].append(result)
    return evaluations


def trace_soaks(inputs: ReportInputs, thermometers: Mapping[str, Thermometer],
                advance: Callable[[int], None]) -> dict[str, list[SoakTrace]]:
    """The block means of every soak for each axis of ``thermometers``, every axis of a soak
    from one reading; no soak is read when ``thermometers`` is empty."""
    traces: dict[str, list[SoakTrace]] = {axis: [] for axis in thermometers}
    for path in inputs.soaks if thermometers else ():
        for axis, trace in trace_soak_axes(path, thermometers, max_points=inputs.max_points,
                                           read_options=inputs.soak_options,
                                           on_chunk=advance).items():
            traces[axis].append(trace)
    return traces


def _soak_files(model: Model) -> tuple[list[str], list[str]]:
    """(existing, missing) soak files named in the model's provenance."""
    paths = [str(i["path"]) for i in model.provenance.get("inputs", [])
             if i.get("role") == "soak" and i.get("path")]
    return [p for p in paths if Path(p).is_file()], [p for p in paths if not Path(p).is_file()]


def _check_axes(model: Model, runs: Sequence[PathLike | Evaluation],
                options: ReadOptions, axes: Sequence[str] | None,
                model_source: str) -> Model:
    """The model's axes to show, checked against every run file (its thermometer kind,
    then its axes: :func:`hrgtc.compensate.multi_axis.match_axes`); the first run's
    match."""
    check_thermometer_kind(options, model, model_source or None)  # before the recordings' axes
    matched = [match_axes(model, recording_axes(run, options), axes, str(run), model_source)
               for run in runs if not isinstance(run, Evaluation)]
    return matched[0] if matched else model


def _evaluate_run(path: PathLike, inputs: ReportInputs,
                  advance: Callable[[int], None]) -> dict[str, Evaluation]:
    """Every axis of a run from one reading
    (:func:`hrgtc.evaluation.evaluate`), with plotting blocks."""
    seen = 0

    def progress(done: float, _total: float) -> None:
        nonlocal seen
        advance(int(done) - seen)
        seen = int(done)

    named = tuple(axis for axis in inputs.instrument.axes if axis)  # those matched already
    return evaluate(inputs.instrument, path, read_options=inputs.read_options,
                    axes=named or None, max_points=inputs.max_points, progress=progress).axes
