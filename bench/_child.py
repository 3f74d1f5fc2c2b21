"""Run a function in a fresh process and return its result with that process's peak RSS."""

from __future__ import annotations

import multiprocessing
import resource
import time
from collections.abc import Callable
from typing import Any


def peak_rss_mb() -> float:
    """This process's peak resident set size. [MB]

    ``VmHWM`` of /proc/self/status belongs to the current address space, so it
    starts afresh in a spawned child; ``ru_maxrss`` survives fork + exec on
    Linux and would report the parent's peak.
    """
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return round(int(line.split()[1]) / 1024.0, 1)
    except OSError:
        pass
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)


def _target(queue: Any, function: Callable[..., Any], args: tuple[Any, ...]) -> None:
    start = time.perf_counter()
    value = function(*args)
    seconds = time.perf_counter() - start
    queue.put((value, seconds, peak_rss_mb()))


def measure(function: Callable[..., Any], *args: Any) -> tuple[Any, float, float]:
    """``(value, seconds, peak_rss_mb)`` of ``function(*args)`` run in a spawned process."""
    context = multiprocessing.get_context("spawn")
    queue = context.Queue()
    process = context.Process(target=_target, args=(queue, function, args))
    process.start()
    value, seconds, peak = queue.get()
    process.join()
    if process.exitcode != 0:
        raise RuntimeError(f"benchmark child exited with {process.exitcode}")
    return value, seconds, peak
