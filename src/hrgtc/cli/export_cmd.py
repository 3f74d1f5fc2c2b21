"""``hrgtc export-c``: the unit's compensation as dependency-free C99 (double or float32) or as
a documented parameter file, for firmware."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path

import typer

from hrgtc.cli._app import app, console, library_errors, print_json
from hrgtc.cli.options import ForceOption, JsonOption


class Precision(StrEnum):
    """Floating type of the C code."""

    double = "double"
    single = "single"


class ExportFormat(StrEnum):
    """What the export writes."""

    c = "c"
    params = "params"


@app.command("export-c")
def export_c_command(
    model: Path = typer.Argument(
        ..., help="Model file written by 'hrgtc calibrate' (one gyro, or every axis of an "
                  "instrument: then <prefix>_<axis>_model.h/.c per axis)."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the files."),
    prefix: str = typer.Option(
        "hrgtc", "--prefix", help="C name prefix: <prefix>_model.h, <prefix>_step(), ..."
    ),
    precision: Precision = typer.Option(
        Precision.double, "--precision",
        help="double (default), or single: float32 for FPU-only MCUs (Cortex-M4F), the "
             "frequency passed centred, the worst error against double stated in the header.",
    ),
    output_format: ExportFormat = typer.Option(
        ExportFormat.c, "--format",
        help="c (default): <prefix>_model.h and .c; params: <prefix>_params.txt, key = value "
             "lines, every number documented, for firmware that evaluates its own polynomials.",
    ),
    force: ForceOption = False,
    json_output: JsonOption = False,
) -> None:
    """Write <prefix>_model.h and <prefix>_model.c: the causal df/dt filter, the drift model
    of Eq. (22), the thermometer inverse, the scale factor when calibrated and a streaming
    step() API (C99, math.h only); or, with --format params, the same numbers as a
    documented parameter file. An instrument's file gives every axis, each its own prefix.

    Example: hrgtc export-c unit.json -o firmware/ --precision single
    """
    from hrgtc.export import export_c

    if output_format is ExportFormat.params and precision is Precision.single:
        raise typer.BadParameter("--precision applies to --format c only; the parameter file "
                                 "holds doubles (%.17g)", param_hint="'--precision'")
    with library_errors():
        files = export_c(model, output, prefix=prefix, force=force,
                         precision=precision.value, output_format=output_format.value)
    if json_output:
        print_json({"model": str(model), "prefix": prefix, "precision": precision.value,
                    "format": output_format.value, "files": [str(p) for p in files]})
        return
    for path in files:
        console.print(f"wrote {path}", soft_wrap=True)
