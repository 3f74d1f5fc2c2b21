"""``hrgtc compensate`` and ``hrgtc evaluate``: apply a model to a run, and measure the gain."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hrgtc.cli._app import (
    console,
    error_console,
    library_errors,
    print_json,
    progress_bar,
)
from hrgtc.cli.options import (
    STRICT_EXIT,
    AxesOption,
    ForceOption,
    JsonOption,
    StrictOption,
    reading_options,
)
from hrgtc.cli.params import option
from hrgtc.settings.compensation import CompensateSettings, EvaluationSettings

if TYPE_CHECKING:
    from hrgtc.compensate.ranges import RangeReport
    from hrgtc.evaluation import Evaluation
    from hrgtc.evaluation.run_evaluation import RunEvaluation
    from hrgtc.model import Model
    from hrgtc.recording import ReadOptions


def note_unchecked(model: Model, model_path: Path) -> None:
    """Say once, on stderr after the work, that an older model file has no training
    statistics, so the recording's rate unit was not checked against them."""
    if any(unit.training is None for unit in model.axes.values()):
        error_console.print(
            f"note: {model_path} has no statistics of its training data (written by an older "
            "hrgtc): the recording's rate noise was not checked against them for a unit "
            "mistake; recalibrate to have it checked", soft_wrap=True)


def warn_ranges(reports: list[RangeReport | None], json_output: bool, strict: bool,
                labels: list[str] | None = None) -> None:
    """Print the range warnings (on stderr beside --json); with ``strict`` exit 3 if any.

    ``labels`` name the reports (the axes): a warning with the same cause on several
    axes is printed once, naming them (its first axis's numbers).
    """
    from hrgtc.cli._app import warning_cause

    groups: dict[str, list[tuple[str, str]]] = {}
    for k, report in enumerate(reports):
        if report is None:
            continue
        label = labels[k] if labels and k < len(labels) else ""
        for line in report.warnings():
            groups.setdefault(warning_cause(line), []).append((line, label))
    for members in groups.values():
        line, label = members[0]
        named = [m[1] for m in members if m[1]]
        if len(members) > 1 and named:
            same = all(m[0] == line for m in members)
            line += (f" (axes {', '.join(named)})" if same else
                     f" (axis {label}; the same cause on {', '.join(named[1:])})")
        (error_console if json_output else console).print(f"[yellow]{line}[/]")
    if strict and groups:
        raise typer.Exit(STRICT_EXIT)


@reading_options
def compensate_command(
    run: Path = typer.Argument(..., help="Recording to compensate (.parquet, .csv, .h5)."),
    model_path: Path = typer.Option(..., "--model", "-m", help="Model file from 'calibrate'."),
    output: Path = typer.Option(..., "-o", "--output", help="Output recording (format by suffix)."),
    chunk_rows: int = option(CompensateSettings, "chunk_rows"),
    force: ForceOption = False,
    strict: StrictOption = False,
    json_output: JsonOption = False,
    axes: AxesOption = None,
    inputs: ReadOptions | None = None,
) -> None:
    """Compensate a run file to file: adds rate_comp_dph, bias_model_dph, resonator_c_est
    and in_range (and scale_model_ppm with a scale factor), chunk by chunk (memory bounded
    whatever the file size). A multi-axis model compensates every axis: rate_comp_dph_x, ...
    With --thermometer sensor the output keeps temperature_c and carries no freq_hz* or
    resonator_c_est* copies of it; spikes are flagged in a 'spike' column, never dropped.

    Example: hrgtc compensate warmup.parquet --model unit.json -o warmup_comp.parquet
    """
    from hrgtc.compensate import compensate_file
    from hrgtc.compensate.multi_axis import parse_axes
    from hrgtc.core.files import refuse_input
    from hrgtc.model import load_model
    from hrgtc.recording import ReadOptions

    inputs = (inputs or ReadOptions()).with_spike_default("flag")
    with library_errors(), progress_bar("compensating", enabled=not json_output) as progress:
        refuse_input(output, [run, model_path])
        model = load_model(model_path)
        summary = compensate_file(run, output, model_path, force=force,
                                  settings=CompensateSettings(chunk_rows), progress=progress,
                                  read_options=inputs, axes=parse_axes(axes))
    if json_output:
        print_json(summary.to_dict())
    else:
        axes = "" if model.is_single_axis else f" (axes {', '.join(model.names)}; the worst)"
        shares = (f"{summary.out_of_range_fraction:.2%} outside the calibrated temperature "
                  f"range, {summary.rate_out_of_range_fraction:.2%} with df/dt beyond its "
                  "training range") if summary.ranges is None else \
            f"beyond the trained ranges: {summary.ranges.shares_text()}"
        console.print(f"wrote {summary.output}: {summary.rows} rows; {shares}{axes}")
        if summary.accounting is not None:  # flagged, never dropped
            console.print(summary.accounting.summary().text(), markup=False)
    note_unchecked(model, model_path)
    warn_ranges([summary.ranges], json_output, strict)


