"""Hold out the end of a drift file: train on its first part, validate on the rest.

The split ``hrgtc calibrate --holdout-s/--holdout-fraction`` makes before
:func:`hrgtc.pipeline.calibration.calibrate` fits anything: one file, cut by
recorded time at a segment start (:func:`hrgtc.core.timeline.holdout_rows`).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence

from hrgtc.core.errors import InputError
from hrgtc.recording import ReadOptions

__all__ = ["holdout_split"]

PathLike = str | os.PathLike[str]


def holdout_split(read_options: ReadOptions, soaks: Sequence[PathLike],
                  drifts: Sequence[PathLike], validate: Sequence[PathLike],
                  holdout_s: float | None = None, holdout_fraction: float | None = None
                  ) -> tuple[ReadOptions, ReadOptions, list[PathLike]]:
    """Train on the first part of the one drift file, validate on its last part (by time).

    The cut is :func:`hrgtc.core.timeline.holdout_rows` of the file's time stamps (the
    last ``holdout_s`` seconds or ``holdout_fraction`` of the recorded time, at a segment
    start: a burst is never split).

    Returns
    -------
    tuple
        The training reading options (``end`` at the cut), the held-out run's
        (``start`` at the cut) and the held-out runs (the drift file), for
        :func:`~hrgtc.pipeline.calibration.calibrate`'s training reading, its held-out
        runs' reading and its held-out runs.
    """
    from hrgtc.core.timeline import holdout_rows

    if len(drifts) != 1 or soaks or validate:
        raise InputError("--holdout-s/--holdout-fraction hold out the end of one --drift file: "
                         "give exactly one --drift and no --soak or --validate (or split the "
                         "files yourself with --start/--end)")
    if read_options.start is not None or read_options.end is not None:
        raise InputError("--holdout-s/--holdout-fraction and --start/--end together: slice the "
                         "file first, or use --end for training and --validate with --start")
    time = read_options.read(drifts[0], keep=["time_s"]).time_s
    cut = holdout_rows(time, holdout_s, holdout_fraction)
    at = f"{time[cut] - time[0]:.9g}"
    return (dataclasses.replace(read_options, end=at),
            dataclasses.replace(read_options, start=at), [drifts[0]])
