"""The "paper" report's data: the evidence of a calibration laid out like [1].

:func:`paper_report` reads the unit's soaks and runs chunk by chunk (the one run pass of
:func:`hrgtc.evaluation.evaluate`, with plotting blocks; the soak traces of
:mod:`hrgtc.report.figures`) and gives a :class:`PaperReport`: per axis, the settling of each
soak (Fig. 3 of [1]), the frequency-temperature fit (Fig. 4, Table 1, Eq. 18), the
temperature from frequency (Fig. 5, Table 2), raw and compensated output of each run
(Fig. 6) with bias stability and Allan deviation, the stepwise drift model (Eq. 21-22) and
the scale factor; a sensor thermometer's model in its own words. The figures are SVG
``data:`` URIs (:class:`~hrgtc.report.figures.Plot`), the tables their cells as text
(:class:`~hrgtc.report.tables.Table`); ``templates/paper/`` lays them out.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

import hrgtc.report.figures as figures
from hrgtc.core.summary import Summary
from hrgtc.evaluation import Evaluation
from hrgtc.evaluation.calibration_figures import (
    EQ18,
    PLATEAUS,
    SENSOR_THERMOMETER,
    TABLE1,
    TABLE2,
    calibration_summary,
    drift_heading,
    power_text,
    thermometer_tables,
)
from hrgtc.evaluation.glance_figures import GLANCE, glance_summary, instrument_glance_summary
from hrgtc.evaluation.heating_cooling import DIRECTIONS, DirectionStats
from hrgtc.model import Model
from hrgtc.report.figures import Plot, SoakTrace, plot
from hrgtc.report.inputs import ReportInputs, RowCounter, evaluate_runs, trace_soaks
from hrgtc.report.tables import (
    FIGURE_COLUMNS,
    INPUTS,
    SOAK_ERROR,
    Table,
    grid_table,
    provenance_summary,
    section_table,
    soak_error_summary,
)
from hrgtc.thermometry import paper
from hrgtc.thermometry.plateaus import Plateau

__all__ = ["AxisReport", "Direction", "HeatingCooling", "PaperReport", "RunReport", "ScaleFactor",
           "Thermometry", "axis_report", "heating_cooling", "paper_report", "table_rows"]


@dataclass(frozen=True)
class Thermometry:
    """Figs. 3-5 and Tables 1-2 of a resonator's axis (its frequency is the thermometer)."""

    missing_soaks: tuple[str, ...]
    settling: Plot | None  # Fig. 3 from the soaks, or (settling_stored) the stored fits
    settling_stored: bool
    settling_block_s: float  # the plotting blocks of the soaks (0: none)
    plateaus: Table
    fit: Plot | None  # Fig. 4
    table1: Table
    eq18_fit: Table | None
    eq18_paper: Table
    eq18_terms: str  # f = ... of the fitted polynomial
    residual_std_mhz: float
    temperature_error: Plot | None  # Fig. 5(a)
    table2: Table
    soak_temperature: Plot | None  # Fig. 5(b)
    soak_error: Table | None


@dataclass(frozen=True)
class Direction:
    """One direction's row of :class:`HeatingCooling` (the numbers of
    :class:`~hrgtc.evaluation.heating_cooling.DirectionStats`; NaN: fewer than three
    blocks). [°/h]"""

    direction: str  # "heating" or "cooling"
    blocks: int
    raw_dph: float
    compensated_dph: float
    improvement: float  # raw / compensated
    residual_rms_dph: float | None  # RMS of model minus true bias (None: not simulated)


@dataclass(frozen=True)
class HeatingCooling:
    """A run's bias stability with heating and cooling apart: a row per direction with a
    block, a sentence per direction without one (or why neither has one)."""

    caption: str
    block_s: float  # [s]
    rows: tuple[Direction, ...]
    truth: bool  # the run is simulated: the residual against the true bias is shown
    notes: tuple[str, ...]


@dataclass(frozen=True)
class RunReport:
    """One run: Fig. 6, its tables (the Allan figure before table ``allan_at``; after the
    last when it equals their number), warnings beyond the calibration and notes."""

    number: int
    run: Evaluation
    recorded: str  # how long it recorded (and its bursts)
    figure: Plot
    tables: tuple[Table, ...]
    allan: Plot | None
    allan_at: int
    warnings: tuple[str, ...]
    housing_not_applied: bool
    notes: tuple[str, ...]
    heating_cooling: HeatingCooling | None = None  # None: the run was not split


