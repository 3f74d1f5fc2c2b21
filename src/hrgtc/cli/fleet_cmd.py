"""``hrgtc fleet ...``: simulate, calibrate, evaluate and report many units on Dask; the prior.

The commands run one task per unit: on a local Dask cluster (``--workers N``),
on an existing one (``--scheduler tcp://HOST:8786`` or ``DASK_SCHEDULER_ADDRESS``),
or here one after the other (``--workers 0``). A unit that fails is listed with
its file, column and row; the others complete, and the exit code is 1.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from hrgtc.cli._app import console, error_console, library_errors, print_json, progress_bar
from hrgtc.cli.options import ForceOption, JsonOption, reading_options
from hrgtc.cli.params import option, settings_options, split_values
from hrgtc.settings.calibration import CalibrationSettings, ThermometerSettings
from hrgtc.settings.drift import DriftSettings
from hrgtc.settings.fleet import (
    FleetCalibration,
    FleetCluster,
    FleetEvaluation,
    FleetSimulation,
)

if TYPE_CHECKING:
    from hrgtc.fleet import FleetRun
    from hrgtc.recording import ReadOptions

fleet_app = typer.Typer(
    name="fleet", no_args_is_help=True, rich_markup_mode=None,
    help="Many units: simulate, calibrate, evaluate and report them as tasks on Dask, and "
    "build the population prior that cuts chamber time.")

def _models_folder_inputs(models: Path) -> list[Path]:
    """The files of a models folder that fleet commands read (never an output, see -o)."""
    if not models.is_dir():
        return []
    return [p for p in models.iterdir() if p.suffix in (".json", ".parquet")]


def _finish(run: FleetRun, json_output: bool, written: str) -> None:
    """Print the outcome per unit (or JSON) and exit 1 when some units failed."""
    if json_output:
        print_json({"summary": run.summary().text(), "counts": run.counts(),
                    "seconds": run.seconds,
                    "where": run.where, "written": written,
                    "workers_died": run.workers_died, "retried": list(run.retried),
                    "units": [{"unit": o.unit, "status": o.status, "error": o.error,
                               "seconds": o.seconds} for o in run.outcomes]})
    else:  # the failed units' table, then the line
        from hrgtc.cli.summary_tables import print_summary

        print_summary(run.summary(), console)
        console.print(f"Written: {written}")
    if run.failed:
        raise typer.Exit(1)


@fleet_app.command("simulate")
@settings_options(FleetSimulation)
@settings_options(FleetCluster, "cluster")
def simulate_command(
    output: Annotated[Path, typer.Option("-o", "--output", help="Fleet folder to write.")] = Path(
        "fleet"),
    force: ForceOption = False,
    json_output: JsonOption = False,
    settings: FleetSimulation | None = None,
    cluster: FleetCluster | None = None,
) -> None:
    """Simulate a population of units, each with its truth (truth.json) beside its files.

    Example: hrgtc fleet simulate --units 32 --seed 1 -o fleet/
    """
    from hrgtc.fleet import simulate_fleet

    with library_errors():
        with progress_bar("units", enabled=not json_output) as progress:
            run = simulate_fleet(output, settings, force=force, cluster=cluster,
                                 progress=progress)
    _finish(run, json_output, str(output))


@fleet_app.command("calibrate")
@reading_options
@settings_options(FleetCalibration, "which")
@settings_options(FleetCluster, "cluster")
def calibrate_command(
    root: Annotated[Path, typer.Argument(
        help="Fleet folder (ROOT/<unit>/{soaks,drift,validate}/) or manifest (.csv, .yaml).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Models folder.")] = Path(
        "models"),
    order: int = option(ThermometerSettings, "order"),
    terms: str | None = option(DriftSettings, "terms"),
    force: ForceOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
    which: FleetCalibration | None = None,
    cluster: FleetCluster | None = None,
) -> None:
    """Calibrate every unit of a fleet, every axis of it: a model per unit and the fleet
    table (fleet.parquet, a row per unit and axis).

    Example: hrgtc fleet calibrate fleet/ -o models/ --workers 4
    """
    from hrgtc.fleet import calibrate_fleet, load_fleet

    settings = CalibrationSettings(
        thermometer=ThermometerSettings(order=order),
        drift=DriftSettings(terms=None if terms is None else split_values(terms, str)))
    which = which or FleetCalibration()
    with library_errors():
        fleet = load_fleet(root, list(which.units) or None)
        with progress_bar("units", enabled=not json_output) as progress:
            run = calibrate_fleet(fleet, output, settings=settings, read_options=inputs,
                                  resume=which.resume, force=force, prior=which.prior,
                                  cluster=cluster, progress=progress)
    _finish(run, json_output, f"{output}/<unit>.json, {output}/fleet.parquet")


@fleet_app.command("evaluate")
@reading_options
@settings_options(FleetEvaluation)
@settings_options(FleetCluster, "cluster")
def evaluate_command(
    root: Annotated[Path, typer.Argument(help="Fleet folder or manifest.")],
    models: Annotated[Path, typer.Option("--models", help="Models folder.")] = Path("models"),
    output: Annotated[Path | None, typer.Option(
        "-o", "--output", help="Evaluation table [default: MODELS/evaluation.parquet].")] = None,
    force: ForceOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
    settings: FleetEvaluation | None = None,
    cluster: FleetCluster | None = None,
) -> None:
    """Evaluate each unit's held-out runs (validate/, else drift/) with its model.

    Example: hrgtc fleet evaluate fleet/ --models models/
    """
    from hrgtc.core.files import refuse_input
    from hrgtc.fleet import evaluate_fleet

    with library_errors():
        if output is not None:
            refuse_input(output, _models_folder_inputs(models))
        with progress_bar("units", enabled=not json_output) as progress:
            run = evaluate_fleet(root, models, output, read_options=inputs, settings=settings,
                                 force=force, cluster=cluster, progress=progress)
    _finish(run, json_output, str(output or models / "evaluation.parquet"))


@fleet_app.command("report")
@reading_options
@settings_options(FleetCluster, "cluster")
def report_command(
    models: Annotated[Path, typer.Argument(help="Models folder (with fleet.parquet).")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Fleet report (HTML).")] = Path(
        "fleet.html"),
    unit_reports: Annotated[Path | None, typer.Option(
        "--unit-reports", help="Also write each unit's report into this folder (needs --root)."
    )] = None,
    root: Annotated[Path | None, typer.Option(
        "--root", help="Fleet folder or manifest (for --unit-reports).")] = None,
    force: ForceOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
    cluster: FleetCluster | None = None,
) -> None:
    """Write the fleet report: distributions, outliers (robust z), failed units with reasons.

    Example: hrgtc fleet report models/ -o fleet.html
    """
    from hrgtc.core.files import refuse_input
    from hrgtc.fleet import report_fleet

    with library_errors():
        refuse_input(output, _models_folder_inputs(models))
        with progress_bar("units", enabled=not json_output and unit_reports is not None) as bar:
            path, run = report_fleet(models, output, source=root, unit_reports=unit_reports,
                                     read_options=inputs, force=force, cluster=cluster,
                                     progress=bar)
    if run is not None:
        _finish(run, json_output, f"{path}, {unit_reports}/<unit>.html")
    elif json_output:
        print_json({"written": str(path)})
    else:
        console.print(f"Fleet report written to {path}")


@fleet_app.command("prior")
def prior_command(
    models: Annotated[Path, typer.Argument(help="Models folder of calibrated units.")],
    output: Annotated[Path, typer.Option("-o", "--output", help="Prior file (JSON).")] = Path(
        "prior.json"),
    exclude: Annotated[list[str] | None, typer.Option(
        "--exclude", help="Leave this unit out (repeat for more).")] = None,
    axis: Annotated[str, typer.Option(
        "--axis", help="The axis of instruments whose thermometers make the prior (x, y, "
        "...); none for single-axis units.")] = "",
    force: ForceOption = False,
    json_output: JsonOption = False,
) -> None:
    """Population prior of the thermometer: mean and covariance of the relative coefficients
    (of one axis of a fleet of instruments: --axis).

    Example: hrgtc fleet prior models/ -o prior.json, then
    hrgtc calibrate --prior prior.json --soak s-20.parquet --soak s40.parquet --drift ...
    """
    from hrgtc.core.files import refuse_input
    from hrgtc.fleet import build_prior

    with library_errors():
        refuse_input(output, _models_folder_inputs(models))
        prior = build_prior(models, output, force=force, exclude=exclude or (), axis=axis)
    if json_output:
        print_json(prior.to_dict())
        return
    console.print(prior.summary().text(), markup=False)
    error_console.print(f"Prior written to {output}")
