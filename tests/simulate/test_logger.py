"""The logger layer of the simulator: what it keeps, how it writes it, and that the truth agrees."""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace

import numpy as np
import pytest

from hrgtc.core.errors import InputError, OutputExistsError
from hrgtc.simulate import constant, cooldown
from hrgtc.simulate.handling import Handling, orientation_matrix
from hrgtc.simulate.logged_files import csv_text, sidecar_paths, write_logged
from hrgtc.simulate.logger import RATE_FACTORS, Logger, log_run, unwrap_counter
from hrgtc.simulate.logger_presets import preset
from hrgtc.simulate.mems import G_SENSITIVITY_DPH_PER_G
from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel, count_to_celsius
from hrgtc.simulate.units import EARTH_RATE_DPH

PAN = "tests/data/pan-cold-test/pan_tvc_cold_2020-03-07.csv"
HANDLOG = "tests/data/pan-cold-test/pan_etu_cold_handlog_2020-03-07.csv"


def _burst(**kw):
    return Logger(kind="burst", sample_rate_hz=20.0, burst_s=5.0, period_s=60.0, **kw)


def test_burst_timing_keeps_burst_s_of_every_period_s():
    run = log_run(constant(20.0, 0.25), "paper-unit", _burst(), seed=3)
    t = run.truth["time_s"]
    segment = run.truth["segment"]
    assert segment.max() + 1 == 15  # 900 s / 60 s
    for k in range(15):
        ts = t[segment == k]
        assert ts.size == 100  # 5 s at 20 Hz
        assert ts[0] == pytest.approx(60.0 * k)
        assert np.allclose(np.diff(ts), 0.05)
    starts = [s["start_s"] for s in run.info["segments"]]
    assert np.allclose(np.diff(starts), 60.0)
    assert len(run) == 1500


def test_burst_rows_are_the_continuous_run_cut():
    """Same seed: the burst file's samples are the continuous file's at the same times."""
    profile = cooldown(20.0, 10.0, hours=0.5, ramp_c_per_min=0.5)
    cont = log_run(profile, "paper-unit", Logger(sample_rate_hz=20.0), seed=5)
    burst = log_run(profile, "paper-unit", _burst(), seed=5)
    index = np.searchsorted(cont.truth["time_s"], burst.truth["time_s"])
    assert np.array_equal(cont.truth["time_s"][index], burst.truth["time_s"])
    for name in ("rate_dph", "resonator_c", "bias_dph", "freq_hz"):
        assert np.array_equal(cont.truth[name][index], burst.truth[name])
    assert np.array_equal(cont.columns["gyro [deg/h]"][index], burst.columns["gyro [deg/h]"])


def test_microsecond_counter_wraps_and_unwraps_to_the_true_clock():
    logger = Logger(sample_rate_hz=10.0, time_unit="us", counter_bits=32,
                    clock_start_s=2.0**32 / 1e6 - 100.0)
    run = log_run(constant(20.0, 0.1), "paper-unit", logger, seed=0)
    written = run.columns["time_us"]
    assert written.max() < 2.0**32 and written.min() >= 0
    assert (np.diff(written) < 0).sum() == 1  # one wrap, 100 s in
    wrap_row = int(np.flatnonzero(np.diff(written) < 0)[0]) + 1
    assert run.truth["time_s"][wrap_row] == pytest.approx(100.0, abs=0.1)
    unwrapped = unwrap_counter(written, 32) / 1e6
    assert np.allclose(unwrapped, run.truth["clock_s"], atol=0.5e-6)
    assert np.allclose(unwrapped - run.truth["time_s"], logger.clock_start_s, atol=1e-6)
    # 71.6 min: the period of a 32-bit µs counter
    assert 2.0**32 / 1e6 / 60.0 == pytest.approx(71.58, abs=0.01)


