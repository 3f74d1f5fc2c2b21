"""Rows the reader removes are masked on the time axis, never turned into gaps (issue 27).

The CATS tag's file (1 Hz, no gap at all) was refused for "3 gap(s) longer than 2 sample
periods" and "the time step changes to 1 Hz but the metadata say 1 Hz": the gaps were the
rows its own spike filter removed. The validator now judges a step over removed rows per
file row, as long as the removed rows took; a real gap beside a removed row is still a
gap, and removed duplicated rows (which took no time) change no rate.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.recording import RecordingValidator
from hrgtc.recording.motion import MotionSettings, detect_motion
from hrgtc.recording.schema import Metadata, Recording


def _validate(time_s, file_rows, gaps="error", chunk=1000):
    n = time_s.size
    rng = np.random.default_rng(0)
    data = {"time_s": time_s, "freq_hz": 20.0 + 0.01 * rng.standard_normal(n),
            "rate_dph": 50.0 + rng.standard_normal(n)}
    validator = RecordingValidator(gaps, thermometer="resonator")
    for a in range(0, n, chunk):
        part = Recording({k: v[a:a + chunk] for k, v in data.items()},
                         Metadata(sample_rate_hz=1.0), source="tag.csv")
        validator.partial_fit(part, file_rows[a:a + chunk])
    return validator


def _removed(n, rows):
    """Times and file rows of a uniform 1 Hz file of ``n`` rows with ``rows`` removed."""
    keep = np.setdiff1d(np.arange(n), rows)
    return keep.astype(float), keep.astype(float)


@pytest.mark.parametrize("chunk", [1000, 7])
def test_rows_the_spike_filter_removed_are_neither_gaps_nor_a_rate_change(chunk):
    # runs of 2 and 3 consecutive rows removed (a handling burst's spikes), 400 rows in all
    removed = np.concatenate([np.arange(s, s + 2 + s % 2) for s in range(50, 20000, 100)])
    time_s, file_rows = _removed(20000, removed)
    validator = _validate(time_s, file_rows, chunk=chunk)
    kinds = [p.kind for p in validator.time_axis.problems("error", False)]
    assert kinds == [] and validator.time_axis.n_gaps == 0
    assert validator.time_axis.rate_change is None


def test_a_real_gap_beside_a_removed_row_is_still_a_gap():
    time_s = np.r_[np.arange(0.0, 500.0), np.arange(510.0, 1500.0)]  # a 10 s pause
    file_rows = np.arange(time_s.size, dtype=float)
    file_rows[500:] += 1  # and the first row after it removed by a filter
    time_s = np.delete(time_s, 500)
    file_rows = np.delete(file_rows, 500)
    validator = _validate(time_s, file_rows)
    problems = validator.time_axis.problems("error", False)
    assert validator.time_axis.n_gaps == 1
    assert [p.kind for p in problems] == ["gap"] and problems[0].row == 500


def test_removed_duplicated_rows_change_no_rate_and_hide_no_long_gap():
    # duplicated rows dropped by the time repair took no time: every 10th row of the
    # file a copy, so a step over one is one period, not half a period each
    time_s = np.r_[np.arange(0.0, 3000.0), np.arange(3010.0, 6000.0)]  # and a 10 s pause
    file_rows = np.arange(time_s.size, dtype=float) + np.arange(time_s.size) // 9
    validator = _validate(time_s, file_rows)
    assert validator.time_axis.rate_change is None
    assert validator.time_axis.n_gaps == 1


def _handled(still_between_s):
    t = np.arange(0.0, 4000.0)
    rate = 40.0 + np.random.default_rng(2).standard_normal(t.size)
    first, second = 500, 500 + 10 + int(still_between_s)
    rate[first:first + 10] += 2000.0  # two handlings
    rate[second:second + 10] -= 2000.0
    return t, rate, (first + 10, second)


def test_a_short_still_pause_between_handlings_is_not_at_rest():
    t, rate, (a, b) = _handled(120.0)
    mask = detect_motion(t, rate)
    pause = slice(a + 10, b - 5)  # clear of the guards
    assert mask.moving[pause].all() and mask.reasons["short_still"][pause].all()
    assert not mask.moving[:400].any() and not mask.moving[b + 100:].any()
    # a long pause is at rest, and the rule can be switched off
    t, rate, (a, b) = _handled(900.0)
    assert not detect_motion(t, rate).moving[a + 10:b - 5].any()
    t, rate, (a, b) = _handled(120.0)
    off = detect_motion(t, rate, settings=MotionSettings(min_still_s=0.0))
    assert not off.moving[a + 10:b - 5].any()


def test_a_short_still_start_before_the_first_handling_is_not_at_rest():
    t = np.arange(0.0, 3000.0)
    rate = 40.0 + np.random.default_rng(3).standard_normal(t.size)
    rate[60:70] += 2000.0  # handled a minute after the start
    mask = detect_motion(t, rate)
    assert mask.moving[:60].all() and not mask.moving[200:].any()


def test_bursts_without_motion_are_never_short_still():
    t = np.concatenate([k * 300.0 + np.arange(0.0, 5.0, 0.02) for k in range(20)])
    rate = 40.0 + np.random.default_rng(4).standard_normal(t.size)
    assert not detect_motion(t, rate).moving.any()


def test_a_jittery_clock_is_no_rate_change_and_a_real_change_is_told_in_digits_that_differ():
    rng = np.random.default_rng(5)
    # a slow logger's clock: steps of 9-21 s, median 10 s, mean 3 % longer (skewed)
    steps = np.where(rng.random(30000) < 0.03, rng.uniform(19.0, 21.0, 30000),
                     rng.normal(10.0, 0.02, 30000))
    time_s = np.cumsum(steps)
    validator = _validate(time_s / 10.0, np.arange(time_s.size, dtype=float))  # 1 Hz scale
    assert validator.time_axis.rate_change is None
    # a real change, 1 % faster from row 5000: its message says two different rates
    time_s = np.r_[np.arange(5000.0), 5000.0 + np.arange(5000.0) / 1.0125]
    validator = _validate(time_s, np.arange(time_s.size, dtype=float))
    (problem,) = [p for p in validator.time_axis.problems("error", False)
                  if p.kind == "sample_rate"]
    assert "changes to 1.01 Hz but the metadata (and the start of the file) say 1 Hz" in \
        problem.message or "changes to 1.012 Hz" in problem.message, problem.message


def test_a_slow_logger_of_clock_times_is_not_told_its_time_is_in_milliseconds(tmp_path):
    from hrgtc.recording import read

    rng = np.random.default_rng(7)
    seconds = np.cumsum(rng.uniform(9.0, 11.0, 400))  # a 0.1 Hz logger, jittery clock
    stamps = np.datetime64("2024-05-01T10:00:00") + (seconds * 1e3).astype("timedelta64[ms]")
    rows = [f"{s},{20 + 0.01 * k:.3f},{50 + 3 * rng.standard_normal():.4f}"
            for k, s in enumerate(stamps.astype(str))]
    path = tmp_path / "slow.csv"
    path.write_text("clock,temp,gyro\n" + "\n".join(rows) + "\n")
    recording = read(path, columns={"time_s": "clock", "temperature_c": "temp",
                                    "rate_dph": "gyro"}, thermometer="sensor")
    assert len(recording) == 400 and 0.09 < recording.sample_rate_hz < 0.11


def test_a_blank_in_a_column_nothing_reads_refuses_nothing(tmp_path):
    # a fuzzed real file (issue 27): blanks in the logger's own status word refused the file
    from hrgtc.recording import read

    n = 600
    rng = np.random.default_rng(8)
    status = np.where(rng.random(n) < 0.05, "", "0")
    rows = [f"{k},{20 + 0.001 * k:.3f},{50 + 3 * rng.standard_normal():.3f},{s}"
            for k, s in enumerate(status)]
    path = tmp_path / "status.csv"
    path.write_text("t,temp,gyro,status\n" + "\n".join(rows) + "\n")
    recording = read(path, columns={"time_s": "t", "temperature_c": "temp", "rate_dph": "gyro"},
                     thermometer="sensor")
    assert len(recording) == n and np.isnan(recording["status"]).sum() == (status == "").sum()


def test_a_duty_cycled_logger_is_bridged_by_default_and_said_so():
    from pathlib import Path

    from hrgtc.core.errors import GapWarning
    from hrgtc.recording import read

    cold = Path(__file__).resolve().parents[1] / "data" / "pan-cold-test" / \
        "pan_tvc_cold_2020-03-07.csv"
    columns = {"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s", "rate_dph_y": "gyroy rad/s",
               "rate_dph_z": "gyroz rad/s", "temperature_c": "temp"}
    with pytest.warns(GapWarning, match="a duty-cycled logger .*24 gaps.*--gaps split"):
        recording = read(cold, columns=columns, thermometer="sensor",
                         units={"time": "ms", "rate": "radps", "temp": "count"})
    assert len(recording) == 6250
    # two pauses of a continuous logger are no duty cycle: the choice is the user's
    time_s = np.r_[np.arange(0.0, 1000.0), np.arange(1100.0, 2000.0), np.arange(2100.0, 3000.0)]
    validator = _validate(time_s, np.arange(time_s.size, dtype=float))
    assert [p.kind for p in validator.time_axis.problems("error", False, 5.0)] == ["gap"]
    assert not validator.time_axis.duty_cycled(5.0)
