"""Tests of hrgtc.thermometry.reference: a raw count's map to °C from a sparse reference log.

Truth: simulated recordings whose count is a known linear function of a known
temperature (scale, offset and the reference probe's lag chosen by the test), with
the reference log written the way operators write one (clock times, °F, a byte-order
mark, blank cells, trailing empty columns, a midnight in between); and the real PAN
cold test, whose map must not depend on the stated start within the lag search.
"""

from __future__ import annotations

import datetime as dt
import json
from pathlib import Path

import numpy as np
import pytest

from hrgtc.core.errors import CalibrationError, RecordingError
from hrgtc.recording import ReadOptions
from hrgtc.thermometry.reference import (
    TemperatureMap,
    fit_count_map,
    map_from_reference,
    options_with_map,
    read_reference_log,
)

DATA = Path(__file__).parents[1] / "data" / "pan-cold-test"
PAN = DATA / "pan_tvc_cold_2020-03-07.csv"
HANDLOG = DATA / "pan_etu_cold_handlog_2020-03-07.csv"
PAN_COLUMNS = {"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s", "rate_dph_y": "gyroy rad/s",
               "rate_dph_z": "gyroz rad/s", "temperature_c": "temp"}
PAN_OPTIONS = ReadOptions(columns=PAN_COLUMNS, units={"time": "ms", "rate": "rad/s"},
                          thermometer="sensor", gaps="split")
SCALE, OFFSET, LAG_S = 0.0059, 24.2, 240.0


def truth_c(time_s):
    """A chamber cool-down: 22 °C, a ramp to 9 °C from t = 1200 to 5000 s, then a hold. [°C]

    Not an exponential: a delay of an exponential is a change of its scale, which a
    linear map absorbs, so its lag could not be told from the map (see the docs).
    """
    ramp = np.clip((np.asarray(time_s) - 1200.0) / 3800.0, 0.0, 1.0)
    return 22.0 - 13.0 * ramp


def burst_recording(seed=0):
    """Bursts of 5 s at 50 Hz every 300 s; the count of the truth, rounded, noisy."""
    rng = np.random.default_rng(seed)
    time_s = np.concatenate([k * 300.0 + 15.0 + np.arange(250) / 50.0 for k in range(25)])
    count = np.round((truth_c(time_s) - OFFSET) / SCALE + 2.0 * rng.standard_normal(time_s.size))
    return time_s, count


