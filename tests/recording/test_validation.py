"""Tests of the fast paths of hrgtc.recording.validation: chunk by chunk, nothing slips through.

A clean chunk is passed by two min/max reductions per column (and the time steps', and the
sample rate of every 1000-row block at once); a defect anywhere must still be reported at
its row, whatever the chunking. Truth: the rows the test corrupted.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.core.errors import RecordingError
from hrgtc.recording import Metadata, Recording, iter_chunks, write

RATE_HZ = 200.0
N = 6000


def clean(seed: int = 3) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    return {"time_s": np.arange(N) / RATE_HZ,
            "freq_hz": 4425.0 + 0.01 * rng.standard_normal(N),
            "rate_dph": 10.0 + 2.0 * rng.standard_normal(N),
            "housing_c": 21.0 + rng.standard_normal(N)}


DEFECTS = {  # kind -> (change the columns at row, what the message says)
    "nan": (lambda c, r: c["rate_dph"].__setitem__(r, np.nan), r"'rate_dph', row {row}: value nan"),
    "inf": (lambda c, r: c["housing_c"].__setitem__(r, np.inf),
            r"'housing_c', row {row}: value inf"),
    "bound": (lambda c, r: c["rate_dph"].__setitem__(r, 1e9), r"'rate_dph', row {row}:"),
    "jump": (lambda c, r: c["freq_hz"].__setitem__(r, 4425.0 * 1.06), r"'freq_hz', row {row}:"),
    "back": (lambda c, r: c["time_s"].__setitem__(r, c["time_s"][r] - 0.02),
             r"'time_s', row {row}:"),
    "gap": (lambda c, r: c["time_s"].__setitem__(slice(r, None), c["time_s"][r:] + 10.0),
            r"row {row}: 1 gap"),
}


@settings(max_examples=40, deadline=None)
@given(kind=st.sampled_from(sorted(DEFECTS)), row=st.integers(1, N - 1),
       rows=st.sampled_from([700, 1000, 2500, N]))
def test_a_defect_is_reported_at_its_row_whatever_the_chunking(tmp_path_factory, kind, row, rows):
    columns = clean()
    change, message = DEFECTS[kind]
    change(columns, row)
    path = write(Recording(columns, Metadata(sample_rate_hz=RATE_HZ)),
                 tmp_path_factory.mktemp("v") / "run.parquet")
    with pytest.raises(RecordingError, match=message.format(row=row)):
        list(iter_chunks(path, chunk_rows=rows))


@pytest.mark.parametrize("rows", [700, 1500, N])
def test_a_sample_rate_change_late_in_the_run_is_found(tmp_path, rows):
    columns = clean()
    columns["time_s"][4000:] = columns["time_s"][4000] + (np.arange(N - 4000) / (RATE_HZ * 1.05))
    path = write(Recording(columns, Metadata(sample_rate_hz=RATE_HZ)), tmp_path / "run.parquet")
    with pytest.raises(RecordingError, match=r"row 4000"):
        list(iter_chunks(path, chunk_rows=rows))
    assert sum(len(c) for c in iter_chunks(write(Recording(clean(), Metadata(
        sample_rate_hz=RATE_HZ)), tmp_path / "clean.parquet"), chunk_rows=rows)) == N


@settings(max_examples=40, deadline=None)
@given(start=st.integers(1, N - 1200), factor=st.floats(0.95, 1.05),
       rows=st.integers(300, N), seed=st.integers(0, 10))
def test_the_sample_rate_check_by_block_end_times_equals_summing_every_step(start, factor,
                                                                           rows, seed):
    """A clean chunk's block means come from the times at the block ends (no pass over the
    steps); chunk by chunk they find the same block, and the same mean, as one chunk whose
    steps are summed (the first chunk always is: its first step is unknown)."""
    from hrgtc.recording.validation import RecordingValidator

    rng = np.random.default_rng(seed)
    step = (1.0 + 1e-4 * rng.standard_normal(N)) / RATE_HZ
    step[start:] /= factor
    columns = {**clean(seed), "time_s": 100.0 + np.cumsum(step)}
    whole = Recording(columns, Metadata(sample_rate_hz=RATE_HZ))
    found = []
    for size in (N, rows):
        validator = RecordingValidator()
        for first in range(0, N, size):
            validator.partial_fit(whole.slice(first, min(first + size, N)))
        found.append(validator.time_axis.rate_change)
    if found[0] is None:
        assert found[1] is None
    else:
        assert found[1][0] == found[0][0]
        assert found[1][1] == pytest.approx(found[0][1], rel=1e-10)
    if abs(factor - 1.0) > 0.02 and start < N - 2 * 1000:
        assert found[0] is not None  # the change is there to find
