"""``hrgtc calibrate``: soaks -> thermometer, ramps -> drift model, one model file."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from hrgtc.cli._app import app, console, error_console, fail, library_errors, print_json
from hrgtc.cli.compensate_cmd import warn_ranges
from hrgtc.cli.options import (
    STRICT_EXIT,
    ForceOption,
    JsonOption,
    StrictOption,
    reading_options,
)
from hrgtc.cli.params import settings_options
from hrgtc.cli.summary_tables import print_summary
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.drift import EQ21_TERMS

if TYPE_CHECKING:
    from hrgtc.pipeline.calibration import CalibrationResult
    from hrgtc.pipeline.instrument import InstrumentCalibration
    from hrgtc.recording import ReadOptions

#: The nine candidate terms of Eq. (21) of [1], as the default of --terms.
EQ21_DEFAULT = ",".join(EQ21_TERMS)


def render(result: CalibrationResult) -> None:
    """Print the unit's Table 1, Table 2 and plateaus (a frequency thermometer:
    :meth:`CalibrationResult.tables`), then the calibration's summary
    (:meth:`CalibrationResult.summary`: thermometer, drift model, stepwise steps, housing
    baseline and held-out runs, a table each, and the Eq. 18 and Eq. 22 forms); the range
    warnings are printed apart."""
    if result.model.thermometer.source != "sensor":
        print_summary(result.tables(), console, notes=False)  # the Eq. 18 form comes below
    print_summary(result.summary(warnings=False), console)


@app.command("calibrate")
@reading_options
@settings_options(CalibrationSettings)
def calibrate_command(
    extra_soaks: list[Path] = typer.Argument(
        None, metavar="[SOAK_FILES]...",
        help="More soak files (so a shell glob after --soak works: --soak soaks/*.parquet).",
    ),
    soak: list[Path] = typer.Option(
        None, "--soak", help="Soak recording (one per set-point, or one holding several)."),
    drift: list[Path] = typer.Option(
        ..., "--drift", help="Ramp recording to fit the drift model on (repeat for more)."),
    validate: list[Path] = typer.Option(
        None, "--validate", help="Held-out run: bias stability raw vs compensated."),
    output: Path = typer.Option(..., "-o", "--output", help="Model file to write (JSON)."),
    aux: list[str] = typer.Option(
        None, "--aux", metavar="NAME=COLUMN", help="An extra logged channel (drive amplitude, "
        "quadrature control voltage) as variable a_NAME, centred on its training mean; the "
        "term a_NAME joins the candidates. compensate/evaluate read the same column."),
    prior: Path = typer.Option(
        None, "--prior", help="Population prior (hrgtc fleet prior): a Bayesian thermometer "
        "fit, so that 2 or 3 soaks suffice."),
    rate_table: list[Path] = typer.Option(
        None, "--rate-table", help="Rate-table run (known input rates at several temperatures: "
        "an input_rate_dph column or --segments): fits the scale factor against frequency."),
    validate_rate_table: list[Path] = typer.Option(
        None, "--validate-rate-table",
        help="Held-out rate-table run: scale-factor error [ppm] before and after."),
    segments: Path = typer.Option(
        None, "--segments", help="CSV start_s,end_s,input_rate_dph of the rate-table holds, for "
        "files without an input_rate_dph column."),
    temp_ref: Path = typer.Option(
        None, "--temp-ref", help="Reference log of the temperature (sparse, e.g. a hand log "
        "every 5 min) written beside the first --drift run: fits its raw temperature count's "
        "map to °C (residual printed, the reference's lag fitted), stores it in the model and "
        "compensation applies it. Columns time_s (seconds, clock times HH:MM[:SS] or dates) "
        "and temperature_c by default (--temp-ref-col)."),
    temp_ref_col: list[str] = typer.Option(
        None, "--temp-ref-col", metavar="NAME=THEIRS", help="The reference log's columns, e.g. "
        "--temp-ref-col time_s=Time --temp-ref-col 'temperature_c=C1 (C)'."),
    temp_ref_start: str = typer.Option(
        None, "--temp-ref-start", metavar="CLOCK", help="Clock time of the recording's t = 0 "
        "(15:40, or 2020-03-07T15:40:00+01:00) when the log has clock times; default: the "
        "recording's first time stamp."),
    temp_ref_unit: str = typer.Option(
        None, "--temp-ref-unit", metavar="C|F", help="Unit of the reference temperature "
        "[default: F when its header says (F), °F or degF, else C]."),
    temp_ref_tz: str = typer.Option(
        None, "--temp-ref-tz", metavar="ZONE", help="Time zone of naive clock times (+01:00, "
        "Europe/Berlin) when the other side carries a UTC offset."),
    temp_ref_lag_s: float = typer.Option(
        None, "--temp-ref-lag-s", help="The reference's lag behind the sensor [s; default: "
        "fitted within ±1800 s]."),
    holdout_s: float = typer.Option(
        None, "--holdout-s", help="Hold out the last SECONDS of recorded time of the --drift "
        "file (cut at a segment start: a burst is never split) and validate on it [s]."),
    holdout_fraction: float = typer.Option(
        None, "--holdout-fraction", help="Hold out this share of the --drift file's recorded "
        "time at its end (e.g. 0.25) and validate on it."),
    force: ForceOption = False,
    strict: StrictOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
    settings: CalibrationSettings | None = None,
) -> None:
    """Calibrate a gyro or a whole instrument: soak plateaus -> thermometer (Eq. 18), ramps ->
    drift model (Eq. 22), rate tables -> scale factor; every axis of a multi-axis file.

    Example: hrgtc calibrate --soak soaks/*.parquet --drift cooldown.parquet
    --validate warmup.parquet -o unit.json

    With a population prior, 2 or 3 soaks: hrgtc calibrate --prior prior.json
    --soak soak_-20C.parquet --soak soak_40C.parquet --drift cooldown.parquet -o unit.json

    A three-axis unit with scale factor: hrgtc calibrate --soak soaks/*.parquet
    --drift cooldown.parquet --rate-table ratetable.parquet --validate warmup.parquet
    --validate-rate-table ratetable_heldout.parquet -o imu.json

    A gyro without a frequency output (its temperature sensor as the thermometer):
    hrgtc calibrate --thermometer sensor --drift cooldown.csv --drift warmup.csv -o imu.json
    """
    from hrgtc.core.files import check_writable, refuse_existing, refuse_input
    from hrgtc.model import save_instrument
    from hrgtc.pipeline.calibration import parse_aux
    from hrgtc.pipeline.instrument import calibrate_instrument
    from hrgtc.recording import ReadOptions
    from hrgtc.thermometry.reference import TemperatureReference, parse_reference_columns

    inputs = (inputs or ReadOptions()).with_spike_default("drop")

    soaks = [*(soak or []), *(extra_soaks or [])]
    with library_errors():
        refuse_input(output, [*soaks, *(drift or []), *(validate or []), *(rate_table or []),
                              *(validate_rate_table or []), prior, segments, temp_ref])
        refuse_existing(output, force)
        check_writable(output, 1e6)  # before the fit, not after it
        stages: dict[str, object] = {}
        ref_options = {"--temp-ref-col": temp_ref_col, "--temp-ref-start": temp_ref_start,
                       "--temp-ref-unit": temp_ref_unit, "--temp-ref-tz": temp_ref_tz,
                       "--temp-ref-lag-s": temp_ref_lag_s}
        stray = [name for name, value in ref_options.items() if value not in (None, [])]
        if temp_ref is None and stray:
            raise fail(f"{stray[0]} describes a reference log: give the log with --temp-ref")
        reference = None if temp_ref is None else TemperatureReference(
            temp_ref, parse_reference_columns(temp_ref_col), unit=temp_ref_unit,
            start=temp_ref_start, tz=temp_ref_tz, lag_s=temp_ref_lag_s)

        def progress(stage: str, done: float, total: float) -> None:
            if not json_output and stage not in stages:
                stages[stage] = True
                error_console.print(f"[dim]… {stage}[/]")

        calibration = calibrate_instrument(
            soaks, drift, validate or (), holdout_s=holdout_s, holdout_fraction=holdout_fraction,
            settings=settings, aux=parse_aux(aux or []), read_options=inputs,
            progress=progress, prior=prior, thermometer=inputs.thermometer,
            rate_tables=rate_table or (), validate_rate_tables=validate_rate_table or (),
            segment_table=segments, temperature_reference=reference,
        )
        save_instrument(calibration.model, output, force=force)
    if json_output:
        print_json({**calibration.document(), "model_file": str(output)})
    else:
        render_map(calibration.model.temperature_map)
        render_instrument(calibration)
        console.print(f"Model written to {output}")
    beyond = calibration.range_reports()
    for file, reports in beyond.items():  # beyond the trained ranges: --strict
        axes = [axis for axis in reports if axis]
        (error_console if json_output else console).print(
            f"{file}:" if len(axes) != 1 else f"{file}, axis {axes[0]}:")
        warn_ranges(list(reports.values()), json_output, strict=False,
                    labels=list(reports) if len(axes) > 1 else None)
    if strict and beyond:
        raise typer.Exit(STRICT_EXIT)


def render_map(stored: dict[str, Any] | None) -> None:
    """The model's temperature map (``--temp-ref``): its line and its note, if any."""
    if stored is None:
        return
    from hrgtc.thermometry.reference import TemperatureMap

    temperature_map = TemperatureMap.from_dict(stored)
    console.print("Temperature map: " + temperature_map.summary())
    if temperature_map.extra.get("note"):
        console.print(f"[yellow]note:[/] {temperature_map.extra['note']}")


def render_instrument(calibration: InstrumentCalibration) -> None:
    """Each axis as :func:`render`, its scale factor, then the instrument's summary
    (:meth:`InstrumentCalibration.summary`: held-out rate tables, cross-axis trials and
    each axis's held-out medians)."""
    from dataclasses import replace

    for axis, result in calibration.axes.items():
        if axis:
            console.rule(f"axis {axis}")
        model = calibration.model.axes[axis]
        render(replace(result, model=model, validation=calibration.validation.get(axis, ())))
        if model.scale_factor is not None:
            print_summary(model.scale_factor.summary(), console)
    summary = calibration.summary()
    if summary.sections or summary.notes:  # rate tables, cross-axis trials, the axes
        print_summary(summary, console)
