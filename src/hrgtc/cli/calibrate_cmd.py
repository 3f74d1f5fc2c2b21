"""``hrgtc calibrate``: soaks -> thermometer, ramps -> drift model, one model file."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from hrgtc.cli._app import console, error_console, fail, library_errors, print_json
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
from hrgtc.settings.inputs import CalibrationInputs

if TYPE_CHECKING:
    from hrgtc.pipeline.axis_calibration import AxisCalibration
    from hrgtc.pipeline.calibration import Calibration
    from hrgtc.recording import ReadOptions

#: The nine candidate terms of Eq. (21) of [1], as the default of --terms.
EQ21_DEFAULT = ",".join(EQ21_TERMS)


def render(result: AxisCalibration, temperature_map: dict[str, Any] | None = None) -> None:
    """Print the axis's Table 1, Table 2 and plateaus (a frequency thermometer:
    :meth:`AxisCalibration.tables`), then its calibration's summary
    (:meth:`AxisCalibration.summary`: thermometer, drift model, stepwise steps, housing
    baseline and held-out runs, a table each, and the Eq. 18 and Eq. 22 forms); the range
    warnings are printed apart. ``temperature_map``: the instrument's map of a sensor's raw
    count (``--temp-ref``), shown as the sensor thermometer's figures."""
    if result.model.thermometer.source != "sensor":
        print_summary(result.tables(), console, notes=False)  # the Eq. 18 form comes below
    print_summary(result.summary(warnings=False, temperature_map=temperature_map), console)


@reading_options
@settings_options(CalibrationSettings)
@settings_options(CalibrationInputs, "given")
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
    force: ForceOption = False,
    strict: StrictOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
    settings: CalibrationSettings | None = None,
    given: CalibrationInputs | None = None,
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
    from hrgtc.model import save_model
    from hrgtc.pipeline.calibration import RateTables, calibrate
    from hrgtc.recording import ReadOptions

    inputs = (inputs or ReadOptions()).with_spike_default("drop")
    given = given or CalibrationInputs()
    ref = given.reference

    soaks = [*(soak or []), *(extra_soaks or [])]
    with library_errors():
        refuse_input(output, [*soaks, *(drift or []), *(validate or []), *(rate_table or []),
                              *(validate_rate_table or []), prior, segments, ref.reference_log])
        refuse_existing(output, force)
        check_writable(output, 1e6)  # before the fit, not after it
        stages: dict[str, object] = {}
        if ref.reference_log is None and ref.described():
            raise fail(f"{ref.described()[0]} describes a reference log: give the log with "
                       "--temp-ref")

        def progress(stage: str, done: float, total: float) -> None:
            if not json_output and stage not in stages:
                stages[stage] = True
                error_console.print(f"[dim]… {stage}[/]")

        calibration = calibrate(
            soaks, drift, validate or (), settings=settings, inputs=given,
            rate_tables=RateTables(rate_table or (), validate_rate_table or (), segments),
            prior=prior, read_options=inputs, progress=progress)
        save_model(calibration.model, output, force=force)
    if json_output:
        print_json({**calibration.to_dict(), "model_file": str(output)})
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
    console.print("Temperature map: " + temperature_map.summary().text())
    if temperature_map.extra.get("note"):
        console.print(f"[yellow]note:[/] {temperature_map.extra['note']}")


def render_instrument(calibration: Calibration) -> None:
    """Each axis as :func:`render`, its scale factor, then the instrument's summary
    (:meth:`Calibration.summary`: held-out rate tables, cross-axis trials and each axis's
    held-out medians)."""
    for axis, result in calibration.axes.items():
        if axis:
            console.rule(f"axis {axis}")
        model = calibration.model.axes[axis]
        render(result, calibration.model.temperature_map)
        if model.scale_factor is not None:
            print_summary(model.scale_factor.summary(), console)
    summary = calibration.summary()
    if summary.sections or summary.notes:  # rate tables, cross-axis trials, the axes
        print_summary(summary, console)