def test_jitter_and_milliseconds():
    logger = Logger(sample_rate_hz=50.0, time_unit="ms", jitter_s=0.5e-3)
    run = log_run(constant(20.0, 0.05), "paper-unit", logger, seed=0)
    written = run.columns["time_ms"]
    assert np.array_equal(written, np.round(written))
    steps = np.diff(written)
    assert np.all(np.abs(steps - 20.0) <= 4.0) and np.mean(steps == 20.0) > 0.3
    assert 0.3 < np.std(written - run.truth["time_s"] * 1e3) < 0.8  # 0.5 ms jitter + rounding
    with pytest.raises(InputError, match="jitter"):
        Logger(sample_rate_hz=50.0, jitter_s=0.01)


def test_wall_clock_timestamps_step_at_daylight_saving(tmp_path):
    from hrgtc.simulate.clock import wall_clock

    # Autumn: 03:00 CEST -> 02:00 CET, the naive clock steps back an hour.
    back = wall_clock("2021-10-31T02:59:59", np.array([0.0, 1.0, 2.0]), "Europe/Berlin")
    assert back.tolist() == ["2021-10-31T02:59:59.000", "2021-10-31T02:00:00.000",
                             "2021-10-31T02:00:01.000"]
    plain = wall_clock("2021-10-31T02:59:59", np.array([0.0, 1.0]))
    assert plain.tolist() == ["2021-10-31T02:59:59.000", "2021-10-31T03:00:00.000"]
    with pytest.raises(InputError, match="time zone"):
        wall_clock("2021-10-31T02:59:59", np.array([0.0]), "Mars/Olympus")
    logger = Logger(sample_rate_hz=1.0, time_unit="timestamp", start="2021-03-28T01:59:00",
                    timezone="Europe/Berlin", restarts_s=(30.0,), restart_off_s=5.0)
    run = log_run(constant(20.0, 0.05), "paper-unit", logger, seed=0)
    stamps = run.columns["timestamp"]
    i = int(np.flatnonzero(run.truth["time_s"] == 60.0)[0])
    assert stamps[i - 1] == "2021-03-28T01:59:59.000" and stamps[i] == "2021-03-28T03:00:00.000"
    assert np.array_equal(run.truth["clock_s"], run.truth["time_s"])  # no reset at restart
    assert "--time-unit" in run.info["hrgtc_options"] and "timestamp" in run.info["hrgtc_options"]
    # the zone the clock times were written in, or the reader sees a 1 h step
    # (the suggested reading options left it out)
    options = run.info["hrgtc_options"]
    assert options[options.index("--tz") + 1] == "Europe/Berlin"
    text = csv_text(run.columns, run.kinds).splitlines()
    assert text[1].startswith("2021-03-28T01:59:00.000,")
    with pytest.raises(InputError, match="CSV only"):
        write_logged(run, tmp_path / "t.parquet")


def test_restarts_reset_the_clock_and_the_bursts():
    logger = _burst(time_unit="ms", restarts_s=(400.0,), restart_off_s=10.0,
                    clock_start_s=0.2, run_offset_dph=5.0)
    run = log_run(constant(20.0, 0.25), "paper-unit", logger, seed=2)
    t, clock = run.truth["time_s"], run.truth["clock_s"]
    assert not np.any((t >= 400.0) & (t < 410.0))
    first = np.flatnonzero(run.truth["restart"])
    assert first.tolist()[0] == 0 and len(first) == 2
    assert t[first[1]] == pytest.approx(410.0)
    assert clock[first[1]] == pytest.approx(0.2)
    assert np.allclose(clock - t, np.where(run.truth["run"] == 0, 0.2, 0.2 - 410.0), atol=1e-3)
    # bursts start again at power-on
    starts = [s["start_s"] for s in run.info["segments"] if s["run"] == 1]
    assert np.allclose(np.diff([410.0, *starts[1:]]), 60.0)
    offsets = run.truth["offset_dph"]
    for r in (0, 1):
        assert np.ptp(offsets[run.truth["run"] == r]) == 0.0
    assert run.info["restarts"][1]["run_offset_dph"] == pytest.approx(offsets[first[1]])


