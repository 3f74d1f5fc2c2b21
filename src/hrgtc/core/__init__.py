"""The core of hrgtc: the time axis of a recording and the accounting of its samples.

Every stage reads time through this package, so a warm-up, a window, a gap or a
held-out split means the same thing in ``info``, ``calibrate``, ``compensate`` and
``evaluate``:

* :mod:`hrgtc.core.timeline` -- a recording's time axis as an ordered set of
  contiguous segments (the one gap test of the package, segment bounds and
  durations, seconds since power-on, windows that never span a gap, slicing by
  seconds or clock time, time blocks for held-out splits);
* :mod:`hrgtc.core.time_steps` -- the one classifier of odd time steps (counter
  wraps, resets, daylight-saving steps, duplicates, a wrong time unit or sample
  rate, a rate that really changes) and the repair that makes each the clean file;
* :mod:`hrgtc.core.accounting` -- samples read, used, and dropped or flagged by reason;
* :mod:`hrgtc.core.timeline_builder` -- a timeline built chunk by chunk;
* :mod:`hrgtc.core.estimator` -- the one contract of the streaming accumulators
  (``partial_fit(chunk) -> self``, ``finish() -> result``).

It also holds what every stage needs and that depends on nothing else of hrgtc:

* :mod:`hrgtc.core.errors` -- the exception and warning classes (one ``HrgtcError``,
  one ``HrgtcWarning`` at the root);
* :mod:`hrgtc.core.meta` -- the version and the paper's reference;
* :mod:`hrgtc.core.files` -- atomic output files, never overwritten without ``force``;
* :mod:`hrgtc.core.progress` -- the progress callback of long library functions;
* :mod:`hrgtc.core.process` -- facts about the running process (peak memory).
* :mod:`hrgtc.core.student_t` -- Student's t tail (the regressions' p-values) without
  importing ``scipy.stats``.

``core`` imports nothing from the other hrgtc stages. Its names are loaded on first use
(PEP 562), so ``from hrgtc.core.errors import HrgtcError`` costs no numpy import and the
command line starts at once; :func:`lazy_names` gives another package the same.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping, MutableMapping
from typing import Any

#: Public name -> the core module that defines it (loaded on first access).
_NAMES = {
    "REASONS": "accounting", "Accounting": "accounting",
    "TimelineBuilder": "timeline_builder",
    "TimeDiagnosis": "time_steps", "TimeEvent": "time_steps", "classify_time_steps": "time_steps",
    **{name: "timeline" for name in (
        "GAP_FACTOR", "GAP_TOLERANCE", "Timeline", "gap_limit_s", "is_gap",
        "median_period_s", "parse_time_bound", "seconds_since_power_on", "segment_bounds",
        "slice_rows", "time_blocks", "windows",
    )},
}

__all__ = sorted(_NAMES)


def lazy_names(package: str, names: Mapping[str, str], namespace: MutableMapping[str, Any],
               ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of ``package``: ``names`` maps each public name to
    its module (relative to the package); a name is imported when first asked for and kept
    in the package's ``namespace`` (its ``globals()``)."""

    def __getattr__(name: str) -> Any:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(f"{package}.{module}"), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(names))

    return __getattr__, __dir__


__getattr__, __dir__ = lazy_names(__name__, _NAMES, globals())
