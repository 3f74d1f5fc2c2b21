"""``hrgtc info FILE``: summarise and validate a recording."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from hrgtc.cli._app import app, console, fail, library_errors, print_json
from hrgtc.cli.options import (
    ColumnsOption,
    FreqUnitOption,
    GapPolicy,
    GapsOption,
    InputRateOption,
    JsonOption,
    RateHzOption,
    RateUnitOption,
    TimeUnitOption,
    UnitNameOption,
    recording_input,
)
from hrgtc.recording_info import describe


@app.command("info")
def info(
    file: Annotated[Path, typer.Argument(help="Recording (.parquet, .pq, .csv, .h5, .hdf5).")],
    col: ColumnsOption = None,
    time_unit: TimeUnitOption = None,
    freq_unit: FreqUnitOption = None,
    rate_unit: RateUnitOption = None,
    rate_hz: RateHzOption = None,
    unit_name: UnitNameOption = None,
    input_rate_dph: InputRateOption = None,
    gaps: GapsOption = GapPolicy.error,
    json_output: JsonOption = False,
) -> None:
    """Duration, sample rate, columns, temperature and frequency spans, gaps, validation.

    Exits with code 2 and the validation message when the recording is bad (with
    --json the report, ok=false and its problems, is printed first).
    """
    inputs = recording_input(
        col, time_unit, freq_unit, rate_unit, rate_hz, unit_name, input_rate_dph
    )
    with library_errors():
        result = describe(file, **inputs.read_kwargs(), gaps=gaps.value)
    if json_output:
        print_json(result.to_dict())
    else:
        console.print(result.summary(), markup=False)
    if not result.ok:
        raise fail(result.validation.message)
