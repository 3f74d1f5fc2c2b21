"""Tests of hrgtc.recording.gaps: the gap policies, the Gap record, split_at_gaps' threshold.

Written for mutants of gaps.py that no test killed (make mutation, issue 21). Truth: the
segments of times built with known gaps; the policy table of docs/.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import RecordingError
from hrgtc.recording import Metadata, Recording, split_at_gaps
from hrgtc.recording.gaps import GAP_POLICIES, Gap, check_gap_policy, filter_restarts_at_gaps


def test_the_filter_restarts_after_a_gap_only_with_split():
    assert {policy: filter_restarts_at_gaps(policy) for policy in GAP_POLICIES} == {
        "error": False, "split": True, "bridge": False, "ignore": False}
    with pytest.raises(RecordingError, match=r"gaps must be one of \['error', 'split', "
                                             r"'bridge', 'ignore'\], got 'Split'"):
        filter_restarts_at_gaps("Split")
    assert check_gap_policy("bridge") == "bridge"


def test_a_gap_round_trips_through_plain_types():
    gap = Gap(start_time_s=12.5, duration_s=3.25, row=126)
    data = gap.to_dict()
    assert data == {"start_time_s": 12.5, "duration_s": 3.25, "row": 126}
    assert Gap.from_dict(data) == gap


def test_split_at_gaps_uses_the_threshold_it_is_given():
    rate_hz = 10.0
    time_s = np.concatenate([np.arange(20), 22.0 + np.arange(20), 52.0 + np.arange(20)]) / rate_hz
    run = Recording({"time_s": time_s, "rate_dph": np.zeros(time_s.size)},
                    Metadata(sample_rate_hz=rate_hz))  # steps of 3 and 13 periods
    assert [len(s) for s in split_at_gaps(run)] == [20, 20, 20]
    assert [len(s) for s in split_at_gaps(run, max_gap_periods=5.0)] == [40, 20]
    assert [len(s) for s in split_at_gaps(run, max_gap_periods=20.0)] == [60]
    first, second = split_at_gaps(run, max_gap_periods=5.0)
    assert first.time_s[-1] == 4.1
    assert second.time_s[0] == 5.2  # times are not shifted
