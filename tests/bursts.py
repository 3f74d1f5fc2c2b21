"""Real-logger time axes cut from a continuous run: bursts, ms/µs counters, wraps, resets.

A small stand-in for ``hrgtc simulate --logger ...`` (built in parallel): it takes a
continuous :class:`~hrgtc.recording.Recording` and keeps only what a duty-cycled or
misbehaving logger would have written, so the truth is the continuous run.
"""

from __future__ import annotations

import numpy as np

from hrgtc.recording import Recording


def cut_bursts(run: Recording, burst_s: float = 5.0, period_s: float = 300.0,
               offset_s: float = 0.0) -> Recording:
    """Keep ``burst_s`` seconds every ``period_s`` seconds (from ``offset_s``) of ``run``."""
    since = run.time_s - run.time_s[0] - offset_s
    keep = (since >= 0) & (np.mod(since, period_s) < burst_s - 1e-9)
    return Recording({name: run[name][keep] for name in run.names}, run.metadata,
                     source=run.source)


def with_time(run: Recording, time_s: np.ndarray) -> Recording:
    """The same run with another time column."""
    return Recording({**{name: run[name] for name in run.names}, "time_s": time_s},
                     run.metadata, source=run.source)


def wrapped_counter_s(time_s: np.ndarray, unit: str = "us", start_s: float = 0.0) -> np.ndarray:
    """The times a 32-bit ``unit`` counter starting at ``start_s`` logs, in seconds."""
    scale = {"us": 1e-6, "ms": 1e-3}[unit]
    ticks = np.round((time_s - time_s[0] + start_s) / scale).astype(np.int64)
    return (ticks % (2**32)) * scale


def duplicated_rows(run: Recording, row: int, count: int) -> Recording:
    """``count`` rows before ``row`` written again after it (a logger that re-sent a block)."""
    order = np.r_[np.arange(row), np.arange(row - count, len(run))]
    return Recording({name: run[name][order] for name in run.names}, run.metadata,
                     source=run.source)