def test_warmup_transient_starts_again_at_each_power_on():
    logger = Logger(sample_rate_hz=5.0, restarts_s=(600.0,), warmup_dph=30.0, warmup_tau_s=60.0)
    run = log_run(constant(20.0, 0.4), "paper-unit", logger, seed=2)
    t, since = run.truth["time_s"], run.truth["clock_s"]
    assert np.allclose(run.truth["offset_dph"], 30.0 * np.exp(-since / 60.0))
    assert run.truth["offset_dph"][np.flatnonzero(run.truth["restart"])].tolist() == [30.0, 30.0]
    assert t[np.flatnonzero(run.truth["restart"])[1]] == pytest.approx(610.0)


def test_count_map_round_trip_and_unsigned_storage():
    channel = TemperatureChannel(lsb_c=0.00625, offset_c=23.375, bits=16)
    logger = Logger(sample_rate_hz=5.0, temperature=channel, frequency=False)
    run = log_run(cooldown(21.5, 15.0, hours=0.5, ramp_c_per_min=0.5), "mems-3", logger, 1)
    written = run.columns["temp_raw"]
    assert written.min() >= 0 and written.max() < 65536
    assert written[0] == 65236  # -300 counts at 21.5 °C, stored unsigned
    back = count_to_celsius(written, 0.00625, 23.375, bits=16)
    assert np.max(np.abs(back - run.truth["sensor_c"])) <= 0.00625 / 2 + 1e-12
    assert run.info["temperature"]["map"]["lsb_c"] == 0.00625
    with pytest.raises(InputError, match="does not fit"):
        log_run(constant(20.0, 0.01), "mems-3",
                replace(logger, temperature=TemperatureChannel(lsb_c=1e-5, bits=16)), 0)


def test_slower_temperature_channel_leaves_empty_cells():
    logger = Logger(sample_rate_hz=10.0, frequency=False,
                    temperature=TemperatureChannel(decimals=3, rate_hz=1.0))
    run = log_run(cooldown(20.0, 15.0, hours=0.2, ramp_c_per_min=1.0), "mems-3", logger, 0)
    temp = run.columns["temp [C]"]
    filled = np.flatnonzero(np.isfinite(temp))
    assert np.all(np.diff(filled) == 10)
    assert np.allclose(temp[filled], run.truth["sensor_c"][filled], atol=5e-4)
    text = csv_text({"temp [C]": temp[:12]}, {"temp [C]": "float:.3f"})
    assert text.splitlines()[2] == ""  # an empty cell


def test_spikes_are_where_the_truth_says():
    logger = Logger(sample_rate_hz=20.0, spikes=4, spike_dph=-6000.0, rate_unit="radps",
                    frequency=False)
    run = log_run(constant(20.0, 0.1), "mems-3", logger, seed=4)
    factor = RATE_FACTORS["radps"]
    found = []
    for axis in "xyz":
        diff = run.columns[f"gyro_{axis} [rad/s]"] - run.truth[f"rate_dph_{axis}"] * factor
        found += [(int(r), axis) for r in np.flatnonzero(np.abs(diff) > 1e-9)]
        for r in np.flatnonzero(np.abs(diff) > 1e-9):
            assert diff[r] == pytest.approx(-6000.0 * factor)
    listed = sorted((s["row"], s["axis"]) for s in run.info["spikes"])
    assert sorted(found) == listed and len(listed) == 4
    assert np.array_equal(np.flatnonzero(run.truth["spike"]), sorted({r for r, _ in listed}))


