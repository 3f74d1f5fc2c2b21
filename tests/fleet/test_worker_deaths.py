"""A fleet whose workers die says so (issue 21): how many died, which units ran again.

A real LocalCluster of two workers runs three units; the task of one unit kills its
worker process on its first attempt (``os._exit``, as the kernel's OOM killer would),
Dask runs it again on a fresh worker, and the :class:`~hrgtc.fleet.FleetRun` (its
summary line and the CLI's JSON fields) names the death and the unit.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import cloudpickle
import pytest

from hrgtc.fleet.run import FleetRun, run_tasks, worker_deaths
from hrgtc.fleet.tasks import UnitOutcome
from hrgtc.settings.fleet import FleetCluster

cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the workers cannot import tests


def _dies_once(unit: str, marker: str) -> UnitOutcome:
    """Kill this worker process the first time (the marker file records the attempt)."""
    if unit == "u1" and not Path(marker).exists():
        Path(marker).write_text("died once\n")
        os._exit(1)
    return UnitOutcome(unit, "ok", {"unit": unit}, None, 0.0)


@pytest.mark.slow
def test_a_worker_that_dies_is_reported_with_the_unit_run_again(tmp_path):
    marker = str(tmp_path / "attempt")
    tasks = [(u, _dies_once, (u, marker)) for u in ("u0", "u1", "u2")]
    run = run_tasks(tasks, cluster=FleetCluster(workers=2))
    assert run.counts() == {"ok": 3, "skipped": 0, "failed": 0}  # Dask ran it again
    assert run.workers_died == 1
    assert run.retried == ("u1",)
    assert "1 worker process(es) died during the run" in run.summary().text()
    assert "run again: u1" in run.summary().text()


def test_without_deaths_the_summary_says_nothing_of_them():
    run = FleetRun((UnitOutcome("a", "ok"),), 1.0, "sequential")
    assert "died" not in run.summary().text() and run.workers_died == 0 and run.retried == ()


def test_worker_deaths_reads_the_scheduler_events():
    keys = {"hrgtc-unit-a-1234": "a", "hrgtc-unit-b-1234": "b"}
    events = [
        (5.0, {"action": "remove-worker", "processing-tasks": {"hrgtc-unit-b-1234"},
               "expected": False}),
        (6.0, {"action": "remove-worker", "processing-tasks": set(), "expected": True}),
        (1.0, {"action": "remove-worker", "processing-tasks": {"hrgtc-unit-a-1234"},
               "expected": False}),  # before this run
        (7.0, {"action": "remove-worker", "processing-tasks": {"other-job-key"},
               "expected": False}),  # another client's task on a shared cluster
        (8.0, {"action": "add-worker"}),
    ]
    assert worker_deaths(events, keys, since=2.0) == (1, ("b",))
