"""``hrgtc export-c``: the unit's compensation as dependency-free C99 for firmware."""

from __future__ import annotations

from pathlib import Path

import typer

from hrgtc.cli._app import app, console, library_errors, print_json
from hrgtc.cli.options import ForceOption, JsonOption


@app.command("export-c")
def export_c_command(
    model: Path = typer.Argument(..., help="Model file written by 'hrgtc calibrate'."),
    output: Path = typer.Option(..., "-o", "--output", help="Folder for the .h and .c files."),
    prefix: str = typer.Option(
        "hrgtc", "--prefix", help="C name prefix: <prefix>_model.h, <prefix>_step(), ..."
    ),
    force: ForceOption = False,
    json_output: JsonOption = False,
) -> None:
    """Write <prefix>_model.h and <prefix>_model.c: the causal df/dt filter, the drift model
    of Eq. (22), the thermometer inverse and a streaming step() API (C99, math.h only).

    Example: hrgtc export-c unit.json -o firmware/
    """
    from hrgtc.compensate import export_c

    with library_errors():
        files = export_c(model, output, prefix=prefix, force=force)
    if json_output:
        print_json({"model": str(model), "prefix": prefix, "files": [str(p) for p in files]})
        return
    for path in files:
        console.print(f"wrote {path}", soft_wrap=True)
