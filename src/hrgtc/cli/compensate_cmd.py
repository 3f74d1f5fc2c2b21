"""``hrgtc compensate`` and ``hrgtc evaluate``: apply a model to a run, and measure the gain."""

from __future__ import annotations

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
from hrgtc.cli.options import STRICT_EXIT, ForceOption, JsonOption, StrictOption, reading_options

if TYPE_CHECKING:
    from hrgtc.compensate.ranges import RangeReport
    from hrgtc.evaluation import Evaluation
    from hrgtc.recording import ReadOptions


def warn_ranges(reports: list[RangeReport | None], json_output: bool, strict: bool) -> None:
    """Print the range warnings (on stderr beside --json); with ``strict`` exit 3 if any."""
    lines = [line for report in reports if report is not None for line in report.warnings()]
    for line in lines:
        (error_console if json_output else console).print(f"[yellow]{line}[/]")
    if strict and lines:
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
    inputs: ReadOptions | None = None,
) -> None:
    """Compensate a run file to file: adds rate_comp_dph, bias_model_dph, resonator_c_est
    and in_range, chunk by chunk (memory bounded whatever the file size).

    Example: hrgtc compensate warmup.parquet --model unit.json -o warmup_comp.parquet
    """
    from hrgtc.compensate import compensate_file
    from hrgtc.model import load_model

    with library_errors(), progress_bar("compensating", enabled=not json_output) as progress:
        model = load_model(model_path)
        summary = compensate_file(run, output, model, force=force, chunk_rows=chunk_rows,
                                  progress=progress, read_options=inputs)
    if json_output:
        print_json(summary.to_dict())
    else:
        console.print(
            f"wrote {summary.output}: {summary.rows} rows; "
            f"{summary.out_of_range_fraction:.2%} outside the calibrated temperature range, "
            f"{summary.rate_out_of_range_fraction:.2%} with df/dt beyond its training range"
        )
    warn_ranges([summary.ranges], json_output, strict)


def render_evaluation(result: Evaluation) -> None:
    """Bias stability table raw / compensated / housing, beside the paper's figures."""
    from hrgtc import paper

    table = Table(title=f"Bias stability of {result.file} (1σ of τ-s means, °/h)")
    table.add_column("output")
    taus = list(result.bias_stability_dph["raw"])
    for tau in taus:
        table.add_column(f"τ = {tau:g} s", justify="right")
    labels = {"raw": "raw", "compensated": "compensated (frequency, Eq. 22)",
              "housing": "compensated (housing thermistor)"}
    for name, row in result.bias_stability_dph.items():
        table.add_row(labels.get(name, name),
                      *("-" if math.isnan(row[t]) else f"{row[t]:.4f}" for t in taus))
    table.add_row("paper, Section 4.2 (10 s)", *(
        f"{paper.BIAS_STABILITY_RAW_DPH} → {paper.BIAS_STABILITY_COMPENSATED_DPH}"
        if t == 10.0 else "" for t in taus))
    console.print(table)
    if result.noise:
        allan = Table(title="Allan noise terms (IEEE Std 952)")
        for column in ("output", "ARW (°/√h)", "bias instability (°/h)", "RRW (°/h/√h)"):
            allan.add_column(column, justify="right")
        for name, terms in result.noise.items():
            def fmt(v: float | None) -> str:
                return "-" if v is None or not math.isfinite(v) else f"{v:.4g}"

            allan.add_row(labels.get(name, name), fmt(terms.arw_deg_per_rt_h),
                          fmt(terms.bias_instability_dph), fmt(terms.rrw_dph_per_rt_h))
        console.print(allan)
    console.print(
        f"improvement at 10 s: {result.improvement_10s:.2f}×; outside the calibrated range: "
        f"{result.out_of_range_fraction:.2%}; df/dt beyond training: "
        f"{result.rate_out_of_range_fraction:.2%}"
    )
    if result.residual_rms_dph is not None:
        console.print(f"RMS of true bias minus model: {result.residual_rms_dph:.4f} °/h")


@app.command("evaluate")
@reading_options
def evaluate_command(
    run: Path = typer.Argument(..., help="Recording to evaluate."),
    model_path: Path = typer.Option(..., "--model", "-m", help="Model file from 'calibrate'."),
    strict: StrictOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
) -> None:
    """Bias stability at 1, 10, 100 s and Allan noise terms, raw vs compensated (and vs the
    housing-thermistor baseline when the run has housing_c).

    Example: hrgtc evaluate warmup.parquet --model unit.json --json
    """
    from hrgtc.evaluation import evaluate
    from hrgtc.model import load_model

    with library_errors(), progress_bar("evaluating", enabled=not json_output) as progress:
        result = evaluate(run, load_model(model_path), progress=progress, read_options=inputs)
    if json_output:
        print_json(result.to_dict())
    else:
        render_evaluation(result)
    warn_ranges([result.ranges], json_output, strict)
