"""``hrgtc compensate`` and ``hrgtc evaluate``: apply a model to a run, and measure the gain."""

from __future__ import annotations

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


#: Blocks of the run at which ``evaluate`` propagates the model's coefficient covariance.
PREDICTION_BLOCKS = 2000


def render_evaluation(result: Evaluation) -> None:
    """Bias stability table raw / compensated / housing, beside the paper's figures."""
    from hrgtc import paper

    table = Table(title=f"Bias stability of {result.file} (1σ of τ-s means, °/h; "
                  f"{result.confidence:.3g} chi-squared interval)")
    table.add_column("output")
    taus = list(result.bias_stability_dph["raw"])
    for tau in taus:
        table.add_column(f"τ = {tau:g} s", justify="right")
    labels = {"raw": "raw", "compensated": "compensated (frequency, Eq. 22)",
              "housing": "compensated (housing thermistor)"}
    for name in result.bias_stability_dph:
        table.add_row(labels.get(name, name), *(result.stability_text(name, t) for t in taus))
    table.add_row("paper, Section 4.2 (10 s)", *(
        f"{paper.BIAS_STABILITY_RAW_DPH} → {paper.BIAS_STABILITY_COMPENSATED_DPH}"
        if t == 10.0 else "" for t in taus))
    console.print(table)
    if result.noise:
        allan = Table(title="Allan noise terms (IEEE Std 952)")
        for column in ("output", "ARW (°/√h)", "bias instability (°/h)", "RRW (°/h/√h)"):
            allan.add_column(column, justify="right")
        for name, terms in result.noise.items():
            allan.add_row(labels.get(name, name), terms.text("arw"),
                          terms.text("bias_instability"), terms.text("rrw"))
        console.print(allan)
    console.print(
        f"improvement at 10 s: {result.improvement_10s:.2f}×; outside the calibrated range: "
        f"{result.out_of_range_fraction:.2%}; df/dt beyond training: "
        f"{result.rate_out_of_range_fraction:.2%}"
    )
    if result.prediction_std_dph is not None:
        std = result.prediction_std_dph
        console.print(f"1σ of the drift model line (coefficient covariance): median "
                      f"{std['median']:.4g} °/h, max {std['max']:.4g} °/h")
    if result.residual_rms_dph is not None:
        console.print(f"RMS of true bias minus model: {result.residual_rms_dph:.4f} °/h")
    if result.directions is not None:
        console.print(result.directions.summary(), markup=False)
    for note in result.notes:
        console.print(note)


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
    inputs: ReadOptions | None = None,
) -> None:
    """Bias stability at 1, 10, 100 s (with 1σ intervals) and Allan noise terms, raw vs
    compensated (and vs the housing-thermistor baseline when the run has housing_c).

    Example: hrgtc evaluate warmup.parquet --model unit.json --deviation oadev
    --allan-csv warmup_allan.csv --json
    """
    from hrgtc.evaluation import evaluate
    from hrgtc.evaluation.run_pass import DEVIATIONS
    from hrgtc.files import refuse_existing, write_text_atomic
    from hrgtc.model import load_model

    if deviation not in DEVIATIONS:
        error_console.print(f"error: --deviation {deviation!r} is not known; use one of "
                            f"{', '.join(DEVIATIONS)}")
        raise typer.Exit(2)
    with library_errors():
        if allan_csv is not None:
            refuse_existing(allan_csv, force)
    with library_errors(), progress_bar("evaluating", enabled=not json_output) as progress:
        result = evaluate(run, load_model(model_path), progress=progress, read_options=inputs,
                          deviation=deviation, max_points=PREDICTION_BLOCKS)
        if allan_csv is not None:
            write_text_atomic(allan_csv, result.allan_csv(), force=force)
    if json_output:
        print_json(result.to_dict())
    else:
        render_evaluation(result)
    warn_ranges([result.ranges], json_output, strict)
