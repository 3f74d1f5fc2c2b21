"""The drift fit's window pass, one run at a time in worker processes (every core).

:func:`~hrgtc.drift.windows.window_means_jointly` reads the runs one after the other,
and what a run adds to each :class:`~hrgtc.drift.windows.WindowJob` depends on the runs
before it only through counts and indices: where its power-on runs are numbered from, the
accelerometer and label columns the first run has (``WindowJob.extra``). So each run's
pass runs on a blank copy of each job in a worker process (:mod:`hrgtc.core.forked`) and
gives back what it adds (:class:`RunPart`), and the command adds the parts in the runs'
order: the power-on runs' indices shifted by those before (their window means are means
of one whole number, so the shift is exact), the windows and counts appended, the
trained ranges' extremes taken with ``fmin``/``fmax`` (which keep, as the chunk-by-chunk
order does, the last of equal values). A run whose extra columns differ from the first
run's (known only once that run is added) is read again in the command with the first's.
The result is the one the in-process pass gives (``tests/drift/test_run_windows.py``).

A run source is read in a worker only when it names its file and says how to carry its
own state back (:class:`ForkableRun`); the others, and small files, are read in-process.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from hrgtc.core import forked


@runtime_checkable
class ForkableRun(Protocol):
    """A run source a worker process may read: its file (None: read it in the command),
    the state its pass leaves (e.g. the rows the spike filter dropped) and how to take it
    back."""

    @property
    def worker_path(self) -> Any: ...

    def passed(self) -> Any: ...

    def restore(self, state: Any) -> None: ...


@dataclass
class RunPart:
    """What one run's pass added to a job: the names, problems and counts, and per warm-up
    the windows (time, power-on run from 0, means, run), extremes and rows left out."""

    sources: list[str]
    power_names: list[str]
    problems: list[str]
    extra: tuple[str, ...] | None
    total: int
    segments: int
    kept: list[tuple[Any, ...]]


def workers_for(runs: Sequence[Any]) -> int:
    """Worker processes for the window pass over ``runs`` (1: in-process)."""
    if len(runs) < 2 or not all(isinstance(r, ForkableRun) for r in runs):
        return 1
    paths = [r.worker_path for r in runs]
    if any(p is None for p in paths):
        return 1
    return forked.processes(len(runs), paths)


@dataclass(frozen=True)
class _RunPass:
    """One run's pass on blank copies of the jobs: each job's :class:`RunPart` or error
    (the first job's error is raised), and the run source's own state."""

    runs: Sequence[Any]
    jobs: Sequence[Any]
    iterate: Callable[[Any], Any]

    @staticmethod
    def prepare() -> None:
        """Load the df/dt filter's compiled loops once, before worker processes fork."""
        import hrgtc.drift._rate_kernel  # noqa: F401

    def __call__(self, index: int) -> tuple[list[RunPart | Exception], Any]:
        copies = [_blank(job) for job in self.jobs]
        failed: list[Exception | None] = [None] * len(copies)

        def each(step: Callable[[Any], None]) -> None:
            for k, copy in enumerate(copies):
                if failed[k] is None:
                    try:
                        step(copy)
                    except Exception as exc:
                        if k == 0:
                            raise
                        failed[k] = exc

        each(lambda job: job.start_run(index))
        source = self.runs[index]
        for chunk in self.iterate(source):
            each(lambda job, chunk=chunk: job.add(chunk))
        each(lambda job: job.end_run())
        parts: list[RunPart | Exception] = [
            exc if exc is not None else _part(copy) for copy, exc in zip(copies, failed,
                                                                          strict=True)]
        return parts, source.passed()


def read_in_workers(runs: Sequence[Any], jobs: Sequence[Any], live: list[int],
                    out: list[Any], workers: int, iterate: Callable[[Any], Any]) -> None:
    """The window pass of ``jobs`` over ``runs`` (``iterate(run)``: its chunks), each run
    in a worker, the parts added here in the runs' order; a job after the first that fails
    is taken out of ``live`` with its error in ``out``."""
    work = _RunPass(runs, jobs, iterate)
    for index, (parts, state) in enumerate(forked.map_in_order(work, range(len(runs)),
                                                               workers)):
        if any(not isinstance(p, Exception) and p.extra != jobs[k].extra
               and jobs[k].extra is not None for k, p in enumerate(parts) if k in live):
            parts, state = work(index)  # its extra columns are the first run's: read here
        runs[index].restore(state)
        for k in list(live):
            part = parts[k]
            if isinstance(part, Exception):
                out[k] = part
                live.remove(k)
            else:
                _add(jobs[k], part)


def _blank(job: Any) -> Any:
    """A copy of ``job`` before any run (its settings, the first run's extra columns),
    reporting no progress (the command reports each run as it adds it)."""
    copy = type(job)(job.settings, job.terms, job.windowing, None, job.thermometer,
                     job.keep, [w.warmup_s for w in job.kept_by])
    copy.extra = job.extra
    return copy


def _part(copy: Any) -> RunPart:
    kept = [(w.time, w.power, w.means, w.run, w.lowest, w.highest, w.warm, w.partial,
             w.left_out) for w in copy.kept_by]
    return RunPart(copy.sources, copy.power_names, copy.problems, copy.extra, copy.total,
                   copy.segments, kept)


def _add(job: Any, part: RunPart) -> None:
    """Add a run's part to ``job`` as its in-process pass would have."""
    first_power = len(job.power_names)
    job.sources += part.sources
    job.power_names += part.power_names
    job.problems += part.problems
    if job.extra is None:
        job.extra = part.extra
    job.total += part.total
    job.segments += part.segments
    for windows, (time, power, means, run, lowest, highest, warm, partial,
                  left_out) in zip(job.kept_by, part.kept, strict=True):
        windows.time += time
        windows.power += [p + first_power for p in power]
        windows.means += means
        windows.run += run
        np.fmin(windows.lowest, lowest, out=windows.lowest)
        np.fmax(windows.highest, highest, out=windows.highest)
        windows.warm += warm
        windows.partial += partial
        windows.left_out += left_out
    if job.progress is not None:
        job.progress(job.total, 0)
