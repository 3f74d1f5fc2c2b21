"""Tests of hrgtc.recording.units: every factor against an independent definition.

Definitions used as truth: 1 rad = 180/π ° (``math.degrees``), 1 h = 3600 s, the
milli and micro prefixes through ``datetime.timedelta``, the fixed points of the
Celsius, Fahrenheit and Kelvin scales (water freezes at 0 °C = 32 °F = 273.15 K and
boils at 100 °C = 212 °F; −40 °C = −40 °F), and a datasheet sensitivity (131 LSB
per °/s for a ±250 °/s 16-bit gyro: 131 LSB = 1 °/s).
"""

from __future__ import annotations

import datetime as dt
import math
from pathlib import Path

import numpy as np
import pytest

from hrgtc.cli.options import UNIT_HELP
from hrgtc.core.errors import InputError, UnitWarning
from hrgtc.recording import read
from hrgtc.recording.mapping import parse_unit, to_contract_unit, unwrap_count, wrapped_count_bits
from hrgtc.recording.units import UNITS, convert, find_unit, per_sample_steps, unit_help

DPH_PER_DPS = 3600.0  # seconds in an hour
PAN = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"


@pytest.mark.parametrize(("kind", "text", "value", "expected"), [
    ("time", "ms", 1.0, dt.timedelta(milliseconds=1).total_seconds()),
    ("time", "µs", 1.0, dt.timedelta(microseconds=1).total_seconds()),
    ("time", "ns", 1000.0, dt.timedelta(microseconds=1).total_seconds()),
    ("time", "s", 2.5, 2.5),
    ("freq", "kHz", 4.4249, 4424.9),
    ("freq", "Hz", 4424.9, 4424.9),
    ("rate", "°/h", 7.0, 7.0),
    ("rate", "°/s", 1.0, DPH_PER_DPS),
    ("rate", "m°/s", 1.0, 1e-3 * DPH_PER_DPS),
    ("rate", "rad/s", 1.0, math.degrees(1.0) * DPH_PER_DPS),
    ("rate", "mrad/s", 1.0, math.degrees(1e-3) * DPH_PER_DPS),
    ("temp", "°C", 21.5, 21.5),
    ("temp", "°F", 32.0, 0.0),
    ("temp", "°F", 212.0, 100.0),
    ("temp", "°F", -40.0, -40.0),
    ("temp", "degF", 98.6, 37.0),
    ("temp", "K", 273.15, 0.0),
    ("temp", "kelvin", 373.15, 100.0),
])
def test_every_plain_factor_against_its_definition(kind, text, value, expected):
    name = parse_unit(kind, text)
    got = convert(np.array([value]), kind, name)[0]
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)
    assert to_contract_unit(np.array([value]), name)[0] == got


def test_every_unit_of_the_table_is_tested_or_special():
    plain = {(u.kind, u.name) for u in UNITS if not (u.per_sample or u.scaled)}
    special = {(u.kind, u.name) for u in UNITS if u.per_sample or u.scaled}
    assert special == {("rate", "drad"), ("rate", "ddeg"), ("rate", "lsb"), ("temp", "count")}
    assert ("time", "timestamp") in plain and len(plain) == 15


def test_help_of_the_options_is_the_table():
    for kind in ("time", "freq", "rate", "temp"):
        assert UNIT_HELP[kind] == unit_help(kind)
    assert "mradps (mrad/s, ×648/π)" in UNIT_HELP["rate"]
    assert "F (°F, (F − 32)×5/9)" in UNIT_HELP["temp"]


def test_unknown_unit_lists_the_known_ones():
    with pytest.raises(InputError, match=r"unknown rate unit 'rpm'.*mradps \(mrad/s\)"):
        find_unit("rate", "rpm")


def write_csv(path, columns):
    names = list(columns)
    rows = np.column_stack([np.asarray(columns[k], dtype=float) for k in names])
    with open(path, "w") as out:
        out.write(",".join(names) + "\n")
        for row in rows:
            out.write(",".join(repr(float(v)) for v in row) + "\n")
    return path


