"""A 10-unit fleet at 10 Hz calibrated on a local Dask cluster of 1 and of 2 workers.

Each unit: 7 soaks of 5 h, a 5 h cool-down and a 5 h warm-up (1.62 M samples, the
paper's campaign at 10 Hz). The fleet is simulated first (not timed, 2 workers);
``hrgtc fleet calibrate`` (:func:`hrgtc.fleet.calibrate_fleet`) then runs with 1 and
with 2 worker processes. Reported: wall time (cluster start included), the
speed-up, units per hour and the peak RSS of each worker process. ``--quick``: 8
units at 2 Hz. 10 units (5 per worker) keep ``make bench`` under 10 minutes; the
per-unit figures do not depend on the fleet's size (each task holds one unit).

``cpu_seconds_per_unit`` (CPU time of the tasks) does not depend on what else the
machine runs; wall time and speed-up do (``load_average_1min`` says how busy it was).
A last line measures what the machine itself allows: the same unit calibrated
``2 x REPEATS`` times by one plain process, then by two processes at once
(``multiprocessing``, no Dask). Its speed-up is the ceiling for the Dask one.
"""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

REPEATS = 2


def _calibrate_repeatedly(soaks: list[str], drifts: list[str], validate: list[str],
                          times: int) -> None:
    import warnings

    from hrgtc.pipeline.calibration import calibrate

    warnings.simplefilter("ignore")
    for _ in range(times):
        calibrate(soaks, drifts, validate)


def _machine_ceiling(unit) -> dict:
    import multiprocessing
    import time

    context = multiprocessing.get_context("spawn")
    args = (list(unit.soaks), list(unit.drifts), list(unit.validate))
    seconds = {}
    for processes in (1, 2):
        with context.Pool(processes) as pool:
            pool.starmap(_calibrate_repeatedly, [(*args, 1)] * processes)  # warm up
            start = time.perf_counter()
            pool.starmap(_calibrate_repeatedly, [(*args, 2 * REPEATS // processes)] * processes)
            seconds[processes] = time.perf_counter() - start
    return {"name": "machine_ceiling_plain_processes", "n": 2 * REPEATS,
            "seconds": round(seconds[2], 2), "seconds_1_process": round(seconds[1], 2),
            "rate": round(2 * REPEATS / seconds[2] * 3600.0),
            "speedup_2_vs_1_process": round(seconds[1] / seconds[2], 2),
            "cores": os.cpu_count(), "load_average_1min": round(os.getloadavg()[0], 2)}


def run(quick: bool = False) -> list[dict]:
    from hrgtc.fleet import calibrate_fleet, simulate_fleet
    from hrgtc.settings.fleet import FleetCluster, FleetSimulation

    units, rate_hz = (8, 2.0) if quick else (10, 10.0)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        simulated = simulate_fleet(
            root / "fleet", FleetSimulation(units=units, seed=1, sample_rate_hz=rate_hz),
            cluster=FleetCluster(workers=2))
        rows = sum(o.row["rows"] for o in simulated.outcomes)
        seconds = {}
        for workers in (1, 2):
            run = calibrate_fleet(root / "fleet", root / f"models-{workers}",
                                  cluster=FleetCluster(workers=workers))
            assert not run.failed, run.failed
            seconds[workers] = run.seconds
            peaks = sorted(run.worker_peak_rss_mb.values())
            cpu = sum(o.cpu_seconds for o in run.outcomes)
            results.append({
                "name": f"fleet_calibrate_{units}units_{workers}workers", "n": units,
                "samples": rows, "sample_rate_hz": rate_hz, "workers": workers,
                "seconds": round(run.seconds, 2), "rate": round(units / run.seconds * 3600.0),
                "units_per_hour": round(units / run.seconds * 3600.0),
                "peak_rss_mb": max(peaks), "peak_rss_mb_per_worker": peaks,
                "cpu_seconds_per_unit": round(cpu / units, 3),
                "units_per_core_hour": round(units / cpu * 3600.0),
                "load_average_1min": round(os.getloadavg()[0], 2),
                "cores": os.cpu_count(),
            })
        results[-1]["speedup_vs_1_worker"] = round(seconds[1] / seconds[2], 2)
        from hrgtc.fleet import load_fleet

        results.append(_machine_ceiling(load_fleet(root / "fleet")[0]))
    return results


if __name__ == "__main__":
    import json

    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
