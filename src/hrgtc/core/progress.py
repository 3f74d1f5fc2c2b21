"""The progress callback that long library functions accept.

Library code never prints; a function that takes a while accepts an optional
``progress(done, total)`` and calls it as it goes (``total`` 0 when unknown).
The CLI turns it into a progress bar. Work made of named stages (calibration,
the demo) reports through :data:`StageProgress`, ``progress(stage, done, total)``.
"""

from __future__ import annotations

from collections.abc import Callable

#: ``progress(done, total)``: work done so far and in all (0 when not known).
Progress = Callable[[float, float], None]
#: ``progress(stage, done, total)``: the same for work made of named stages.
StageProgress = Callable[[str, float, float], None]


def for_stage(progress: StageProgress | None, stage: str) -> Progress | None:
    """A :data:`Progress` that reports ``stage`` to a :data:`StageProgress` (None stays None)."""
    if progress is None:
        return None
    return lambda done, total: progress(stage, done, total)
