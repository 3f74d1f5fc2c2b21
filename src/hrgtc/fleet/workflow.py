"""Fleet workflows: simulate, calibrate, evaluate, report and build a prior over many units.

Each function builds one task per unit (:mod:`hrgtc.fleet.tasks`), runs them
with :func:`hrgtc.fleet.run.run_tasks` (sequentially, on a local Dask cluster
or on an existing one) and writes the fleet's outputs: the models and the
fleet table (``fleet.parquet``), the evaluation table, the fleet report, the
prior. The tables are long-form: a row per unit × axis (:mod:`hrgtc.fleet.results`).
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.core.files import refuse_existing
from hrgtc.core.progress import Progress
from hrgtc.fleet import tasks
from hrgtc.fleet.manifest import UnitFiles, load_fleet
from hrgtc.fleet.results import read_table, write_table
from hrgtc.fleet.run import FleetRun, run_tasks
from hrgtc.recording import ReadOptions
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.fleet import FleetCluster, FleetEvaluation, FleetSimulation

__all__ = ["FLEET_TABLE", "build_prior", "calibrate_fleet", "evaluate_fleet", "report_fleet",
           "simulate_fleet"]

PathLike = str | os.PathLike[str]
#: The fleet table written beside the models.
FLEET_TABLE = "fleet.parquet"
#: The evaluation table written beside the models by ``fleet evaluate``.
EVALUATION_TABLE = "evaluation.parquet"


def _fleet(source: PathLike | Sequence[UnitFiles]) -> list[UnitFiles]:
    return list(source) if not isinstance(source, str | os.PathLike) else load_fleet(source)


def simulate_fleet(output: PathLike, settings: FleetSimulation | None = None, *,
                   force: bool = False, cluster: FleetCluster | None = None,
                   progress: Progress | None = None) -> FleetRun:
    """Simulate ``settings.units`` units of the population of ``settings.seed`` under
    ``output/<unit>/`` (instruments of ``settings.axes`` axes when more than one).

    Unit k gets soaks at ``settings.setpoints_c`` (``soaks/``), a cool-down (``drift/``),
    a warm-up (``validate/``) and its ground truth (``truth.json``; an instrument's
    ``truth-<axis>.json`` per axis): the drawn frequency law, thermal constants, bias law
    and noise (:mod:`hrgtc.fleet.population`). ``cluster``: where the units run (default: a local
    Dask cluster, one worker per core).
    """
    settings = settings or FleetSimulation()
    units = settings.units
    if not isinstance(units, int) or units < 1:
        raise InputError(f"--units must be a positive integer, got {units!r}")
    root = Path(output)
    if not force and root.is_dir() and any(root.iterdir()):
        raise InputError(f"{root} is not empty; pass --force to overwrite or give a new folder")
    root.mkdir(parents=True, exist_ok=True)
    work = [(f"s{settings.seed}-u{k:04d}", tasks.simulate_unit, (settings, k, str(root), force))
            for k in range(units)]
    return run_tasks(work, cluster=cluster, progress=progress, label="simulate")


def calibrate_fleet(source: PathLike | Sequence[UnitFiles], output: PathLike, *,
                    settings: CalibrationSettings | None = None,
                    read_options: ReadOptions | None = None, resume: bool = False,
                    force: bool = False, prior: PathLike | None = None,
                    cluster: FleetCluster | None = None,
                    progress: Progress | None = None) -> FleetRun:
    """Calibrate every unit, every axis of it, as one task per unit
    (:func:`hrgtc.fleet.tasks.calibrate_unit`).

    Writes ``output/<unit>.json`` (models: one file per unit, for every axis),
    ``output/<unit>.outcome.json`` and the fleet table ``output/fleet.parquet`` (a row per
    unit × axis). Existing models are refused unless
    ``force`` (recalibrate all) or ``resume`` (skip units whose model exists and
    whose inputs' SHA-256 are unchanged, recalibrate the others).

    Parameters
    ----------
    source
        A manifest, a fleet folder, or the units' files.
    settings
        The calibration's settings (thermometer order, candidate terms, ...), the same for
        every unit; None: the defaults.
    prior
        A prior file: every unit is calibrated with it (:mod:`hrgtc.thermometry.prior`).
    cluster
        Where the units run (default: a local Dask cluster, one worker per core).
    """
    fleet = _fleet(source)
    out = Path(output)
    models = [tasks.model_path(out, u.unit) for u in fleet]
    if not resume:
        refuse_existing([*models, out / FLEET_TABLE], force,
                        "nothing was calibrated; --resume skips unchanged units")
    out.mkdir(parents=True, exist_ok=True)
    work = [(u.unit, tasks.calibrate_unit,
             (u, str(out), settings or CalibrationSettings(), read_options, resume,
              None if prior is None else str(prior)))
            for u in fleet]
    run = run_tasks(work, cluster=cluster, progress=progress, label="calibrate")
    write_table(run.outcomes, out / FLEET_TABLE, force=True)
    return run


def evaluate_fleet(source: PathLike | Sequence[UnitFiles], models: PathLike,
                   output: PathLike | None = None, *, read_options: ReadOptions | None = None,
                   settings: FleetEvaluation | None = None, force: bool = False,
                   cluster: FleetCluster | None = None,
                   progress: Progress | None = None) -> FleetRun:
    """Evaluate each unit's held-out runs with its model, every axis of it; write the
    evaluation table (a row per unit × axis).

    ``output`` defaults to ``<models>/evaluation.parquet``; ``settings``: what is computed
    (default: the Allan noise terms too).
    """
    fleet = _fleet(source)
    target = Path(output) if output is not None else Path(models) / EVALUATION_TABLE
    refuse_existing(target, force)
    allan = (settings or FleetEvaluation()).allan
    work = [(u.unit, tasks.evaluate_unit, (u, str(models), read_options, allan)) for u in fleet]
    run = run_tasks(work, cluster=cluster, progress=progress, label="evaluate")
    write_table(run.outcomes, target, force=force)
    return run


def report_fleet(models: PathLike, output: PathLike, *, table: PathLike | None = None,
                 source: PathLike | Sequence[UnitFiles] | None = None,
                 unit_reports: PathLike | None = None,
                 read_options: ReadOptions | None = None, force: bool = False,
                 cluster: FleetCluster | None = None,
                 progress: Progress | None = None) -> tuple[Path, FleetRun | None]:
    """Write the fleet report from the fleet table; optionally each unit's report as tasks.

    Parameters
    ----------
    models
        The models folder (holding ``fleet.parquet``).
    output
        The fleet report (HTML).
    table
        Another fleet table (default ``<models>/fleet.parquet``).
    source, unit_reports
        With both, each calibrated unit's HTML report (:func:`hrgtc.report.build_report`)
        is written to ``unit_reports/<unit>.html`` as one task per unit.
    """
    from hrgtc.fleet.report import build_fleet_report

    rows = read_table(table or Path(models) / FLEET_TABLE)
    refuse_existing(output, force)
    run = None
    if unit_reports is not None:
        if source is None:
            raise InputError("unit reports need the fleet's files: give the fleet ROOT")
        done = {r["unit"] for r in rows if r["status"] in ("ok", "skipped")}
        fleet = [u for u in _fleet(source) if u.unit in done]
        Path(unit_reports).mkdir(parents=True, exist_ok=True)
        work = [(u.unit, tasks.report_unit, (u, str(models), str(unit_reports), read_options,
                                              force)) for u in fleet]
        run = run_tasks(work, cluster=cluster, progress=progress, label="report")
    return build_fleet_report(rows, output, force=force), run


def build_prior(models: PathLike, output: PathLike | None = None, *, force: bool = False,
                exclude: Sequence[str] = (), axis: str = "") -> Any:
    """The population prior of a models folder (every ``<unit>.json`` model file).

    ``axis``: the axis whose thermometers make the prior ("" : single-axis units; the x
    axes of a fleet of instruments are one population, their y axes another). Models
    without that axis are left out, as are units whose model was fitted with a prior
    themselves (they would feed the prior back into itself) and those in ``exclude``.
    """
    from hrgtc.model import load_model
    from hrgtc.thermometry.prior import ThermometerPrior, save_prior

    folder = Path(models)
    if not folder.is_dir():
        raise InputError(f"{folder}: no such models folder")
    thermometers, names, other_axes = [], [], set()
    for path in sorted(folder.glob("*.json")):
        if path.name.endswith(".outcome.json"):
            continue
        try:
            head = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError):
            continue
        if not isinstance(head, dict) or head.get("schema") != "hrgtc.model":
            continue
        model = load_model(path)
        if axis not in model.axes:
            other_axes.update(model.axes)
            continue
        if model.unit in exclude or "prior" in model.provenance.get("settings", {}):
            continue
        thermometers.append(model.axes[axis].thermometer)
        names.append(model.unit)
    if not thermometers:
        if other_axes:
            raise InputError(
                f"{folder}: no model file has the axis {axis!r}; the models' axes are "
                f"{', '.join(sorted(a or repr('') for a in other_axes))}: pass --axis")
        raise InputError(f"{folder}: no model files; run 'hrgtc fleet calibrate' first")
    prior = ThermometerPrior.from_thermometers(thermometers, names)
    if output is not None:
        save_prior(prior, output, force=force)
    return prior
