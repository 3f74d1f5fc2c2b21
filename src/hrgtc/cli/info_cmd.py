"""``hrgtc info FILE``: summarise and validate a recording."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from hrgtc.cli._app import console, fail, library_errors, print_json
from hrgtc.cli.options import JsonOption, reading_options

if TYPE_CHECKING:
    from hrgtc.recording import ReadOptions


@reading_options
def info(
    file: Annotated[Path, typer.Argument(help="Recording (.parquet, .pq, .csv, .h5, .hdf5).")],
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
) -> None:
    """Duration, sample rate, columns, temperature and frequency spans, gaps, validation.

    Exits with code 2 and the validation message when the recording is bad (with
    --json the report, ok=false and its problems, is printed first).
    """
    from hrgtc.recording import describe

    with library_errors():
        result = describe(file, inputs)
    if json_output:
        print_json(result.to_dict())
    else:
        console.print(result.summary().text(), markup=False)
    if not result.ok:
        raise fail(result.validation.message)
