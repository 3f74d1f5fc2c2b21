"""``hrgtc export-c``: the unit's compensation as dependency-free C99 (double or float32) or as
a documented parameter file, for firmware."""

from __future__ import annotations

from pathlib import Path

import typer

from hrgtc.cli._app import console, library_errors, print_json
from hrgtc.cli.options import ForceOption, JsonOption
from hrgtc.cli.params import option
from hrgtc.settings.export import ExportSettings


def export_c_command(
    model: Path = typer.Argument(
        ..., help="Model file written by 'hrgtc calibrate' (one gyro, or every axis of an "
                  "instrument: then <prefix>_<axis>_model.h/.c per axis)."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the files."),
    prefix: str = option(ExportSettings, "prefix"),
    precision: str = option(ExportSettings, "precision"),
    output_format: str = option(ExportSettings, "output_format"),
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

    with library_errors():
        files = export_c(model, output, prefix=prefix, force=force,
                         precision=precision, output_format=output_format)
    if json_output:
        print_json({"model": str(model), "prefix": prefix, "precision": precision,
                    "format": output_format, "files": [str(p) for p in files]})
        return
    for path in files:
        console.print(f"wrote {path}", soft_wrap=True)