#: Blocks of the run at which ``evaluate`` propagates the model's coefficient covariance.
PREDICTION_BLOCKS = 2000


def render_evaluation(result: Evaluation, sensor: bool = False) -> None:
    """The run's figures (its :meth:`~hrgtc.evaluation.Evaluation.figures`) as tables,
    beside the paper's figures; the range warnings are :func:`warn_ranges`'s.

    ``sensor``: the thermometer is a temperature sensor (a MEMS gyro, not an HRG):
    the compensated rows say so and the paper's HRG figures are left out.
    """
    from hrgtc.cli.summary_tables import print_summary
    from hrgtc.thermometry import paper

    print_summary(result.figures(sensor=sensor, warnings=False), console)
    if not sensor:  # the paper's figures are an HRG's
        console.print(f"paper, Section 4.2 (10 s): {paper.BIAS_STABILITY_RAW_DPH} → "
                      f"{paper.BIAS_STABILITY_COMPENSATED_DPH} °/h", markup=False)


@reading_options
def evaluate_command(
    run: Path = typer.Argument(..., help="Recording to evaluate."),
    model_path: Path = typer.Option(..., "--model", "-m", help="Model file from 'calibrate'."),
    deviation: str = option(EvaluationSettings, "deviation"),
    allan_csv: Path | None = typer.Option(
        None, "--allan-csv",
        help="Also write the curves: series, tau_s, deviation, lower, upper, n."),
    force: ForceOption = False,
    strict: StrictOption = False,
    json_output: JsonOption = False,
    axes: AxesOption = None,
    inputs: ReadOptions | None = None,
) -> None:
    """Bias stability at 1, 10, 100 s (with 1σ intervals) and Allan noise terms, raw vs
    compensated (and vs the housing-thermistor baseline when the run has housing_c);
    with a multi-axis model, each axis and the instrument's summary.

    Example: hrgtc evaluate warmup.parquet --model unit.json --deviation oadev
    --allan-csv warmup_allan.csv --json
    """
    from hrgtc.compensate.multi_axis import parse_axes
    from hrgtc.core.files import refuse_existing, refuse_input, write_text_atomic
    from hrgtc.evaluation import evaluate
    from hrgtc.evaluation.run_evaluation import warn_worse_than_raw
    from hrgtc.evaluation.run_pass import DEVIATIONS
    from hrgtc.model import load_model
    from hrgtc.recording import ReadOptions

    inputs = (inputs or ReadOptions()).with_spike_default("drop")
    if deviation not in DEVIATIONS:
        error_console.print(f"error: --deviation {deviation!r} is not known; use one of "
                            f"{', '.join(DEVIATIONS)}")
        raise typer.Exit(2)
    with library_errors():
        if allan_csv is not None:
            refuse_input(allan_csv, [run, model_path])
            refuse_existing(allan_csv, force)
        model = load_model(model_path)
        with progress_bar("evaluating", enabled=not json_output) as progress:
            result = evaluate(
                model, run, axes=parse_axes(axes), read_options=inputs,
                settings=EvaluationSettings(deviation=deviation),
                max_points=PREDICTION_BLOCKS, progress=progress, model_source=str(model_path))
        if allan_csv is not None:
            write_text_atomic(allan_csv, result.allan_csv(), force=force)
    render_instrument_evaluation(result, json_output)
    warn_worse_than_raw(result)
    note_unchecked(model, model_path)
    warn_ranges([r.ranges for r in result.axes.values()], json_output, strict,
                list(result.axes))


def render_instrument_evaluation(result: RunEvaluation, json_output: bool) -> None:
    """``hrgtc evaluate``'s output: each axis's table, then the instrument's summary (the
    axes side by side, the scale-factor check: :meth:`RunEvaluation.summary`), or the
    JSON document (the scale check on stderr)."""
    from hrgtc.cli.summary_tables import print_summary

    model = result.model
    sensor = {axis: m.thermometer.source == "sensor" for axis, m in model.axes.items()}
    if json_output:
        print_json(result.to_dict())
    else:  # a heading per named axis (the one axis of a single-axis model has none)
        for axis, evaluation in result.axes.items():
            if axis:
                console.rule(f"axis {axis}")
            render_evaluation(evaluation, sensor[axis])
    checks = result.scale_checks
    if checks and json_output:
        error_console.print("scale factor: " + "; ".join(
            f"axis {c.axis or '-'} {c.raw_max_ppm:.1f} → {c.compensated_max_ppm:.1f} ppm"
            for c in checks))
    elif not json_output:
        print_summary(result.summary(), console)
