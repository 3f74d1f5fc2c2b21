"""Tests of hrgtc.recording.time_axis through :func:`read`: the time repair keeps the rows
and the repaired times together, and ``--start``/``--end`` keep the rows between them.

Written for mutants that no test of the recording package killed (make mutation,
issue 21). Truth: a file written from known times and values.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.recording import read

RATE_HZ = 10.0
READ = {"columns": {"time_s": "t", "freq_hz": "f", "rate_dph": "w"},
        "metadata": {"sample_rate_hz": RATE_HZ, "input_rate_dph": 10.0}}


def _clean(rows: int = 300):
    time_s = np.arange(rows) / RATE_HZ
    freq_hz = 4428.5 + 1e-4 * np.arange(rows)
    rate_dph = 10.0 + 0.01 * np.arange(rows)
    return time_s, freq_hz, rate_dph


def _write(path, time_column, freq_hz, rate_dph, fmt="%.17g"):
    np.savetxt(path, np.column_stack([time_column, freq_hz, rate_dph]), delimiter=",",
               header="t,f,w", comments="", fmt=fmt)
    return path


def test_a_wrapped_counter_with_duplicated_rows_reads_as_the_clean_file(tmp_path):
    time_s, freq_hz, rate_dph = _clean()
    ticks = np.round((time_s + 4294.0) / 1e-6).astype(np.int64) % 2**32  # wraps at row 10
    rows = np.r_[np.arange(150), np.arange(140, 300)]  # rows 140-149 sent twice
    path = tmp_path / "wrapped.csv"
    np.savetxt(path, np.column_stack([ticks[rows], freq_hz[rows], rate_dph[rows]]),
               delimiter=",", header="t,f,w", comments="", fmt=["%d", "%.17g", "%.17g"])
    run = read(path, units={"time": "us"}, **READ)
    assert run.metadata.extra["duplicates_dropped"] == 10
    assert "wrapped" in run.metadata.extra["time_repairs"][0]
    np.testing.assert_allclose(np.diff(run.time_s), np.diff(time_s), atol=2e-6)
    np.testing.assert_array_equal(run.freq_hz, freq_hz)
    np.testing.assert_array_equal(run.rate_dph, rate_dph)


def test_start_and_end_keep_the_rows_between_them(tmp_path):
    time_s, freq_hz, rate_dph = _clean()
    path = _write(tmp_path / "run.csv", 1000.0 + time_s, freq_hz, rate_dph)
    run = read(path, start=5.0, end=10.0, **READ)
    np.testing.assert_array_equal(run.time_s, 1000.0 + time_s[50:100])
    np.testing.assert_array_equal(run.rate_dph, rate_dph[50:100])
    assert run.metadata.extra["rows_sliced"] == 250
    assert len(read(path, start=25.0, **READ)) == 50
    assert len(read(path, end=2.0, **READ)) == 20
    assert len(read(path, **READ)) == 300
    with pytest.raises(InputError, match=r"--end \(5\.0\) must be after --start \(5\.0\)"):
        read(path, start=5.0, end=5.0, **READ)
