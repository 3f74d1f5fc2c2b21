"""Build the HTML report of a unit or of a whole instrument (one section per axis).

:func:`build_report` reads the soaks and runs chunk by chunk, evaluates each run
(every axis as :func:`hrgtc.evaluation.evaluate` with plotting blocks) and writes one
self-contained page with the sections of :mod:`hrgtc.report.html`. A multi-axis
model gives the instrument's summary (one row per axis and run) and then every
axis's sections; each file is read once for all the axes
(:func:`hrgtc.evaluation.instrument_pass.evaluate_axes`,
:func:`hrgtc.report.figures.trace_soak_axes`).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Sequence
from html import escape
from pathlib import Path
from typing import Any

from hrgtc.compensate.multi_axis import match_axes, recording_axes
from hrgtc.core.errors import InputError
from hrgtc.core.files import refuse_existing, write_text_atomic
from hrgtc.core.progress import Progress
from hrgtc.evaluation import Evaluation
from hrgtc.evaluation.calibration_figures import (
    SENSOR_THERMOMETER,
    calibration_summary,
    thermometer_tables,
)
from hrgtc.evaluation.glance_figures import GLANCE, instrument_glance_summary
from hrgtc.evaluation.instrument_pass import evaluate_axes
from hrgtc.model import InstrumentModel, UnitModel, load_instrument
from hrgtc.model_fit import check_thermometer_kind
from hrgtc.recording import ReadOptions, count_rows
from hrgtc.report.figures import SoakTrace, trace_soak_axes
from hrgtc.report.html import (
    _CSS,
    DOI,
    _drift_model,
    _grid_table,
    _header,
    _Page,
    _run,
    _scale_factor,
    _section_table,
    _settling,
    _summary,
    _table_rows,
    _temperature,
    _thermometer,
    reference,
)
from hrgtc.settings.compensation import ReportSettings
from hrgtc.thermometry.plateaus import Plateau
from hrgtc.thermometry.reference import options_with_map

__all__ = ["build_report"]

PathLike = str | os.PathLike[str]


def _soak_files(model: UnitModel) -> tuple[list[str], list[str]]:
    """(existing, missing) soak files named in the model's provenance."""
    paths = [str(i["path"]) for i in model.provenance.get("inputs", [])
             if i.get("role") == "soak" and i.get("path")]
    return [p for p in paths if Path(p).is_file()], [p for p in paths if not Path(p).is_file()]


