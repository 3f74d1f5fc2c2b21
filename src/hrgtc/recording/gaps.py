"""Gaps in a recording: time steps longer than a few sample periods, and what to do with them.

A logger that drops data, pauses or runs duty-cycled leaves gaps; ``--gaps`` says
what they mean (the gap test itself is :func:`hrgtc.core.timeline.is_gap`, the one
of the whole package):

``error`` (default)
    A gap is a problem: the message names the first one and the modes below (the
    safe choice: nothing is guessed about a file whose time axis has holes).
``split``
    The segments between gaps are processed apart, as separate runs: the df/dt
    filter restarts (and settles again) after each gap; windows, bias stability and
    Allan deviation never cross a gap.
``bridge``
    The filters carry across a gap using its true duration (the temperature kept
    changing while the logger slept); the warm-up is applied once, from the start of
    the recording; windows, bias stability and Allan deviation still never cross a
    gap. The mode for duty-cycled (burst) loggers whose bursts are shorter than the
    filter's settling time.
``ignore``
    Deprecated alias of ``bridge`` (kept for existing scripts).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Annotated, Literal

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import RecordingError
from hrgtc.core.records import Count
from hrgtc.core.timeline import GAP_FACTOR, GAP_TOLERANCE, is_gap
from hrgtc.recording.schema import Recording

GapPolicy = Literal["error", "split", "bridge", "ignore"]
GAP_POLICIES: tuple[str, ...] = ("error", "split", "bridge", "ignore")
GAP_PERIODS = GAP_FACTOR  # a time step longer than this many sample periods is a gap
__all__ = [
    "GAP_PERIODS",
    "GAP_POLICIES",
    "GAP_TOLERANCE",
    "MAX_LISTED_GAPS",
    "Gap",
    "GapPolicy",
    "check_gap_policy",
    "filter_restarts_at_gaps",
    "split_at_gaps",
]
MAX_LISTED_GAPS = 1000


@dataclass(frozen=True)
class Gap(records.Written):
    """A time step longer than :data:`GAP_PERIODS` sample periods.

    Parameters
    ----------
    start_time_s
        Time of the last sample before the gap. [s]
    duration_s
        Time between the samples on either side of the gap. [s]
    row
        First row after the gap (0 = first data row).
    """

    start_time_s: float
    duration_s: Annotated[float, Meta(ge=0)]
    row: Count


def check_gap_policy(gaps: str) -> str:
    """Return ``gaps`` if it is a known gap policy, else raise InputError."""
    if gaps not in GAP_POLICIES:
        raise RecordingError(f"gaps must be one of {list(GAP_POLICIES)}, got {gaps!r}")
    return gaps


def filter_restarts_at_gaps(gaps: str) -> bool:
    """True when the df/dt filter restarts after a gap (``split``), False when it carries
    across (``bridge``, ``ignore``) or gaps are errors."""
    return check_gap_policy(gaps) == "split"


def split_at_gaps(recording: Recording, max_gap_periods: float = GAP_PERIODS) -> list[Recording]:
    """Cut a recording into gap-free segments.

    Parameters
    ----------
    recording
        Recording with strictly increasing ``time_s``.
    max_gap_periods
        A time step longer than this many sample periods (of the metadata's
        sample rate) starts a new segment.

    Returns
    -------
    list of Recording
        Views of consecutive rows, same metadata; times are not shifted.
    """
    period = 1.0 / recording.metadata.sample_rate_hz
    starts = np.flatnonzero(is_gap(np.diff(recording.time_s), period, max_gap_periods)) + 1
    bounds = [0, *starts.tolist(), len(recording)]
    return [recording.slice(a, b) for a, b in itertools.pairwise(bounds)]