def test_duplicated_rows_follow_their_originals():
    logger = _burst(spikes=2, duplicates=5, time_unit="ms")
    run = log_run(constant(20.0, 0.25), "paper-unit", logger, seed=8)
    assert len(run) == 1505 and run.info["rows"] == 1505
    dup = np.flatnonzero(run.truth["duplicate"])
    assert dup.tolist() == run.info["duplicates"] and dup.size == 5
    for name, values in run.columns.items():
        assert np.array_equal(values[dup], values[dup - 1]), name
    assert np.array_equal(run.truth["time_s"][dup], run.truth["time_s"][dup - 1])
    keep = ~run.truth["duplicate"]
    assert np.all(np.diff(run.truth["time_s"][keep]) > 0)
    for spike in run.info["spikes"]:
        assert run.truth["spike"][spike["row"]]
    for segment in run.info["segments"]:
        rows = np.flatnonzero(run.truth["segment"] == run.truth["segment"][segment["first_row"]])
        assert rows[0] == segment["first_row"] and rows[-1] == segment["last_row"]


def test_rates_rounded_to_significant_digits():
    logger = Logger(sample_rate_hz=5.0, rate_unit="radps", rate_digits=3, frequency=False)
    run = log_run(constant(20.0, 0.02), "mems-3", logger, seed=0)
    text = csv_text(run.columns, run.kinds).splitlines()
    x = run.columns["gyro_x [rad/s]"]
    assert text[1].split(",")[1] == f"{x[0]:.2E}"
    relative = np.abs(x / (run.truth["rate_dph_x"] * RATE_FACTORS["radps"]) - 1.0)
    assert relative.max() < 5e-3 and relative.max() > 0


def test_hrg_orientation_offsets_are_earth_rate_projections():
    handling = Handling(orientations=4, handling_s=30.0, max_rate_dps=200.0)
    logger = Logger(sample_rate_hz=5.0, handling=handling, accelerometer=True)
    run = log_run(constant(20.0, 1.0), "paper-unit", logger, seed=0)
    lat = math.radians(40.0)
    earth = EARTH_RATE_DPH * np.array([math.cos(lat), 0.0, math.sin(lat)])
    for k, row in enumerate(run.info["orientations"]):
        expected = (orientation_matrix(k).T @ earth)[2] - earth[2]
        assert row["offset_dph"]["z"] == pytest.approx(expected, abs=1e-9)
        assert abs(row["offset_dph"]["z"]) <= 2 * EARTH_RATE_DPH
    assert run.info["orientations"][3]["offset_dph"]["z"] == pytest.approx(-2 * earth[2])
    still = ~run.truth["motion"]
    accel = np.column_stack([run.columns[f"acc_{a} [g]"] for a in "xyz"])
    assert np.allclose(np.linalg.norm(accel[still], axis=1), 1.0, atol=0.02)
    assert np.all(run.truth["orientation"][~still] == -1)
    assert 160.0 <= run.info["motion_peak_dps"] <= 200.0
    moving = run.truth["motion_dph"][~still]
    assert np.max(np.abs(moving)) / 3600.0 == pytest.approx(run.info["motion_peak_dps"])
    assert np.all(run.truth["motion_dph"][still] == 0.0)
    # windows: the handled rows are exactly the rows inside them
    t = run.truth["time_s"]
    inside = np.zeros_like(still)
    for w in run.info["handling_windows"]:
        inside |= (t >= w["start_s"]) & (t < w["end_s"])
    assert np.array_equal(inside, ~still)


def test_mems_orientation_offsets_follow_g_sensitivity():
    handling = Handling(orientations=3, g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G)
    logger = Logger(sample_rate_hz=2.0, frequency=False, handling=handling)
    run = log_run(constant(20.0, 1.0), "mems-3", logger, seed=0)
    up = np.array([0.0, 0.0, 1.0])
    lat = math.radians(40.0)
    earth = EARTH_RATE_DPH * np.array([math.cos(lat), 0.0, math.sin(lat)])
    for k, row in enumerate(run.info["orientations"]):
        rot = orientation_matrix(k)
        for i, axis in enumerate("xyz"):
            expected = (np.asarray(G_SENSITIVITY_DPH_PER_G[axis]) @ (rot.T @ up - up)
                        + (rot.T @ earth)[i] - earth[i])
            assert row["offset_dph"][axis] == pytest.approx(expected)
        rows = run.truth["orientation"] == k
        assert np.allclose(run.truth["offset_dph_x"][rows], row["offset_dph"]["x"])


