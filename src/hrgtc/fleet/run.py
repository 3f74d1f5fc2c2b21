"""The fleet driver: one task per unit on Dask, a local cluster or an existing one.

Where the tasks run:

* ``workers=0``: in this process, one unit after the other (no Dask; the
  reference the parallel runs are tested against, bit for bit);
* ``scheduler="tcp://host:8786"`` (or the ``DASK_SCHEDULER_ADDRESS``
  environment variable, Dask's ``scheduler-address`` setting): an existing
  Dask cluster, unchanged; its workers need hrgtc installed and the unit files
  at the same paths (a shared file system);
* otherwise an in-process :class:`distributed.LocalCluster` on this machine,
  ``workers`` processes of one thread each (default: one per core, at most one
  per unit), started and stopped around the run.

Only paths, settings and the small outcomes cross between the client and the
workers; the workers read the data. Tasks never raise (:mod:`hrgtc.fleet.tasks`);
a worker that dies (out of memory, killed) fails its unit, not the run: Dask
runs its unit again elsewhere (up to 3 deaths), and :class:`FleetRun` says how many
workers died and which units were run again.
Dask is imported only here and only when a cluster is used.
"""

from __future__ import annotations

import os
import time
import uuid
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from hrgtc.core.process import peak_rss_mb
from hrgtc.core.progress import Progress
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.fleet.tasks import UnitOutcome, error_record
from hrgtc.settings.fleet import FleetCluster

#: The heading of a fleet run's table of failed units.
FAILED = "Failed units"

__all__ = ["FleetRun", "Task", "run_tasks", "scheduler_address", "worker_deaths"]

#: ``(unit, function, args)``: one unit's task.
Task = tuple[str, Callable[..., UnitOutcome], tuple[Any, ...]]


@dataclass(frozen=True)
class FleetRun:
    """Outcomes of a fleet run and how it ran.

    Attributes
    ----------
    outcomes
        One per unit, in name order.
    seconds
        Wall time, cluster start included. [s]
    where
        ``"sequential"``, ``"local cluster of N workers"`` or the scheduler address.
    worker_peak_rss_mb
        Peak resident set size of each worker process (local cluster only). [MB]
    workers_died
        Worker processes that died during the run (out of memory, killed); Dask
        runs the units they held again on another worker.
    retried
        The units whose task was running on a worker that died, so ran again (their
        outcome is that of the last attempt; after 3 deaths the unit fails).
    """

    outcomes: tuple[UnitOutcome, ...]
    seconds: float
    where: str
    worker_peak_rss_mb: dict[str, float] = field(default_factory=dict)
    workers_died: int = 0
    retried: tuple[str, ...] = ()

    @property
    def failed(self) -> list[UnitOutcome]:
        """The units that failed."""
        return [o for o in self.outcomes if o.status == "failed"]

    def counts(self) -> dict[str, int]:
        """Units per status."""
        out: dict[str, int] = {"ok": 0, "skipped": 0, "failed": 0}
        for o in self.outcomes:
            out[o.status] = out.get(o.status, 0) + 1
        return out

    def summary(self) -> Summary:
        """Units done, skipped and failed, the wall time, the workers that died, and each
        failed unit's error (type, file, column, row, message) as a table; its text one
        line (the table is the CLI's, before it)."""
        c = self.counts()
        figures = [Figure("units", "units", len(self.outcomes)),
                   Figure("seconds", "wall time", self.seconds, "s",
                          definition="Wall time of the run, cluster start included."),
                   Figure("where", "where", self.where),
                   *(Figure(f"counts.{status}", status, c[status])
                     for status in ("ok", "skipped", "failed"))]
        line = ("{units} units in {seconds:.1f} s ({where}): {counts.ok} done, "
                "{counts.skipped} skipped (unchanged), {counts.failed} failed")
        if self.workers_died:
            units = ", ".join(self.retried) if self.retried else "none"
            figures.append(Figure("workers_died", "worker processes died", self.workers_died))
            line += ("; {workers_died} worker process(es) died during the run and "
                     f"{len(self.retried)} unit(s) were run again: {escape(units)}")
        failed: list[Figure] = []
        for k, o in enumerate(self.failed):
            e = o.error or {}
            cells = (("unit", o.unit), ("error", str(e.get("type"))),
                     ("file", str(e.get("file") or "–")), ("column", str(e.get("column") or "–")),
                     ("row", str(e.get("row") or "–")),
                     ("message", (str(e.get("message", "")).splitlines() or [""])[0][:200]))
            failed += [Figure(f"failed[{k}].{column}", f"{o.unit}: {column}", value, row=o.unit,
                              column=column) for column, value in cells]
        return Summary("fleet run", (("run", tuple(figures)), (FAILED, tuple(failed))),
                       layout=(line,))


def scheduler_address(scheduler: str | None = None) -> str | None:
    """The scheduler to use: ``scheduler``, else ``DASK_SCHEDULER_ADDRESS`` / Dask's config."""
    if scheduler:
        return scheduler
    if os.environ.get("DASK_SCHEDULER_ADDRESS"):
        return os.environ["DASK_SCHEDULER_ADDRESS"]
    try:
        import dask

        return dask.config.get("scheduler-address", None) or None
    except ImportError:  # pragma: no cover - dask is a dependency
        return None