def test_angle_increments_per_sample_become_rates_with_each_step(tmp_path):
    rng = np.random.default_rng(5)
    steps = 0.01 + 0.002 * rng.random(400)  # jittered 100 Hz clock
    time_s = np.cumsum(steps)
    rate_radps = 1e-3 * np.sin(time_s)
    dtheta = rate_radps * np.r_[np.median(steps[1:]), steps[1:]]  # over each sample's step
    path = write_csv(tmp_path / "imu.csv", {"t": time_s, "f": np.full(400, 4424.9),
                                           "dth": dtheta})
    rec = read(path, columns={"time_s": "t", "freq_hz": "f", "rate_dph": "dth"},
               units={"rate": "rad/sample"}, validate=False)
    np.testing.assert_allclose(rec.rate_dph, np.degrees(rate_radps) * 3600.0, rtol=1e-9)
    # in degrees, streamed in chunks that cut the steps: the same
    path = write_csv(tmp_path / "imu_deg.csv", {"t": time_s, "f": np.full(400, 4424.9),
                                               "dth": np.degrees(dtheta)})
    from hrgtc.recording import ReadOptions
    options = ReadOptions(columns={"time_s": "t", "freq_hz": "f", "rate_dph": "dth"},
                          units={"rate": "ddeg"}, chunk_rows=37)
    chunked = np.concatenate([c.rate_dph for c in options.chunks(path)])
    np.testing.assert_allclose(chunked, np.degrees(rate_radps) * 3600.0, rtol=1e-9)


def test_increment_after_a_gap_covers_one_period_not_the_pause():
    time_s = np.array([0.0, 0.1, 0.2, 5.2, 5.3])
    steps = per_sample_steps(time_s, None, 0.1)
    np.testing.assert_allclose(steps, [0.1, 0.1, 0.1, 0.1, 0.1])
    np.testing.assert_allclose(per_sample_steps(np.array([0.35, 0.5]), 0.2, 0.1), [0.15, 0.15])


def test_raw_rate_count_with_datasheet_sensitivity(tmp_path):
    counts = np.array([131.0, -262.0, 0.0, 13.1])
    path = write_csv(tmp_path / "raw.csv", {"t": np.arange(4) * 0.01,
                                           "f": np.full(4, 4424.9), "g": counts})
    cols = {"time_s": "t", "freq_hz": "f", "rate_dph": "g"}
    rec = read(path, columns=cols, units={"rate": "LSB"}, rate_scale=131.0, validate=False)
    np.testing.assert_allclose(rec.rate_dph, [3600.0, -7200.0, 0.0, 360.0], rtol=1e-15)
    with pytest.raises(InputError, match="--rate-scale K from the datasheet"):
        read(path, columns=cols, units={"rate": "lsb"}, validate=False)
    with pytest.raises(InputError, match="give it with --rate-unit lsb"):
        read(path, columns=cols, rate_scale=131.0, validate=False)


def test_fahrenheit_converts_every_temperature_column(tmp_path):
    path = write_csv(tmp_path / "f.csv", {"t": np.arange(3.0), "f": np.full(3, 4424.9),
                                         "w": np.zeros(3), "chamber_c": [32.0, 50.0, 212.0],
                                         "housing_c": [-40.0, 14.0, 68.0]})
    rec = read(path, columns={"time_s": "t", "freq_hz": "f", "rate_dph": "w"},
               units={"temp": "°F"}, validate=False)
    np.testing.assert_allclose(rec["chamber_c"], [0.0, 10.0, 100.0], atol=1e-12)
    np.testing.assert_allclose(rec["housing_c"], [-40.0, -10.0, 20.0], atol=1e-12)
    with pytest.raises(InputError, match="not a count"):
        read(path, columns={"time_s": "t", "freq_hz": "f", "rate_dph": "w"},
             units={"temp": "F"}, temp_scale=0.5, validate=False)


def test_signed_count_stored_unsigned_is_unwrapped():
    assert unwrap_count(np.array([65236.0]), 16)[0] == -300.0
    assert unwrap_count(np.array([2.0**32 - 5, 7.0]), 32).tolist() == [-5.0, 7.0]
    assert wrapped_count_bits(np.array([65236.0, 65000.0, 63123.0])) == 16
    assert wrapped_count_bits(np.array([2.0**32 - 100, 2.0**32 - 3])) == 32
    assert wrapped_count_bits(np.array([1200.0, 1800.0])) is None  # an ordinary count
    assert wrapped_count_bits(np.array([65236.5, 65000.0])) is None  # not whole numbers
    assert wrapped_count_bits(np.array([40000.0, 41000.0])) is None  # far under 2^16
    # a sensor crossing zero: a mix of small positives and values just under 2^16
    assert wrapped_count_bits(np.array([65530.0, 65535.0, 0.0, 3.0, 65534.0])) == 16


