"""Tests of hrgtc.drift.run_windows: the window pass with each run in a worker process gives
what the in-process pass gives, field for field and bit for bit.

Truth: :func:`hrgtc.drift.windows.window_means_jointly` in one process (the chunk-by-chunk
pass) on the same runs and jobs. The runs are made to exercise what a run's part depends
on: a logger restart inside a run (its power-on runs numbered after the runs before), a
gap, samples left out as not at rest, a first run without the accelerometer columns that
a later run has (read again in the command with the first run's columns) and a later run
without those a run before it has, two warm-ups, a second job, and a job that fails.
"""

from __future__ import annotations

import dataclasses
import sys

import numpy as np
import pytest

from hrgtc.core import forked
from hrgtc.core.timeline import RESTARTS_KEY
from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.run_windows import ForkableRun
from hrgtc.drift.windows import Windowing, WindowJob, window_means_jointly
from hrgtc.recording import Recording

from synthetic import ramp_run

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="worker processes are forked on Linux only")

SETTINGS = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, rate_tau_s=5.0,
                           warmup_s=60.0)


class _Run:
    """A run read in chunks that counts its chunks (its pass's own state)."""

    def __init__(self, recording: Recording, rows: int) -> None:
        self.recording, self.rows, self.chunks_read = recording, rows, 0

    def __call__(self):
        self.chunks_read = 0
        for start in range(0, len(self.recording), self.rows):
            self.chunks_read += 1
            yield self.recording.slice(start, start + self.rows)

    worker_path = "synthetic"  # any file: the workers are forced on these small runs

    def passed(self) -> int:
        return self.chunks_read

    def restore(self, state: int) -> None:
        self.chunks_read = state


def _runs(accel: tuple[int, ...]) -> list[_Run]:
    rng = np.random.default_rng(7)
    runs = []
    clock = 0.0
    for k in range(4):
        run = ramp_run(seed=k, start_c=20.0 - 5 * k, end_c=-20.0, hours=0.5)
        time = run.time_s + clock
        if k == 1:  # a gap
            time[9000:] += 30.0
        clock = float(time[-1]) + 1.0
        columns = {n: run[n] for n in run.names}
        columns["time_s"] = time
        if k in accel:
            for axis in "xyz":
                columns[f"accel_{axis}"] = rng.normal(0.0, 1e-3, len(time))
        metadata = run.metadata
        if k == 2:  # a logger restart: a power-on run of its own
            metadata = dataclasses.replace(metadata, extra={RESTARTS_KEY: [float(time[11000])]})
        runs.append(_Run(Recording(columns, metadata, f"run-{k}"), rows=4096 + 1000 * k))
    return runs


def _keep(runs: list[_Run]) -> list[np.ndarray]:
    keep = []
    for k, run in enumerate(runs):
        mask = np.ones(len(run.recording), dtype=bool)
        mask[3000 + 500 * k:3400 + 500 * k] = False  # handled: not at rest
        keep.append(mask)
    return keep


def _jobs(keep: list[np.ndarray]) -> list[WindowJob]:
    windowing = Windowing(10.0, ("df",))
    return [WindowJob(SETTINGS, parse_terms(["f", "f^2", "df"]), windowing, keep=keep,
                      warmups_s=(60.0, 0.0)),
            WindowJob(SETTINGS, parse_terms(["f", "f*df"]), Windowing(20.0), keep=keep),
            WindowJob(SETTINGS, parse_terms(["f"]), Windowing(0.01), keep=keep)]  # fails


def _same(a, b) -> None:
    assert type(a) is type(b)
    if isinstance(a, Exception):
        assert str(a) == str(b)
        return
    for one, other in zip(a, b, strict=True):
        for field in dataclasses.fields(one):
            x, y = getattr(one, field.name), getattr(other, field.name)
            if isinstance(x, dict) and x and isinstance(next(iter(x.values())), np.ndarray):
                assert x.keys() == y.keys()
                for key in x:
                    np.testing.assert_array_equal(x[key], y[key])
            elif isinstance(x, np.ndarray):
                assert x.dtype == y.dtype
                np.testing.assert_array_equal(x, y)
            else:
                assert x == y, field.name


@pytest.mark.parametrize("accel", [(0, 1, 2, 3), (1, 2, 3), (0, 3)],
                         ids=["every-run", "later-runs", "first-and-last"])
def test_runs_in_workers_give_the_in_process_windows(accel, monkeypatch):
    monkeypatch.setenv(forked.ENVIRONMENT, "1")
    runs = _runs(accel)
    keep = _keep(runs)
    here = window_means_jointly(runs, _jobs(keep))
    counts = [run.chunks_read for run in runs]
    for run in runs:
        run.chunks_read = -1
    monkeypatch.setenv(forked.ENVIRONMENT, "2")
    assert all(isinstance(run, ForkableRun) for run in runs)
    progress: list[tuple[float, float]] = []
    jobs = _jobs(keep)
    jobs[0].progress = lambda done, total: progress.append((done, total))
    there = window_means_jointly(runs, jobs)
    for one, other in zip(here, there, strict=True):
        _same(one, other)
    assert isinstance(here[2], Exception)  # the failing job's own error, given back
    assert here[0][0].power_run.max() == len(runs)  # the restart: one power-on run more
    assert [run.chunks_read for run in runs] == counts  # each pass's own state came back
    assert progress[-1] == (sum(len(r.recording) for r in runs), 0)
