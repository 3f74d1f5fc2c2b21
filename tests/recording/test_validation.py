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

from hrgtc.errors import RecordingError
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
    "gap": (lambda c, r: c["time_s"].__setitem__(slice(r, None), c["time_s"][r:] + 1.0),
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
        list(iter_chunks(path, rows=rows))


@pytest.mark.parametrize("rows", [700, 1500, N])
def test_a_sample_rate_change_late_in_the_run_is_found(tmp_path, rows):
    columns = clean()
    columns["time_s"][4000:] = columns["time_s"][4000] + (np.arange(N - 4000) / (RATE_HZ * 1.05))
    path = write(Recording(columns, Metadata(sample_rate_hz=RATE_HZ)), tmp_path / "run.parquet")
    with pytest.raises(RecordingError, match=r"row 4000"):
        list(iter_chunks(path, rows=rows))
    assert sum(len(c) for c in iter_chunks(write(Recording(clean(), Metadata(
        sample_rate_hz=RATE_HZ)), tmp_path / "clean.parquet"), rows=rows)) == N