@dataclass(frozen=True)
class ScaleFactor:
    """The scale-factor model: temperature groups of the rate-table holds and k(f)."""

    candidates: tuple[str, ...]
    groups: Table
    equation: str
    residual_ppm: str
    input_rate_max_dps: str


@dataclass(frozen=True)
class AxisReport:
    """One axis's sections; its element ids start with ``prefix`` ("" on a single axis)."""

    name: str
    prefix: str
    model: Model
    sensor: bool
    sensor_table: Table | None  # a sensor thermometer: what it is
    thermometry: Thermometry | None  # a resonator: Figs. 3-5
    runs: tuple[RunReport, ...]
    excluded: tuple[tuple[str, float], ...]  # candidates left out, their p-value if added
    steps: Table | None
    drift: Table | None
    eq22_kept: tuple[str, ...]
    equation: str  # the drift model
    housing: Table | None  # the housing-thermistor baseline and its equation
    housing_equation: str
    scale: ScaleFactor | None


@dataclass(frozen=True)
class PaperReport:
    """Everything the paper report shows (``templates/paper/`` renders it)."""

    title: str
    unit: str
    model_path: str | None
    model_version: str  # the hrgtc that wrote the model file ("?": not recorded)
    model_created_utc: str
    generated_utc: str
    sensor: bool  # the first axis's thermometer is a temperature sensor
    inputs: Table | None  # the model's inputs (provenance)
    single_axis: bool
    glance: Table | None  # one axis: its runs at a glance; several: the instrument's
    axes: tuple[AxisReport, ...]


def paper_report(inputs: ReportInputs) -> PaperReport:
    """The data of the paper report of ``inputs``: each run and soak read once, every axis
    (:func:`hrgtc.report.inputs.evaluate_runs`, :func:`~hrgtc.report.inputs.trace_soaks`)."""
    instrument = inputs.instrument
    first = next(iter(instrument.axes.values()))
    traced = {axis: m.thermometer for axis, m in instrument.axes.items()
              if m.thermometer.source != "sensor"}
    files = [run for run in inputs.runs if not isinstance(run, Evaluation)]
    counter = RowCounter(inputs.progress, [*(inputs.soaks if traced else ()), *files])
    generated = datetime.now(UTC).isoformat(timespec="seconds")
    evaluations = evaluate_runs(inputs, counter.advance)
    traces = trace_soaks(inputs, traced, counter.advance)
    single = instrument.is_single_axis
    axes = tuple(axis_report(axis, "" if single else f"{axis}-", instrument.of_axis(axis),
                             evaluations[axis], traces.get(axis, []), inputs.missing_soaks,
                             instrument.temperature_map)
                 for axis in instrument.axes)
    sensor = first.thermometer.source == "sensor"
    if single:
        glance = (grid_table(glance_summary(evaluations[""], paper_row=not sensor), GLANCE,
                             "At a glance: 10 s bias stability, raw and compensated")
                  if evaluations[""] else None)
    else:
        glance = grid_table(instrument_glance_summary(instrument, evaluations), GLANCE,
                            "At a glance: 10 s bias stability per axis and run")
    provenance = provenance_summary(instrument.provenance)
    counter.finish()
    return PaperReport(
        inputs.title or f"Temperature compensation report — unit {instrument.unit}",
        instrument.unit, inputs.model_path, str(instrument.provenance.get("hrgtc_version", "?")),
        str(instrument.provenance.get("created_utc", "?")), generated, sensor,
        grid_table(provenance, INPUTS, INPUTS) if provenance.sections else None, single,
        glance, axes)


def axis_report(name: str, prefix: str, model: Model,
                evaluations: Sequence[Evaluation] = (), traces: Sequence[SoakTrace] = (),
                missing: Sequence[str] = (),
                temperature_map: dict[str, Any] | None = None) -> AxisReport:
    """One axis ``name`` (its ids start with ``prefix``; ``model``: its one-axis model, see
    :meth:`hrgtc.model.Model.of_axis`): Figs. 3-5 and Tables 1-2 (a sensor
    thermometer: what it is and the map of its count, ``temperature_map``), its runs
    (``evaluations``, with plotting blocks), drift and scale factor; ``traces``: its soaks,
    ``missing``: soak files no longer on disk."""
    sensor = model.thermometer.source == "sensor"
    sensor_table = thermometry = None
    if sensor:
        sensor_table = section_table(
            calibration_summary(model, temperature_map=temperature_map), SENSOR_THERMOMETER,
            "Thermometer: the gyro's temperature sensor" + (
                ", its count mapped to °C by the reference log" if temperature_map
                else ", read directly"))
    else:
        thermometry = _thermometry(model, traces, missing)
    d = model.drift
    summary = calibration_summary(model)
    left_out = [c for c in d.candidates if c not in d.selected]
    return AxisReport(
        name, prefix, model, sensor, sensor_table, thermometry,
        tuple(_run(k, run, model) for k, run in enumerate(evaluations, start=1)),
        tuple(zip(left_out, d.stepwise.excluded_pvalues, strict=True)) if left_out else (),
        section_table(summary, "stepwise steps", "Stepwise steps"),
        section_table(summary, drift_heading(sensor),
                      "The final model: coefficients ± 1σ, p-values, fit"),
        tuple(n for n in d.selected if n in paper.EQ22_TERMS), d.equation(sensor),
        None if model.housing is None else section_table(
            summary, "housing-thermistor baseline", "Classical baseline (housing thermistor)"),
        "" if model.housing is None else model.housing.equation(), _scale_factor(model))


