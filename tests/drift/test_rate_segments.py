"""Tests of hrgtc.drift.rate_segments: segment tables, holds of rate-table runs, their errors.

Truth: a step pattern with known change rows (boundaries counted by hand), the
same holds found from the column and from a table, and rates built so each hold's
mean and scale error are known exactly.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.drift import (
    RateStep,
    find_rate_segments,
    read_segment_table,
    segment_scale_errors,
)
from hrgtc.recording import Metadata, Recording

FS = 10.0
# (first row, input °/h): 0 from row 0, a 0.3 s acceleration at 5 °/h, then ±100
CHANGES = ((0, 0.0), (300, 5.0), (303, 100.0), (900, -100.0))
N = 1500


def step_run(k_ppm=0.0, bias_dph=0.0):
    inputs = np.empty(N)
    for (start, value), (stop, _) in zip(CHANGES, (*CHANGES[1:], (N, 0.0)), strict=True):
        inputs[start:stop] = value
    rows = np.arange(N, dtype=float)
    return Recording({"time_s": rows / FS, "freq_hz": 4400.0 + 1e-3 * rows,
                      "rate_dph": inputs * (1 + k_ppm * 1e-6) + bias_dph + rows * 1e-3,
                      "input_rate_dph": inputs},
                     Metadata(sample_rate_hz=FS), source="steps.csv")


def test_boundaries_from_the_column_are_exact():
    segments = find_rate_segments(step_run(), settle_s=2.0, min_duration_s=10.0)
    # (first row, stop row): 2 s = 20 rows left out after each change; the
    # acceleration (3 rows, none left after settling) is dropped
    expected = [(20, 300, 0.0), (323, 900, 100.0), (920, 1500, -100.0)]
    assert [(s.first_row, s.first_row + s.rows, s.input_rate_dph) for s in segments] == expected
    for seg, (first, stop, rate) in zip(segments, expected, strict=True):
        assert seg.start_s == first / FS
        assert seg.end_s == (stop - 1) / FS
        assert seg.rows == stop - first
        # mean of rows * 1e-3 over first..stop-1 is their midpoint
        assert seg.rate_dph == pytest.approx(rate + (first + stop - 1) / 2 * 1e-3, abs=1e-12)
        assert seg.freq_hz == pytest.approx(4400.0 + (first + stop - 1) / 2 * 1e-3, abs=1e-9)


def test_settle_zero_keeps_every_row_and_short_stretches_by_min_duration():
    segments = find_rate_segments(step_run(), settle_s=0.0, min_duration_s=0.3)
    assert [(s.first_row, s.rows) for s in segments] == [(0, 300), (300, 3), (303, 597),
                                                         (900, 600)]
    assert len(find_rate_segments(step_run(), settle_s=0.0, min_duration_s=0.31)) == 3


def test_table_gives_the_same_segments_as_the_column(tmp_path):
    path = tmp_path / "steps.csv"
    path.write_text("# rate table log\nstart_s,end_s,input_rate_dph\n0,30,0\n\n30.3,90,100\n"
                    "90,150,-100\n")
    table = read_segment_table(path)
    assert table == (RateStep(0.0, 30.0, 0.0), RateStep(30.3, 90.0, 100.0),
                     RateStep(90.0, 150.0, -100.0))
    run = step_run()
    without_column = Recording({k: v for k, v in run.columns.items() if k != "input_rate_dph"},
                               run.metadata)
    from_table = find_rate_segments(without_column, table, settle_s=2.0)
    assert from_table == find_rate_segments(run, settle_s=2.0)


def test_a_table_hold_outside_the_run_names_its_row():
    table = (RateStep(0.0, 30.0, 0.0), RateStep(200.0, 260.0, 10.0))
    with pytest.raises(InputError, match=r"steps.csv: segment table row 1 \(200 to 260 s\)"):
        find_rate_segments(step_run(), table)


@pytest.mark.parametrize(("text", "match"), [
    ("start_s,end_s,input_rate_dph\n0,10,0\n10,abc,5\n",
     r"t.csv: line 3 \(row 1\), column 'end_s': 'abc' is not a finite number"),
    ("start_s,end_s,input_rate_dph\n0,10,nan\n", r"line 2 \(row 0\), column 'input_rate_dph'"),
    ("start_s,end_s,input_rate_dph\n0,10,0\n20,15,5\n",
     r"line 3 \(row 1\), column 'end_s': end 15 s is not after the start 20 s"),
    ("start_s,end_s,input_rate_dph\n0,10,0\n5,15,5\n",
     r"line 3 \(row 1\), column 'start_s': start 5 s lies before the end 10 s"),
    ("start_s,end_s,input_rate_dph\n0,10\n", r"line 2 \(row 0\): expected 3 fields, got 2"),
    ("start,end,rate\n0,10,0\n", r"line 1: header \['start', 'end', 'rate'\]"),
    ("# nothing\n\n", "empty"),
    ("start_s,end_s,input_rate_dph\n", "no rows"),
])
def test_table_errors_name_file_row_and_column(tmp_path, text, match):
    path = tmp_path / "t.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=match):
        read_segment_table(path)


def test_missing_table_file(tmp_path):
    with pytest.raises(InputError, match="cannot read the segment table"):
        read_segment_table(tmp_path / "absent.csv")


def test_recording_errors():
    run = step_run()
    plain = Recording({k: v for k, v in run.columns.items() if k != "input_rate_dph"},
                      run.metadata, source="plain.csv")
    with pytest.raises(InputError, match=r"plain\.csv: no column 'input_rate_dph'"):
        find_rate_segments(plain)
    inputs = run["input_rate_dph"].copy()
    inputs[700] = np.nan
    with pytest.raises(InputError, match="column 'input_rate_dph', row 700"):
        find_rate_segments(run.with_columns(input_rate_dph=inputs))
    with pytest.raises(InputError, match="settle_s"):
        find_rate_segments(run, settle_s=-1.0)


def test_scale_errors_before_and_after():
    run = step_run(k_ppm=250.0, bias_dph=7.0)
    rows = np.arange(N) * 1e-3
    raw = segment_scale_errors(run, 7.0 + rows, settle_s=2.0)
    assert [s.input_rate_dph for s in raw.segments] == [100.0, -100.0]  # zero input left out
    np.testing.assert_allclose(raw.error_ppm, 250.0, atol=1e-6)
    compensated = run.with_columns(rate_dph=(run.rate_dph - 7.0 - rows) / (1 + 250e-6))
    after = segment_scale_errors(compensated, segments=raw.segments)
    np.testing.assert_allclose(after.error_ppm, 0.0, atol=1e-6)
    assert after.max_abs_ppm < 1e-6 and raw.rms_ppm == pytest.approx(250.0)
    assert "2 segments" in raw.summary().text() and len(raw.to_dict()["error_ppm"]) == 2
    with pytest.raises(InputError, match="bias_dph has shape"):
        segment_scale_errors(run, np.zeros(3))