def test_hand_warming_moves_temperature_bias_and_rate_together():
    from hrgtc.simulate import units
    from hrgtc.simulate.handling import hand_warming

    handling = Handling(orientations=2, handling_s=60.0, change_times_s=(1800.0,),
                        g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G)
    base = Logger(sample_rate_hz=1.0, frequency=False, handling=handling,
                  temperature=TemperatureChannel(decimals=3))
    warm = replace(base, handling=replace(handling, hand_warming_c=3.8))
    profile = cooldown(24.0, 20.0, hours=1.0, ramp_c_per_min=0.1)
    cold_run, warm_run = (log_run(profile, "mems-3", b, seed=3) for b in (base, warm))
    t = warm_run.truth["time_s"]
    warming = hand_warming(t, warm.handling, 3599.0)
    assert warming.max() == pytest.approx(3.8)
    assert np.allclose(warm_run.truth["sensor_c"] - cold_run.truth["sensor_c"], warming)
    law = units.get("mems-3").axes["x"].bias_law
    r, h = cold_run.truth["resonator_c_x"], cold_run.truth["housing_c"]
    change = law.bias_dph(r + warming, h) - law.bias_dph(r, h)
    assert np.allclose(warm_run.truth["bias_dph_x"] - cold_run.truth["bias_dph_x"], change)
    assert np.allclose(warm_run.truth["rate_dph_x"] - cold_run.truth["rate_dph_x"], change)
    # the true dT/dt sees the warming: +3.8 °C in 60 s while the chamber cools
    moving = warm_run.truth["motion"]
    assert np.median(warm_run.truth["dtdt_c_per_s_x"][moving]) == pytest.approx(3.8 / 60, rel=0.1)


def test_reference_log_has_the_real_hand_log_quirks():
    log = ReferenceLog(every_s=300.0, start="2020-03-07T15:44:40", lag_s=300.0, trailing_rows=3,
                       blank_fraction=0.2, empty_columns=14)
    logger = Logger(sample_rate_hz=1.0, frequency=False,
                    temperature=TemperatureChannel(decimals=2), reference_log=log)
    run = log_run(cooldown(21.5, 10.0, hours=2.0, ramp_c_per_min=0.2), "mems-3", logger, 7)
    text = run.reference_log
    assert text.startswith("\ufeffTime,F2 (F),F3 (F),F4 (F),C1 (C),")
    real = open(HANDLOG, encoding="utf-8-sig", newline="").read()
    assert text[1:].split("\r\n")[0] == real.split("\r\n")[0]  # the same header
    lines = text[1:].split("\r\n")[1:-1]
    assert all(line.count(",") == 18 for line in lines)
    assert lines[0].startswith("15:45,")
    readings = run.info["temperature"]["reference_log"]["readings"]
    assert len(lines) == len(readings) + 3
    assert all(line.endswith("," * 18) for line in lines[-3:])
    blanks = 0
    for line, reading in zip(lines, readings, strict=False):
        cell = line.split(",")[4]
        if cell == "":
            blanks += 1
            continue
        assert float(cell) == pytest.approx(reading["probe_c"], abs=0.05 + 1e-9)
    assert blanks > 0
    # the probe lags: while cooling, it reads warmer than the sensor
    late = [r for r in readings if r["probe_c"] is not None and r["time_s"] > 1800]
    assert all(r["probe_c"] > r["sensor_c"] for r in late)


