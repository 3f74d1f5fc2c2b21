"""``hrgtc compensate`` and ``hrgtc evaluate``: apply a model to a run, and measure the gain."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import TYPE_CHECKING

import typer
from rich.table import Table

from hrgtc.cli._app import (
    app,
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

if TYPE_CHECKING:
    from hrgtc.compensate.ranges import RangeReport
    from hrgtc.evaluation import Evaluation
    from hrgtc.model import InstrumentModel
    from hrgtc.recording import ReadOptions


def note_unchecked(model: InstrumentModel, model_path: Path) -> None:
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


@app.command("compensate")
@reading_options
def compensate_command(
    run: Path = typer.Argument(..., help="Recording to compensate (.parquet, .csv, .h5)."),
    model_path: Path = typer.Option(..., "--model", "-m", help="Model file from 'calibrate'."),
    output: Path = typer.Option(..., "-o", "--output", help="Output recording (format by suffix)."),
    chunk_rows: int = typer.Option(1 << 20, "--chunk-rows", help="Rows per processing chunk."),
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
    from hrgtc.compensate import compensate_instrument_file
    from hrgtc.compensate.instrument import parse_axes
    from hrgtc.compensate.model_fit import check_thermometer_kind
    from hrgtc.files import refuse_input
    from hrgtc.model import load_instrument
    from hrgtc.recording import ReadOptions
    from hrgtc.thermometry.reference import options_with_map

    inputs = (inputs or ReadOptions()).with_spike_default("flag")
    if inputs.spike_filter == "drop":
        error_console.print("error: compensate flags spikes, it never drops a row: use "
                            "--spike-filter flag (a 'spike' column marks them) or off")
        raise typer.Exit(2)
    with library_errors(), progress_bar("compensating", enabled=not json_output) as progress:
        refuse_input(output, [run, model_path])
        model = load_instrument(model_path)
        inputs = options_with_map(inputs, model.temperature_map)
        for unit_model in model.axes.values():  # the error names the model file
            check_thermometer_kind(inputs, unit_model, model_path)
        summary = compensate_instrument_file(run, output, model, force=force,
                                             chunk_rows=chunk_rows, progress=progress,
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
            console.print(summary.accounting.summary(), markup=False)
    note_unchecked(model, model_path)
    warn_ranges([summary.ranges], json_output, strict)


#: Blocks of the run at which ``evaluate`` propagates the model's coefficient covariance.
PREDICTION_BLOCKS = 2000


def render_evaluation(result: Evaluation, sensor: bool = False) -> None:
    """Bias stability table raw / compensated / housing, beside the paper's figures.

    ``sensor``: the thermometer is a temperature sensor (a MEMS gyro, not an HRG):
    the compensated row says so and the paper's HRG figures are left out.
    """
    from hrgtc import paper

    table = Table(title=f"Bias stability of {result.file} (1σ of τ-s means, °/h; "
                  f"{result.confidence:.3g} chi-squared interval)")
    table.add_column("output")
    taus = list(result.bias_stability_dph["raw"])
    for tau in taus:
        table.add_column(f"τ = {tau:g} s", justify="right")
    labels = {"raw": "raw", "compensated": ("compensated (temperature sensor)" if sensor
                                            else "compensated (frequency, Eq. 22)"),
              "housing": "compensated (housing thermistor)"}
    for name in result.bias_stability_dph:
        table.add_row(labels.get(name, name), *(result.stability_text(name, t) for t in taus))
    if not sensor:  # the paper's figures are an HRG's
        table.add_row("paper, Section 4.2 (10 s)", *(
            f"{paper.BIAS_STABILITY_RAW_DPH} → {paper.BIAS_STABILITY_COMPENSATED_DPH}"
            if t == 10.0 else "" for t in taus))
    console.print(table)
    console.print("offset and spread the bias stability does not show: " + "; ".join(
        f"{name} {result.offset_text(name)}" for name in result.bias_stability_dph),
        markup=False)
    if result.noise:
        allan = Table(title="Allan noise terms (IEEE Std 952)")
        for column in ("output", "ARW (°/√h)", "bias instability (°/h)", "RRW (°/h/√h)"):
            allan.add_column(column, justify="right")
        for name, terms in result.noise.items():
            allan.add_row(labels.get(name, name), terms.text("arw"),
                          terms.text("bias_instability"), terms.text("rrw"))
        console.print(allan)
    shares = (f"outside the calibrated range: {result.out_of_range_fraction:.2%}; df/dt "
              f"beyond training: {result.rate_out_of_range_fraction:.2%}"
              if result.ranges is None else
              f"beyond the trained ranges: {result.ranges.shares_text()}")
    console.print(f"improvement at 10 s: {result.improvement_10s:.2f}×; compensated "
                  f"{result.offset_text()}; {shares}")
    if result.prediction_std_dph is not None:
        std = result.prediction_std_dph
        console.print(f"1σ of the drift model line (coefficient covariance): median "
                      f"{std['median']:.4g} °/h, max {std['max']:.4g} °/h")
    if result.residual_rms_dph is not None:
        console.print(f"RMS of true bias minus model: {result.residual_rms_dph:.4f} °/h")
    if result.n_not_at_rest:
        console.print(f"{result.n_not_at_rest} samples not at rest left out of the figures "
                      f"({result.n_not_at_rest / result.n_samples:.1%}; --motion keep uses them)")
    if result.directions is not None:
        console.print(result.directions.summary(sensor=sensor), markup=False)
    for note in result.notes:
        console.print(note)
    if result.accounting is not None:
        console.print(result.accounting.summary(), markup=False)


@app.command("evaluate")
@reading_options
def evaluate_command(
    run: Path = typer.Argument(..., help="Recording to evaluate."),
    model_path: Path = typer.Option(..., "--model", "-m", help="Model file from 'calibrate'."),
    deviation: str = typer.Option(
        "oadev", "--deviation",
        help="Deviation curve: oadev (overlapping Allan), adev (non-overlapping), mdev "
             "(modified), hdev (Hadamard), tdev (time). Noise terms come from adev/oadev."),
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
    from hrgtc.compensate.instrument import match_axes, parse_axes, recording_axes
    from hrgtc.compensate.model_fit import check_thermometer_kind
    from hrgtc.evaluation import evaluate
    from hrgtc.evaluation.run_pass import DEVIATIONS
    from hrgtc.files import refuse_existing, refuse_input, write_text_atomic
    from hrgtc.model import load_instrument
    from hrgtc.recording import ReadOptions
    from hrgtc.thermometry.reference import options_with_map

    inputs = (inputs or ReadOptions()).with_spike_default("drop")

    if deviation not in DEVIATIONS:
        error_console.print(f"error: --deviation {deviation!r} is not known; use one of "
                            f"{', '.join(DEVIATIONS)}")
        raise typer.Exit(2)
    with library_errors():
        if allan_csv is not None:
            refuse_input(allan_csv, [run, model_path])
            refuse_existing(allan_csv, force)
    results: dict[str, Evaluation] = {}
    with library_errors():
        model = load_instrument(model_path)
        inputs = options_with_map(inputs, model.temperature_map)
        for unit_model in model.axes.values():  # before reading the recording's axes
            check_thermometer_kind(inputs, unit_model, model_path)
        model = match_axes(model, recording_axes(run, inputs), parse_axes(axes), str(run),
                           str(model_path))
    for axis, unit_model in model.axes.items():
        label = "evaluating" + (f" axis {axis}" if axis else "")
        with library_errors(), progress_bar(label, enabled=not json_output) as progress:
            results[axis] = evaluate(
                run, unit_model, progress=progress, deviation=deviation,
                read_options=dataclasses.replace(inputs, axis=axis or None),
                max_points=PREDICTION_BLOCKS)
    with library_errors():
        if allan_csv is not None:
            write_text_atomic(allan_csv, allan_text(results), force=force)
    sensor = {axis: m.thermometer.source == "sensor" for axis, m in model.axes.items()}
    if model.is_single_axis:
        if json_output:
            print_json(results[""].to_dict())
        else:
            render_evaluation(results[""], sensor[""])
    elif json_output:
        summary = [{k: None if isinstance(v, float) and not math.isfinite(v) else v
                    for k, v in row.items()} for row in axis_summary(results)]  # NaN: no figure
        print_json({"unit": model.unit, "axes": {a: r.to_dict() for a, r in results.items()},
                    "summary": summary})
    else:
        for axis, result in results.items():
            console.rule(f"axis {axis}")
            render_evaluation(result, sensor[axis])
        render_axis_summary(model.unit, results)
    checks = scale_checks(run, model, inputs)
    if checks and json_output:
        error_console.print("scale factor: " + "; ".join(
            f"axis {c.axis or '-'} {c.raw_max_ppm:.1f} → {c.compensated_max_ppm:.1f} ppm"
            for c in checks))
    elif checks:
        render_scale_checks(checks)
    note_unchecked(model, model_path)
    warn_ranges([r.ranges for r in results.values()], json_output, strict, list(results))


def scale_checks(run: Path, model: InstrumentModel, inputs: ReadOptions) -> tuple:
    """The scale-factor check of a rate-table run (it has input_rate_dph columns) when the
    model has a scale factor; () otherwise."""
    from hrgtc.instrument import check_scale_factor

    if all(m.scale_factor is None for m in model.axes.values()):
        return ()
    names = inputs.head(run).names
    if not any(n == "input_rate_dph" or n.startswith("input_rate_dph_") for n in names):
        return ()
    return check_scale_factor(run, model, inputs)


def render_scale_checks(checks: tuple) -> None:
    """Scale-factor error at each temperature of a rate-table run, raw → compensated."""
    table = Table(title="Scale-factor error (ppm) at each temperature of the rate table "
                  "(slope of rate − Ω against Ω, IEEE Std 1431), raw → compensated")
    for column in ("axis", "frequency (Hz)", "holds", "raw", "compensated"):
        table.add_column(column, justify="right")
    for check in checks:
        for f, n, raw, comp in zip(check.freq_hz, check.holds, check.raw_ppm,
                                   check.compensated_ppm, strict=True):
            table.add_row(check.axis or "-", f"{f:.4f}", str(n), f"{raw:+.2f}", f"{comp:+.2f}")
    console.print(table)


def allan_text(results: dict[str, Evaluation]) -> str:
    """The Allan CSV of every axis (an ``axis`` column first when there are several)."""
    if list(results) == [""]:
        return results[""].allan_csv()
    lines: list[str] = []
    for axis, result in results.items():
        header, *rows = result.allan_csv().splitlines()
        if not lines:
            lines.append("axis," + header)
        lines.extend(f"{axis},{row}" for row in rows)
    return "\n".join(lines) + "\n"


def axis_summary(results: dict[str, Evaluation]) -> list[dict[str, float | str]]:
    """One row per axis: 10 s bias stability raw and compensated, improvement, ranges."""
    return [{"axis": axis, "raw_10s_dph": r.raw_10s, "compensated_10s_dph": r.compensated_10s,
             "improvement_10s": r.improvement_10s,
             "compensated_mean_dph": r.mean_dph.get("compensated", float("nan")),
             "compensated_rms_dph": r.rms_dph.get("compensated", float("nan")),
             "out_of_range_fraction": r.out_of_range_fraction,
             "rate_out_of_range_fraction": r.rate_out_of_range_fraction}
            for axis, r in results.items()]


def render_axis_summary(unit: str, results: dict[str, Evaluation]) -> None:
    """The instrument's summary table: one row per axis."""
    table = Table(title=f"{unit}: 10 s bias stability per axis (°/h)")
    for column in ("axis", "raw", "compensated", "improvement", "comp. mean", "comp. RMS",
                   "beyond T", "beyond df/dt"):
        table.add_column(column, justify="right")
    for row in axis_summary(results):
        table.add_row(str(row["axis"]), f"{row['raw_10s_dph']:.4f}",
                      f"{row['compensated_10s_dph']:.4f}", f"{row['improvement_10s']:.2f}×",
                      f"{row['compensated_mean_dph']:+.4g}", f"{row['compensated_rms_dph']:.4g}",
                      f"{row['out_of_range_fraction']:.1%}",
                      f"{row['rate_out_of_range_fraction']:.1%}")
    console.print(table)