def write_log(path, start, minutes, fahrenheit=True, lag_s=LAG_S):
    """A hand log every 5 min: HH:MM clock times, the reference lagging the sensor."""
    lines = ["\ufeffTime,Probe (F),Probe (C),,,"]
    for k in range(minutes // 5):
        clock = start + dt.timedelta(minutes=5 * k)
        t = (clock - start).total_seconds()
        value = float(np.round(truth_c(t - lag_s), 1))
        temp = value * 9.0 / 5.0 + 32.0 if fahrenheit else value
        blank = k == 7  # a reading nobody wrote down
        lines.append(f"{clock:%H:%M},{'' if blank else round(temp, 2)},{value},,,")
    lines.append("00:00,,,,,")  # trailing rows of the template, blank
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_map_and_lag_from_a_fahrenheit_hand_log_across_midnight(tmp_path):
    start = dt.datetime(2020, 3, 7, 23, 40)
    log_path = write_log(tmp_path / "log.csv", start, 125)
    log = read_reference_log(log_path, {"time_s": "Time", "temperature_c": "Probe (F)"},
                             start="23:40")
    assert log.unit == "F" and log.skipped == 2  # °F from the header; two blank readings
    assert log.time_s[0] == 0.0 and log.time_s[-1] == 120 * 60.0  # 00:00 … 01:40 after 23:40
    time_s, count = burst_recording()
    fitted = fit_count_map(time_s, count, log)
    assert fitted.scale_c_per_count == pytest.approx(SCALE, rel=0.01)
    assert fitted.offset_c == pytest.approx(OFFSET, abs=0.1)
    assert abs(fitted.lag_s - LAG_S) <= 30.0
    assert fitted.residual_rms_c < 0.06  # the log's 0.1 °C rounding, (0.1/√12 = 0.029)
    assert fitted.points == len(log.time_s) - 1  # the last reading is past the recording
    # a lag held at 0 takes the error as a bias: a worse residual
    held = fit_count_map(time_s, count, log, lag_s=0.0)
    assert held.residual_rms_c > 3 * fitted.residual_rms_c


def test_a_start_wrong_by_minutes_moves_the_lag_not_the_map(tmp_path):
    start = dt.datetime(2020, 3, 7, 15, 40)
    log_path = write_log(tmp_path / "log.csv", start, 125, fahrenheit=False)
    columns = {"time_s": "Time", "temperature_c": "Probe (C)"}
    time_s, count = burst_recording(1)
    right = fit_count_map(time_s, count, read_reference_log(log_path, columns, start="15:40"))
    late = fit_count_map(time_s, count, read_reference_log(log_path, columns, start="15:45"))
    assert late.lag_s == pytest.approx(right.lag_s - 300.0, abs=1e-9)
    assert late.scale_c_per_count == pytest.approx(right.scale_c_per_count, rel=1e-9)
    assert late.offset_c == pytest.approx(right.offset_c, rel=1e-9)


def test_seconds_dates_and_time_zones(tmp_path):
    path = tmp_path / "secs.csv"
    path.write_text("time_s,temperature_c\n0,20\n600,19\n\n1200,18\n", encoding="utf-8")
    log = read_reference_log(path)
    np.testing.assert_array_equal(log.time_s, [0.0, 600.0, 1200.0])
    stamped = tmp_path / "stamped.csv"
    stamped.write_text("when,T\n2020-03-07T16:45:00+01:00,20\n2020-03-07T16:50:00+01:00,19\n",
                       encoding="utf-8")
    cols = {"time_s": "when", "temperature_c": "T"}
    log = read_reference_log(stamped, cols, start="2020-03-07T15:40:00Z")
    np.testing.assert_array_equal(log.time_s, [300.0, 600.0])
    with pytest.raises(RecordingError, match="--temp-ref-tz"):
        read_reference_log(stamped, cols, start="2020-03-07T15:40:00")
    log = read_reference_log(stamped, cols, start="2020-03-07T16:40:00", tz="+01:00")
    np.testing.assert_array_equal(log.time_s, [300.0, 600.0])


def test_errors_name_the_file_column_and_fix(tmp_path):
    path = tmp_path / "clock.csv"
    path.write_text("Time,C1 (C)\n15:45,21.5\n15:50,x\n", encoding="utf-8")
    cols = {"time_s": "Time", "temperature_c": "C1 (C)"}
    with pytest.raises(RecordingError, match=r"'C1 \(C\)', line 3: 'x' is not a number"):
        read_reference_log(path, cols, start="15:40")
    path.write_text("Time,C1 (C)\n15:45,21.5\n15:50,21.4\n", encoding="utf-8")
    with pytest.raises(RecordingError, match="--temp-ref-start"):
        read_reference_log(path, cols)
    with pytest.raises(RecordingError, match=r"'Probe' .* not found.*--temp-ref-col"):
        read_reference_log(path, {"time_s": "Time", "temperature_c": "Probe"}, start="15:40")
    time_s, count = burst_recording()
    far = read_reference_log(path, cols, start="09:00")  # 7 h before: no reading inside
    with pytest.raises(CalibrationError, match="is --temp-ref-start the clock time"):
        fit_count_map(time_s, count, far)


def test_map_round_trips_and_reaches_the_reading_options():
    fitted = TemperatureMap(0.005, 24.0, 16, 120.0, 0.2, 0.4, 25, (-2400.0, -300.0), "log.csv")
    again = TemperatureMap.from_dict(json.loads(json.dumps(fitted.to_dict())))
    assert again == fitted
    options = options_with_map(ReadOptions(), fitted.to_dict())
    assert (options.temp_scale, options.temp_offset_c, options.temp_unwrap) == (0.005, 24.0, "16")
    mine = ReadOptions(temp_scale=0.01)  # the user's own scale wins
    assert options_with_map(mine, fitted) is mine


def test_real_cold_test_map_from_its_hand_log():
    cols = {"time_s": "Time", "temperature_c": "C1 (C)"}
    with pytest.warns(UserWarning, match="signed 16-bit count"):
        fitted = map_from_reference(PAN, HANDLOG, PAN_OPTIONS, columns=cols, start="15:45")
    # 25 readings 15:45 … 17:45 fall on the recording; the fitted lag (440 s) leaves the
    # last one beyond its end. Lags are compared by residual variance per degree of freedom
    assert fitted.points == 24 and fitted.count_bits == 16
    assert fitted.scale_c_per_count == pytest.approx(0.005870, rel=1e-3)
    assert fitted.offset_c == pytest.approx(24.279, abs=1e-3)
    assert fitted.residual_rms_c == pytest.approx(0.273, abs=1e-3)
    assert fitted.lag_s == 440.0
    # the first burst (count ≈ −303) maps to ≈ 22.4 °C, the last (≈ −2413) to ≈ 10.1 °C
    assert fitted.apply(np.array([-303.0]))[0] == pytest.approx(22.50, abs=0.01)
    with pytest.warns(UserWarning):
        earlier = map_from_reference(PAN, HANDLOG, PAN_OPTIONS, columns=cols, start="15:30")
    assert earlier.scale_c_per_count == pytest.approx(fitted.scale_c_per_count, rel=1e-12)
    assert earlier.lag_s == fitted.lag_s + 900.0


def test_the_map_is_fitted_whatever_the_spikes_policy():
    """Issue 27: with --spikes drop the raw count (-300, unwrapped) was judged an
    impossible temperature before the map was fitted: every row dropped, "the recording
    has no rows". Impossible temperatures are judged after the map."""
    from dataclasses import replace

    cols = {"time_s": "Time", "temperature_c": "C1 (C)"}
    with pytest.warns(UserWarning, match="signed 16-bit count"):
        fitted = map_from_reference(PAN, HANDLOG, replace(PAN_OPTIONS, spikes="drop"),
                                    columns=cols, start="15:45")
    assert fitted.points == 24 and fitted.lag_s == 440.0
    assert fitted.scale_c_per_count == pytest.approx(0.005870, rel=1e-3)


def test_reference_columns_option():
    from hrgtc.core.errors import InputError
    from hrgtc.thermometry.reference import parse_reference_columns

    assert parse_reference_columns(["time_s=Time", "temperature_c=C1 (C)"]) == {
        "time_s": "Time", "temperature_c": "C1 (C)"}
    with pytest.raises(InputError, match="--temp-ref-col 'probe=C1': write NAME=THEIRS"):
        parse_reference_columns(["probe=C1"])