def test_reference_log_with_dates_and_fahrenheit():
    log = ReferenceLog(start="2020-03-07T23:50:00", dates=True, fahrenheit=True, bom=False,
                       crlf=False, blank_fraction=0.0, trailing_rows=0, empty_columns=0)
    logger = Logger(sample_rate_hz=1.0, frequency=False,
                    temperature=TemperatureChannel(), reference_log=log)
    run = log_run(constant(20.0, 0.5), "mems-3", logger, 0)
    lines = run.reference_log.split("\n")
    assert lines[0] == "Time,F2 (F),F3 (F),F4 (F),C1 (F)"
    assert lines[1].startswith("2020-03-07 23:50,") and lines[3].startswith("2020-03-08 00:00,")
    assert float(lines[1].split(",")[4]) == pytest.approx(68.0, abs=0.1)


def test_written_files_round_trip(tmp_path):
    p = preset("pan-cold")
    run = log_run(p.profile, p.unit, replace(p.logger, reference_log=None), seed=1)
    files = write_logged(run, tmp_path / "pan.csv")
    data = np.genfromtxt(files.path, delimiter=",", names=True, deletechars="")
    header = open(files.path).readline().strip().split(",")
    assert header == list(run.columns)
    for k, name in enumerate(header):
        assert np.array_equal(data[data.dtype.names[k]], run.columns[name]), name
    info = json.loads(open(files.truth_json).read())
    assert info["rows"] == len(run) and info["spikes"] == run.info["spikes"]
    truth = np.genfromtxt(files.truth_csv, delimiter=",", names=True)
    assert truth.size == len(run)
    assert np.array_equal(truth["time_s"], run.truth["time_s"])
    with pytest.raises(OutputExistsError):
        write_logged(run, tmp_path / "pan.csv")
    parquet = write_logged(run, tmp_path / "pan2.parquet")
    import pyarrow.parquet as pq

    back = pq.read_table(parquet.path)
    assert back.column_names == list(run.columns)
    assert np.array_equal(back["time (ms)"].to_numpy(), run.columns["time (ms)"])
    assert sidecar_paths(tmp_path / "a.csv")["reference_log"].name == "a_reflog.csv"


def test_hdf5_writes_slashes_in_names_as_per(tmp_path):
    import h5py

    run = log_run(constant(20.0, 0.02), "paper-unit", Logger(sample_rate_hz=5.0), seed=0)
    files = write_logged(run, tmp_path / "run.h5")
    with h5py.File(files.path) as f:
        assert np.array_equal(f["recording/gyro [deg_per_h]"][()], run.columns["gyro [deg/h]"])
    info = json.loads(open(files.truth_json).read())
    assert info["columns"]["rate"] == "gyro [deg_per_h]"
    assert "rate_dph=gyro [deg_per_h]" in info["hrgtc_options"]


