"""Run a function in a fresh process and return its result with that process's peak RSS."""

from __future__ import annotations

import multiprocessing
import time
from collections.abc import Callable
from typing import Any

from hrgtc.core.process import peak_rss_mb


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