def build_report(
    model: UnitModel | InstrumentModel | PathLike,
    runs: Sequence[PathLike | Evaluation],
    output: PathLike,
    *,
    soaks: Sequence[PathLike] | None = None,
    title: str | None = None,
    force: bool = False,
    max_points: int = ReportSettings.max_points,
    read_options: ReadOptions | None = None,
    progress: Progress | None = None,
    axes: Sequence[str] | None = None,
    model_source: str = "",
) -> Path:
    """Write the report: one self-contained HTML file with Figs. 3-6 and Tables 1-2 of [1].

    Parameters
    ----------
    model
        The unit's or instrument's model, or the path of its model file.
    runs
        Recordings to compensate and evaluate (Fig. 6 of [1]), one section each, or
        evaluations already made with plotting blocks (:func:`hrgtc.evaluation.evaluate`
        with ``max_points``; single-axis models only), which are not computed again.
    output
        The HTML file; written atomically, never overwritten without ``force``.
    soaks
        Soak recordings for Figs. 3 and 5(b); default: the model's soak inputs that
        still exist on disk (read with the column mapping stored in the model).
    title
        Page title (default names the unit).
    max_points
        Most points per plotted curve; plots use block means of at least 10 s.
    read_options
        How to read the runs and the given soaks (column mapping, units, metadata); the
        model's temperature map (``--temp-ref``) applies unless they give their own
        scale and offset.
    progress
        Optional ``callback(rows_done, rows_total)``.
    axes
        The axes to show (``--axes``); None: all. The model's and each run's axes must
        agree unless ``axes`` names those to show
        (:func:`hrgtc.compensate.multi_axis.match_axes`).
    model_source
        The model's name in messages (default: its path when ``model`` is one).

    Returns
    -------
    pathlib.Path
        The written file.

    Raises
    ------
    OutputExistsError
        ``output`` exists and ``force`` is False (checked before any work).
    InputError
        An evaluation given in ``runs`` kept no plotting blocks, or was given for a
        multi-axis model; the runs are read as the other kind of thermometer than the
        model's; the model's and a run's axes differ (checked before any run is read).
    """
    target = Path(output)
    refuse_existing(target, force)
    model_path = None
    if isinstance(model, UnitModel):
        instrument = InstrumentModel.single(model)
    elif isinstance(model, InstrumentModel):
        instrument = model
    else:
        model_path, instrument = str(model), load_instrument(model)
    options = options_with_map(read_options or ReadOptions(), instrument.temperature_map)
    instrument = _check_axes(instrument, runs, options, axes, model_source or model_path or "")
    first = next(iter(instrument.axes.values()))
    soak_paths, missing = _soak_files(first) if soaks is None else ([str(p) for p in soaks], [])
    if soaks is None:
        settings = first.provenance.get("settings", {})
        soak_options = ReadOptions(columns=settings.get("columns") or None,
                                   units=settings.get("units") or None)
    else:
        soak_options = options
    for run in runs:
        if isinstance(run, Evaluation) and (run.blocks is None or not instrument.is_single_axis):
            raise InputError(f"{run.file}: the evaluation kept no plotting blocks (or the model "
                             "has several axes); evaluate it with max_points, or pass the file")
    files = [run for run in runs if not isinstance(run, Evaluation)]
    traced = {axis: m.thermometer for axis, m in instrument.axes.items()
              if m.thermometer.source != "sensor"}
    total = sum(count_rows(p) for p in [*(soak_paths if traced else ()), *files])
    done = 0

    def advance(rows: int) -> None:
        nonlocal done
        done += rows
        if progress is not None:
            progress(done, total)

    page = _Page()
    _header(page, dataclasses.replace(first, unit=instrument.unit), title
            or f"Temperature compensation report — unit {instrument.unit}", model_path,
            "" if instrument.is_single_axis else next(iter(instrument.axes)))
    evaluations: dict[str, list[Evaluation]] = {axis: [] for axis in instrument.axes}
    for run in runs:  # every axis of a run from one reading
        found = ({"": run} if isinstance(run, Evaluation) else
                 _evaluate_run(run, instrument, options, max_points, advance))
        for axis, result in found.items():
            evaluations[axis].append(result)
    traces: dict[str, list[SoakTrace]] = {axis: [] for axis in traced}
    for path in soak_paths if traced else ():  # every axis of a soak from one reading
        for axis, trace in trace_soak_axes(path, traced, max_points=max_points,
                                           read_options=soak_options,
                                           on_chunk=advance).items():
            traces[axis].append(trace)
    sections: dict[str, list[str]] = {}
    for axis, unit_model in instrument.axes.items():
        axis_page = _Page()
        axis_page.count = page.count
        _unit_sections(axis_page, unit_model, evaluations[axis], traces.get(axis, []),
                       missing, instrument.temperature_map)
        page.count = axis_page.count
        sections[axis] = axis_page.parts
    if instrument.is_single_axis:
        _summary(page, evaluations[""], first.thermometer.source == "sensor")
        page.add(*sections[""])
    else:
        _instrument_summary(page, instrument, evaluations)
        for axis, parts in sections.items():
            html = "\n".join(parts).replace(' id="', f' id="{axis}-').replace(
                'href="#', f'href="#{axis}-')
            page.add(f'<section id="axis-{escape(axis)}"><h2 class="axis">Axis '
                     f"{escape(axis)}</h2>", html, "</section>")
    body = "\n".join(page.parts)
    title_text = title or f"Temperature compensation report — unit {instrument.unit}"
    html = (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{escape(title_text)}</title>"
            f"<style>{_CSS}</style></head><body>\n{body}\n<footer class=\"muted\"><p>[1] "
            f"{reference(first.thermometer.source == 'sensor')}. doi:{DOI}. Generated by "
            "hrgtc.</p></footer></body></html>\n")
    written = write_text_atomic(target, html, force=force)
    if progress is not None:
        progress(total, total)
    return written