def test_pan_cold_preset_looks_like_the_real_file():
    start = time.perf_counter()
    p = preset("pan-cold")
    run = log_run(p.profile, p.unit, p.logger, seed=0)
    assert time.perf_counter() - start < 5.0  # 2 h at 50 Hz in bursts: seconds
    real_header = open(PAN).readline().strip().split(",")
    assert real_header == list(run.columns)
    real = np.genfromtxt(PAN, delimiter=",", skip_header=1)
    assert len(run) == real.shape[0] == 6250
    t = run.columns["time (ms)"]
    assert t[0] == pytest.approx(real[0, 0], abs=3)
    steps = np.diff(t)
    assert np.median(steps) == 20 and np.sum(steps > 1000) == 24
    real_steps = np.diff(real[:, 0])
    assert np.allclose(steps[steps > 1000], np.median(real_steps[real_steps > 1000]), atol=25)
    assert abs(run.columns["temp"][0] - 65236) <= 5  # -300 counts, stored unsigned
    rates = np.column_stack([run.columns[f"gyro{a} rad/s"] for a in "xyz"])
    assert np.allclose(np.median(rates, axis=0), np.median(real[:, 4:7], axis=0), atol=0.01)
    assert len(run.info["spikes"]) == 3

    def bursts(time_ms, rates):
        segment = np.cumsum(np.r_[0, np.diff(time_ms) > 1000])
        parts = [rates[segment == k] for k in range(segment.max() + 1)]
        return (np.median([p.std(axis=0) for p in parts], axis=0),
                np.array([p.mean(axis=0) for p in parts]))

    noise_sim, means_sim = bursts(t, rates)
    noise_real, means_real = bursts(real[:, 0], real[:, 4:7])
    assert np.allclose(noise_sim, noise_real, rtol=0.15)  # 0.00053 rad/s within a burst
    drift_sim, drift_real = means_sim[-1] - means_sim[0], means_real[-1] - means_real[0]
    assert np.allclose(drift_sim[:2], drift_real[:2], rtol=0.4)  # x -0.0086, y +0.0040 rad/s
    sensor = run.truth["sensor_c"]
    assert sensor[0] == 21.5 and 6.0 < sensor[-1] < 11.0  # the real unit: 21.5 -> 8.8 °C
    dtdt = run.info["dfdt_still"]["dtdt_c_per_s"]["x"]
    assert -10.0 < dtdt["min"] * 3600 < -5.0  # the real cool-down: about -6 °C/h


def test_fridge_preset_has_three_orientations_and_handling():
    p = preset("fridge-3day")
    short = replace(p.logger, handling=replace(p.logger.handling, change_times_s=(3000.0, 6000.0)))
    run = log_run(constant(24.0, 3.0), p.unit, short, seed=0)
    assert set(np.unique(run.truth["orientation"])) == {-1, 0, 1, 2}
    assert 448.0 <= run.info["motion_peak_dps"] <= 560.0
    assert run.truth["motion"].sum() == 120
    assert "gx_mrad_s" in run.columns and "ax_m_s2" in run.columns
    peak = max(np.max(np.abs(run.columns[f"g{a}_mrad_s"])) for a in "xyz")
    assert peak > 448.0 * math.pi / 180 * 1000 * 0.99
    hours = p.profile.duration_s / 3600.0
    assert hours == pytest.approx(72.0)
    assert p.profile.chamber_c([0.0, 20 * 3600.0, 50 * 3600.0]).tolist() == [24.0, 5.0, 24.0]


def test_logger_refuses_bad_settings():
    with pytest.raises(InputError, match="shorter than period_s"):
        Logger(kind="burst", burst_s=300.0, period_s=300.0)
    with pytest.raises(InputError, match="ms or us"):
        Logger(counter_bits=32)
    with pytest.raises(InputError, match="rate_unit"):
        Logger(rate_unit="rpm")
    with pytest.raises(InputError, match="not roles"):
        log_run(constant(20.0, 0.01), "paper-unit", Logger(columns={"rate_q": "q"}), 0)
    with pytest.raises(InputError, match="needs a logged temperature"):
        Logger(reference_log=ReferenceLog())
    with pytest.raises(InputError, match="one per ten rows"):
        log_run(constant(20.0, 0.01), "paper-unit", Logger(sample_rate_hz=1.0, spikes=10), 0)
    with pytest.raises(InputError, match="one per ten rows"):
        log_run(constant(20.0, 0.01), "paper-unit", Logger(sample_rate_hz=1.0, duplicates=9), 0)
    with pytest.raises(InputError, match="leaves no run"):
        log_run(constant(20.0, 0.01), "paper-unit", Logger(restarts_s=(30.0,)), 0)