def _scale_factor(model: Model) -> ScaleFactor | None:
    """The scale-factor model's groups, k(f) and fit; None without one."""
    sf = model.scale_factor
    if sf is None:
        return None
    summary = sf.summary()
    shown = summary.figures()
    return ScaleFactor(
        tuple(sf.candidates),
        grid_table(summary, "scale-factor temperature groups",
                   "Temperature groups of the rate-table holds",
                   ("mean frequency", "k", "std error", "model k", "holds")),
        sf.equation(), shown["scale_factor.residual_ppm"].number(),
        shown["scale_factor.input_rate_max_dps"].number())


def _match(plateaus: Sequence[Plateau], source: str) -> list[Plateau]:
    """Plateaus found in ``source``: the same file, else the same file name."""
    same = [p for p in plateaus if p.source and os.path.realpath(p.source)
            == os.path.realpath(source)]
    return same or [p for p in plateaus if p.source and Path(p.source).name == Path(source).name]


def table_rows(model: Model, plateaus: Sequence[Plateau]) -> list[dict[str, float]]:
    """Each plateau's chamber temperature, settled frequency, the temperature from it and its
    error (Table 2 of [1])."""
    t = np.array([p.chamber_c for p in plateaus])
    f = np.array([p.settled_freq_hz for p in plateaus])
    estimate = model.thermometer.temperature(f, warn=False) if f.size else f
    return [{"chamber_c": a, "freq_hz": b, "temperature_c": c, "error_c": c - a}
            for a, b, c in zip(t, f, estimate, strict=True)]


def _thermometry(model: Model, traces: Sequence[SoakTrace],
                 missing: Sequence[str]) -> Thermometry:
    """Fig. 3 and the plateaus, Fig. 4, Table 1 and Eq. 18 beside the paper's, Fig. 5(a),
    Table 2 and Fig. 5(b) with the soaks' error against the truth."""
    th = model.thermometer
    plateaus = [Plateau.from_dict(p) for p in model.plateaus]
    table = table_rows(model, plateaus)
    tables = thermometer_tables(th, plateaus)
    settling, stored = None, False
    if traces:
        settling = plot(figures.settling_figure(
            traces, [_match(plateaus, t.source) for t in traces]),
            "frequency of each soak vs time")
    elif any(p.fit is not None for p in plateaus):
        with_fit = [p for p in plateaus if p.fit is not None]
        settling, stored = plot(figures.settling_figure(
            [None] * len(with_fit), [[p] for p in with_fit]),
            "stored settling fits of each soak"), True
    fit = None if not plateaus else plot(figures.thermometer_figure(
        th, [r["chamber_c"] for r in table], [r["freq_hz"] for r in table],
        [p.settled_freq_std_hz for p in plateaus]), "frequency-temperature fit and residuals")
    high, powers = th.coefficients_high_first, range(th.order, -1, -1)
    terms = " ".join(f"{'−' if c < 0 else '+'} {abs(c):.7g}"
                     + (f"·{power_text('T', n)}" if n else "")
                     for n, c in zip(powers, high, strict=True))
    errors = soak_error_summary(traces)
    return Thermometry(
        tuple(missing), settling, stored, traces[0].block_s if traces else 0.0,
        grid_table(tables, PLATEAUS, "Plateaus of the unit (from the model file)"), fit,
        grid_table(tables, TABLE1, "The unit's Table 1"),
        section_table(calibration_summary(model, table), "thermometer (Eq. 18)",
                      "Thermometer (Eq. 18): coefficients c0 (constant) to c3 (T³) ± 1σ, "
                      "p-values, fit"),
        grid_table(tables, EQ18, "Coefficients beside the paper's, highest power first"),
        terms.lstrip("+ "), 1e3 * th.residual_std_hz,
        plot(figures.temperature_error_figure(table), "temperature error at each plateau")
        if table else None,
        grid_table(tables, TABLE2, "The unit's Table 2"),
        plot(figures.soak_temperature_figure(traces),
             "temperature from frequency during each soak") if traces else None,
        grid_table(errors, SOAK_ERROR, SOAK_ERROR) if errors.sections else None)