def _check_axes(model: InstrumentModel, runs: Sequence[PathLike | Evaluation],
                options: ReadOptions, axes: Sequence[str] | None,
                model_source: str) -> InstrumentModel:
    """The model's axes to show, checked against every run file (its thermometer kind,
    then its axes: :func:`hrgtc.compensate.multi_axis.match_axes`); the first run's
    match."""
    for unit_model in model.axes.values():  # before reading the recordings' axes
        check_thermometer_kind(options, unit_model, model_source or None)
    matched = [match_axes(model, recording_axes(run, options), axes, str(run), model_source)
               for run in runs if not isinstance(run, Evaluation)]
    return matched[0] if matched else model


def _unit_sections(page: _Page, model: UnitModel, evaluations: Sequence[Evaluation],
                   traces: Sequence[SoakTrace], missing: list[str],
                   temperature_map: dict[str, Any] | None = None) -> None:
    """One axis's sections: Figs. 3-5 and Tables 1-2 (a sensor thermometer: what it is and
    the map of its count, ``temperature_map``), its runs, drift and scale factor."""
    plateaus = [Plateau.from_dict(p) for p in model.plateaus]
    table = _table_rows(model, plateaus)
    sensor = model.thermometer.source == "sensor"
    if sensor:
        low, high = model.thermometer.temperature_range_c
        page.note(f"No frequency output: the gyro's temperature sensor is the thermometer "
                  f"(trained {low:.2f} to {high:.2f} °C); no soak settling, frequency fit or "
                  "temperature from frequency to show.")
        _section_table(page, calibration_summary(model, temperature_map=temperature_map),
                       SENSOR_THERMOMETER, "Thermometer: the gyro's temperature sensor"
                       + (", its count mapped to °C by the reference log" if temperature_map
                          else ", read directly"))
    else:
        tables = thermometer_tables(model.thermometer, plateaus)
        _settling(page, plateaus, traces, missing, tables)
        _thermometer(page, model, plateaus, table, tables)
        _temperature(page, table, traces, tables)
    page.add('<section id="runs"><h2>4. Runs: raw and compensated output</h2>')
    if not evaluations:
        page.note("No runs given.")
    for k, run in enumerate(evaluations, start=1):
        _run(page, k, run, model)
    page.add("</section>")
    _drift_model(page, model)
    _scale_factor(page, model)


def _instrument_summary(page: _Page, model: InstrumentModel,
                        evaluations: dict[str, list[Evaluation]]) -> None:
    """The instrument at a glance: each axis's 10 s bias stability per run, scale factor."""
    page.add(f'<section id="instrument"><h2>Instrument {escape(model.unit)}: '
             f"{len(model.axes)} axes</h2>",
             _grid_table(instrument_glance_summary(model, evaluations), GLANCE,
                         "At a glance: 10 s bias stability per axis and run"),
             "<nav><ol>" + "".join(f'<li><a href="#axis-{escape(a)}">Axis {escape(a)}</a></li>'
                                   for a in model.axes) + "</ol></nav></section>")


def _evaluate_run(path: PathLike, model: InstrumentModel, options: ReadOptions,
                  max_points: int, advance: Callable[[int], None]) -> dict[str, Evaluation]:
    """Every axis of a run from one reading
    (:func:`hrgtc.evaluation.instrument_pass.evaluate_axes`), with plotting blocks."""
    seen = 0

    def progress(done: float, _total: float) -> None:
        nonlocal seen
        advance(int(done) - seen)
        seen = int(done)

    return evaluate_axes(path, model, read_options=options, max_points=max_points,
                         progress=progress)