def test_cli_logger_burst_and_preset_overrides(tmp_path):
    from typer.testing import CliRunner

    from hrgtc.cli import app

    runner = CliRunner()
    args = ["simulate", "--logger", "burst", "--profile", "constant", "--hours", "0.1",
            "--rate-hz", "10", "--burst-s", "2", "--period-s", "30", "--time-unit", "ms",
            "--counter-bits", "32", "-o", str(tmp_path / "b.csv"), "--json"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.stderr
    written = json.loads(result.stdout)[0]
    assert written["rows"] == 12 * 20  # 360 s / 30 s bursts of 2 s at 10 Hz
    info = json.loads(open(written["truth_json"]).read())
    assert info["logger"]["kind"] == "burst" and info["logger"]["counter_bits"] == 32
    assert "--gaps" in info["hrgtc_options"]
    again = runner.invoke(app, args)
    assert again.exit_code != 0 and "exist" in again.stderr
    result = runner.invoke(app, ["simulate", "--logger", "pan-cold", "--spikes", "0",
                                 "--no-reference-log", "--hours", "0.5", "--profile",
                                 "constant", "-o", str(tmp_path / "p.csv"), "--json"])
    assert result.exit_code == 0, result.stderr
    info = json.loads(open(json.loads(result.stdout)[0]["truth_json"]).read())
    assert info["spikes"] == [] and info["unit"] == "mems-3"
    assert info["logger"]["rate_unit"] == "radps" and info["temperature"]["map"]["lsb_c"]
    assert not (tmp_path / "p_reflog.csv").exists()
    assert info["rows"] == 6 * 250  # 1800 s: bursts at 0, 305, ..., 1525 s


def test_cli_preset_without_its_accelerometer(tmp_path):
    """``--logger fridge-3day --no-accelerometer`` writes the file without the
    accelerometer columns (it failed: the preset's names of those columns were kept)."""
    from typer.testing import CliRunner

    from hrgtc.cli import app

    result = CliRunner().invoke(app, ["simulate", "--logger", "fridge-3day",
                                      "--no-accelerometer", "--profile", "constant",
                                      "--hours", "0.1", "-o", str(tmp_path / "f.csv"), "--json"])
    assert result.exit_code == 0, result.output
    header = (tmp_path / "f.csv").read_text().splitlines()[0].split(",")
    assert header == ["timestamp_ms", "gx_mrad_s", "gy_mrad_s", "gz_mrad_s", "temp_C"]
    info = json.loads((tmp_path / "f.truth.json").read_text())
    assert info["logger"]["accelerometer"] is False and info["rows"] == 360


def test_true_dfdt_from_the_slow_track_matches_the_samples():
    """The truth's dT/dt and df/dt (from a ~1 Hz track of the whole run) agree with the
    derivative of the kept samples' noiseless resonator temperature and frequency law."""
    from hrgtc.simulate import units

    run = log_run(cooldown(20.0, 0.0, hours=1.0, ramp_c_per_min=0.5), "paper-unit",
                  Logger(sample_rate_hz=10.0), seed=0)
    t, resonator = run.truth["time_s"], run.truth["resonator_c"]
    direct = np.gradient(resonator, t)
    assert np.allclose(run.truth["dtdt_c_per_s"][10:-10], direct[10:-10],
                       atol=1e-3 * np.max(np.abs(direct)))
    law = units.get("paper-unit").frequency_law
    dfdt = np.gradient(law.frequency_hz(resonator), t)
    assert np.allclose(run.truth["dfdt_hz_per_s"][10:-10], dfdt[10:-10],
                       atol=1e-3 * np.max(np.abs(dfdt)))
    still = run.info["dfdt_still"]["dfdt_hz_per_s"]["x"]
    assert still["min"] == pytest.approx(run.truth["dfdt_hz_per_s"].min())


def test_memory_follows_the_kept_rows():
    """10 h at 200 Hz in 5 s bursts every 300 s: 120,000 rows kept of 7.2 M simulated."""
    logger = Logger(kind="burst", sample_rate_hz=200.0, burst_s=5.0, period_s=300.0)
    run = log_run(constant(20.0, 10.0), "paper-unit", logger, seed=0)
    assert len(run) == 120 * 1000
    assert run.info["simulated_rows"] == 7_200_000