def _recorded(run: Evaluation) -> str:
    """How long the run recorded: its samples' time; for a burst logger also its bursts
    and their spacing (the span is many times the recorded time)."""
    text = f"{run.duration_s / 3600:.3g} h recorded"
    burst = next(iter(run.burst_allan.values()), None)
    if burst is not None:
        text += f", in bursts of {burst.burst_s:.3g} s every {burst.period_s:.4g} s"
    return text


def _run(k: int, run: Evaluation, model: Model) -> RunReport:
    """Run ``k``: Fig. 6, its figures as tables, the Allan deviation (before the noise
    terms), its warnings and notes."""
    hrg = model.thermometer.source != "sensor"  # the paper's figures are an HRG's
    summary = run.figures(sensor=not hrg, warnings=False)
    tables, allan_at = [], None
    for heading, _ in summary.sections:
        if heading.startswith(HEATING_COOLING):  # its own table, a row per direction
            continue
        if heading.startswith("Allan") and run.allan and allan_at is None:
            allan_at = len(tables)
        tables.append(_run_table(run, summary, heading, hrg))
    if run.allan and not run.noise:
        allan_at = len(tables)
    return RunReport(
        k, run, _recorded(run),
        plot(figures.run_figure(run, not hrg), f"raw and compensated output of {run.name}"),
        tuple(tables),
        plot(figures.allan_figure(run), f"Allan deviation of {run.name}")
        if allan_at is not None else None,
        len(tables) if allan_at is None else allan_at,
        tuple(line.removeprefix("warning: ") for line in run.range_warnings()),
        model.housing is not None and "housing" not in run.bias_stability_dph,
        tuple(summary.notes),
        None if run.directions is None else heating_cooling(run.directions, run.name, not hrg))


#: The start of the heading of a run's heating and cooling figures
#: (:func:`hrgtc.evaluation.run_figures.run_figures`).
HEATING_COOLING = "heating and cooling apart"


def heating_cooling(directions: DirectionStats, name: str, sensor: bool) -> HeatingCooling:
    """Run ``name``'s heating and cooling apart (``directions``: its
    :attr:`~hrgtc.evaluation.Evaluation.directions`; ``sensor``: the thermometer is a
    temperature sensor, its words)."""
    what = "temperature" if sensor else "resonator temperature"
    block = f"{directions.block_s:g} s"
    caption = (f"Heating and cooling apart of {name}: {block} bias stability by the sign of "
               f"the {what} rate, raw and compensated")
    truth = directions.residual_rms_dph is not None
    if directions.reason is not None:
        return HeatingCooling(caption, directions.block_s, (), truth,
                              (f"Heating and cooling apart: no {block} block "
                               f"({directions.reason}).",))
    total = sum(directions.blocks.values())
    rows, notes = [], []
    for d in DIRECTIONS:
        if not directions.blocks[d]:
            other = next(o for o in DIRECTIONS if o != d)
            notes.append(f"No {d} block: the run's {total} blocks of {block} outside the "
                         f"dead band of the {what} rate were all {other}.")
            continue
        rows.append(Direction(
            d, directions.blocks[d], directions.raw_dph[d], directions.compensated_dph[d],
            directions.improvement(d),
            directions.residual_rms_dph[d] if directions.residual_rms_dph is not None else None))
    return HeatingCooling(caption, directions.block_s, tuple(rows), truth, tuple(notes))


def _run_table(run: Evaluation, summary: Summary, heading: str, hrg: bool) -> Table:
    """A section of the run's figures as a table, its caption naming the run."""
    captions = {"bias stability": f" with its {run.confidence:.3g} chi-squared interval, "
                "(blocks − 1) degrees of freedom" + (
                    " (paper [1], Section 4.2: 3.0143 → 0.5848 °/h on its cool-down)"
                    if hrg else ""),
                "Allan noise terms": " (IEEE Std 952-1997, Annex C)"}
    head, _, detail = heading.partition(" (")
    caption = (f"{head[:1].upper()}{head[1:]} of {run.name}"
               + (f" ({detail}" if detail else "") + captions.get(head, ""))
    return Table(caption, FIGURE_COLUMNS,
                 tuple(tuple(row[1:]) for row in summary.rows() if row[0] == heading))
