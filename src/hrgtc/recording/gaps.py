"""Gaps in a recording: time steps longer than a few sample periods, and what to do with them.

A logger that drops data leaves a gap; ``--gaps`` says whether that is an error
(default), whether the run is processed as separate segments (``split``: the
df/dt filter restarts after each gap) or accepted as it is (``ignore``).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any, Literal

import numpy as np

from hrgtc.errors import RecordingError
from hrgtc.recording.schema import Recording

GapPolicy = Literal["error", "split", "ignore"]
GAP_POLICIES: tuple[str, ...] = ("error", "split", "ignore")
GAP_PERIODS = 2.0  # a time step longer than this many sample periods is a gap
#: Relative slack of the gap threshold: one missing sample (a step of exactly 2 periods,
#: e.g. a dropped spike) is not a gap whatever the rounding of the times.
GAP_TOLERANCE = 1e-6
MAX_LISTED_GAPS = 1000


@dataclass(frozen=True)
class Gap:
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
    duration_s: float
    row: int

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Gap:
        """Inverse of :meth:`to_dict`."""
        return cls(**dict(data))


def check_gap_policy(gaps: str) -> str:
    """Return ``gaps`` if it is a known gap policy, else raise InputError."""
    if gaps not in GAP_POLICIES:
        raise RecordingError(f"gaps must be one of {list(GAP_POLICIES)}, got {gaps!r}")
    return gaps


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
    limit = max_gap_periods * period * (1.0 + GAP_TOLERANCE)
    starts = np.flatnonzero(np.diff(recording.time_s) > limit) + 1
    bounds = [0, *starts.tolist(), len(recording)]
    return [recording.slice(a, b) for a, b in itertools.pairwise(bounds)]