def test_real_recording_count_is_unwrapped_with_a_warning():
    pan_recording_path = PAN
    cols = {"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s", "rate_dph_y": "gyroy rad/s",
            "rate_dph_z": "gyroz rad/s", "temperature_c": "temp"}
    with pytest.warns(UnitWarning, match=r"signed 16-bit count stored unsigned.*65236 -> -300"):
        rec = read(pan_recording_path, columns=cols, units={"time": "ms", "rate": "rad/s",
                                                            "temp": "count"},
                   thermometer="sensor", gaps="split", validate=False)
    assert rec["temperature_c"][0] == -300.0
    assert rec["temperature_c"].max() < 0 and rec["temperature_c"].min() == 63123 - 65536
    assert rec.metadata.extra["temperature_count_bits"] == 16
    with pytest.warns(UnitWarning):
        off = read(pan_recording_path, columns=cols, units={"time": "ms", "rate": "rad/s"},
                   temp_scale=0.01, thermometer="sensor", gaps="split", validate=False)
    assert off["temperature_c"][0] == pytest.approx(-3.0)
    kept = read(pan_recording_path, columns=cols, units={"time": "ms", "rate": "rad/s"},
                temp_scale=0.01, temp_unwrap="off", thermometer="sensor", gaps="split",
                validate=False)
    assert kept["temperature_c"][0] == pytest.approx(652.36)


# -- mutants of units.py that no test killed (make mutation, issue 21) -------------------------
def test_find_unit_names_the_kinds_for_an_unknown_kind():
    with pytest.raises(InputError) as caught:
        find_unit("speed", "m/s")
    assert str(caught.value) == ("unknown unit kind 'speed'; use one of "
                                 "['time', 'freq', 'rate', 'temp']")


@pytest.mark.parametrize(("name", "symbol"), [("ddeg", "Δθ °/sample"), ("lsb", "LSB")])
def test_convert_refuses_per_sample_and_scaled_units(name, symbol):
    with pytest.raises(InputError) as caught:
        convert(np.ones(3), "rate", name)
    assert str(caught.value) == (f"{symbol} needs the time steps or a scale; read it through "
                                 "a recording with its options")


def test_convert_gives_float64_whatever_the_input():
    out = convert(np.array([1.0, 2.0], dtype=np.float32), "rate", "radps")
    assert out.dtype == np.float64
    assert out[1] == 2.0 * 648000.0 / math.pi  # float32 would be off in the 8th digit


def test_per_sample_steps_takes_the_period_for_zero_steps_and_gaps_but_not_two_periods():
    period = 0.5
    time_s = np.array([0.0, 0.5, 0.5, 1.5, 3.0, 3.5])  # steps 0.5, 0, 1.0 (2 periods), 1.5
    assert per_sample_steps(time_s, None, period).tolist() == [0.5, 0.5, 0.5, 1.0, 0.5, 0.5]
    assert per_sample_steps(time_s, -1.0, period).tolist() == [1.0, 0.5, 0.5, 1.0, 0.5, 0.5]


def test_median_period_ignores_zero_negative_and_infinite_steps():
    from hrgtc.recording.units import median_period

    assert median_period(np.array([0.0, 1.0, -4.0, -9.0, -14.0, -13.0])) == 1.0
    assert median_period(np.array([0.0, 0.0, 0.0, 0.0, 1.0])) == 1.0
    assert median_period(np.array([0.0, 2.0, np.inf])) == 2.0
    assert median_period(np.array([5.0])) is None
    assert median_period(np.array([1.0, 1.0])) is None


def test_find_unit_ignores_case_and_spaces():
    assert find_unit("rate", " RAD / S ").name == "radps"


@pytest.mark.parametrize(("text", "name"), [("Δθdeg", "ddeg"), ("Δθrad", "drad"),
                                            ("Δθ °/sample", "ddeg"), ("m°/s", "mdps")])
def test_find_unit_accepts_its_spellings_with_a_capital_and_the_symbols_it_shows(text, name):
    """The table's "Δθdeg" and the symbols the error message lists are accepted (a capital
    Δ was compared with the lower-cased input and never matched)."""
    assert find_unit("rate", text).name == name