def _sequential(tasks: Sequence[Task], progress: Progress | None) -> list[UnitOutcome]:
    outcomes = []
    for done, (_unit, function, args) in enumerate(tasks, start=1):
        outcomes.append(function(*args))
        if progress is not None:
            progress(done, len(tasks))
    return outcomes


def worker_deaths(events: Sequence[tuple[float, Any]], keys: dict[str, str],
                  since: float) -> tuple[int, tuple[str, ...]]:
    """Workers that died since ``since`` and the units they were running, from scheduler events.

    Parameters
    ----------
    events
        The scheduler's ``"all"`` events, ``(time, message)`` (``Client.get_events``).
    keys
        Task key -> unit of this run.
    since
        Start of the run (``time.time()``). [s]

    Returns
    -------
    (int, tuple of str)
        Unexpected worker removals (a death, not a shutdown) and the units whose
        task was processing on the worker, in name order.
    """
    died, units = 0, set()
    for stamp, message in events:
        if not isinstance(message, dict) or message.get("action") != "remove-worker":
            continue
        if stamp < since or message.get("expected"):
            continue
        mine = {keys[k] for k in message.get("processing-tasks", ()) if k in keys}
        if mine or not keys:
            died += 1
        units |= mine
    return died, tuple(sorted(units))


def _on_cluster(client: Any, tasks: Sequence[Task], progress: Progress | None,
                label: str) -> tuple[list[UnitOutcome], int, tuple[str, ...]]:
    from distributed import as_completed

    run_id = uuid.uuid4().hex[:8]
    since = time.time()
    futures = {
        client.submit(function, *args, key=f"hrgtc-{label}-{unit}-{run_id}", pure=False,
                      retries=0): unit
        for unit, function, args in tasks
    }
    keys = {future.key: unit for future, unit in futures.items()}
    outcomes = []
    for done, future in enumerate(as_completed(futures), start=1):
        unit = futures[future]
        start = time.perf_counter()
        try:
            outcomes.append(future.result())
        except Exception as exc:  # the worker died (memory, signal): this unit fails
            outcomes.append(UnitOutcome(unit, "failed", {}, error_record(exc),
                                        time.perf_counter() - start))
        future.release()
        if progress is not None:
            progress(done, len(tasks))
    try:
        events = client.get_events("all")
    except Exception:  # an old scheduler without events: nothing to say
        events = ()
    died, retried = worker_deaths(events, keys, since)
    return outcomes, died, retried


def run_tasks(tasks: Sequence[Task], *, cluster: FleetCluster | None = None,
              progress: Progress | None = None, label: str = "unit") -> FleetRun:
    """Run one task per unit (module docstring for where) and gather the outcomes.

    Parameters
    ----------
    tasks
        ``(unit, function, args)`` each; ``function(*args)`` returns a
        :class:`~hrgtc.fleet.tasks.UnitOutcome` and must be importable by the workers.
    cluster
        Where the tasks run: ``cluster.scheduler``, the address of an existing Dask
        scheduler (default ``DASK_SCHEDULER_ADDRESS``); else a local cluster of
        ``cluster.workers`` processes (default: cores, at most one per unit); 0 workers
        runs the tasks here, one after the other.
    progress
        ``progress(units_done, units_total)``.
    label
        Part of the Dask task keys (what the dashboard shows).
    """
    from hrgtc.core.errors import InputError

    start = time.perf_counter()
    scheduler, workers = (cluster or FleetCluster()).scheduler, (cluster or FleetCluster()).workers
    if workers is not None and workers < 0:
        raise InputError(f"workers must be >= 0, got {workers}")
    address = None if workers == 0 and not scheduler else scheduler_address(scheduler)
    peaks: dict[str, float] = {}
    died, retried = 0, ()
    if address is None and workers == 0:
        outcomes, where = _sequential(tasks, progress), "sequential"
    elif not tasks:
        outcomes, where = [], "nothing to do"
    elif address is not None:
        from distributed import Client

        try:
            client = Client(address, timeout="20s")
        except OSError as exc:
            raise InputError(f"cannot reach the Dask scheduler at {address}: {exc}; start it "
                             "(dask scheduler) or drop --scheduler / DASK_SCHEDULER_ADDRESS")\
                from exc
        with client:
            outcomes, died, retried = _on_cluster(client, tasks, progress, label)
            where = address
    else:
        import logging

        from distributed import Client, LocalCluster

        n = max(1, min(workers or (os.cpu_count() or 1), len(tasks)))
        with (
            LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                         dashboard_address=None, silence_logs=logging.ERROR,
                         host="127.0.0.1") as cluster,
            Client(cluster) as client,
        ):
            outcomes, died, retried = _on_cluster(client, tasks, progress, label)
            peaks = {str(k): float(v) for k, v in client.run(peak_rss_mb).items()}
        where = f"local cluster of {n} worker{'s' if n > 1 else ''}"
    return FleetRun(tuple(sorted(outcomes, key=lambda o: o.unit)),
                    time.perf_counter() - start, where, peaks, died, retried)
