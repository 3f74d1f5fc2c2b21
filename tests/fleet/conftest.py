"""Fleets on disk and a Dask cluster, built once for the fleet tests.

``fleet_root``: three simulated single-axis units of seed 5 and a fourth, ``s5-bad``, whose
first soak is a corrupt file; ``instrument_root``: two simulated three-axis instruments of
seed 3 (:func:`hrgtc.fleet.population.draw_instrument`); ``cluster``: a real
``distributed.LocalCluster`` of two single-thread worker processes, reached by its address
as an existing cluster is (``FleetCluster(scheduler=...)``).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from hrgtc.fleet import simulate_fleet
from hrgtc.settings.fleet import FleetCluster, FleetSimulation

# Tiny rates and short soaks: the physics does not depend on the rate.
SMALL = {"sample_rate_hz": 1.0, "soak_hours": 2.5, "ramp_hours": 2.0,
         "setpoints_c": (-20.0, 0.0, 10.0, 20.0, 40.0)}


@pytest.fixture(scope="session")
def fleet_root(tmp_path_factory) -> Path:
    """Three simulated units and a fourth whose first soak is a corrupt file."""
    root = tmp_path_factory.mktemp("fleet")
    run = simulate_fleet(root / "data", FleetSimulation(units=3, seed=5, **SMALL),
                         cluster=FleetCluster(workers=0))
    assert run.counts()["ok"] == 3
    bad = root / "data" / "s5-bad"
    shutil.copytree(root / "data" / "s5-u0000", bad)
    corrupt = sorted((bad / "soaks").glob("*.parquet"))[0]
    corrupt.write_bytes(b"PAR1 this is not a parquet file")
    return root / "data"


@pytest.fixture(scope="session")
def instrument_root(tmp_path_factory) -> Path:
    """Two simulated instruments of three axes (x, y, z) each."""
    root = tmp_path_factory.mktemp("instruments") / "data"
    run = simulate_fleet(root, FleetSimulation(units=2, seed=3, axes=3, **SMALL),
                         cluster=FleetCluster(workers=0))
    assert run.counts()["ok"] == 2
    return root


@pytest.fixture(scope="session")
def cluster():
    """A LocalCluster of two worker processes, one thread each, for the session."""
    import logging

    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None, silence_logs=logging.ERROR,
                      host="127.0.0.1") as local:
        yield FleetCluster(scheduler=local.scheduler_address)
