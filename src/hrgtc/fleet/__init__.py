"""Fleets: many units calibrated, evaluated and reported as tasks on Dask; a population prior.

Takes a fleet on disk (a manifest ``unit, role, path`` or the folders
``ROOT/<unit>/{soaks,drift,validate}/``) of single-axis units or multi-axis
instruments and gives one model per unit, the fleet table (Parquet, long-form: a
row per unit × axis), the fleet report (HTML, per axis) and the population prior
of the thermometer (:mod:`hrgtc.thermometry.prior`). The parts:

- :mod:`~hrgtc.fleet.manifest`: which files belong to which unit;
- :mod:`~hrgtc.fleet.population`: a simulated population (units or instruments) and its
  documented spread;
- :mod:`~hrgtc.fleet.tasks`: one unit's work, paths in, a small outcome out;
- :mod:`~hrgtc.fleet.run`: the driver (sequential, local Dask cluster, remote scheduler);
- :mod:`~hrgtc.fleet.results`: the fleet table, a row per unit × axis;
- :mod:`~hrgtc.fleet.report`: the fleet report;
- :mod:`~hrgtc.fleet.workflow`: the workflows behind ``hrgtc fleet ...``.
"""

from __future__ import annotations

from hrgtc.fleet.manifest import UnitFiles, load_fleet
from hrgtc.fleet.run import FleetRun, run_tasks
from hrgtc.fleet.tasks import UnitOutcome
from hrgtc.fleet.workflow import (
    build_prior,
    calibrate_fleet,
    evaluate_fleet,
    report_fleet,
    simulate_fleet,
)

__all__ = [
    "FleetRun",
    "UnitFiles",
    "UnitOutcome",
    "build_prior",
    "calibrate_fleet",
    "evaluate_fleet",
    "load_fleet",
    "report_fleet",
    "run_tasks",
    "simulate_fleet",
]
