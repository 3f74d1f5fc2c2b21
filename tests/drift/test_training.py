"""Tests of hrgtc.drift.training: training statistics and the noise check of recordings.

Issue 21, Deliver 2: a wrong unit that makes values larger (``--rate-unit dps`` on °/h
data) passed every check. Truth: the simulator's white noise (2 °/h per sample at
10 Hz: differences of std 2√2, MAD 0.6745·2√2 = 1.908 °/h), and unit factors applied
here by hand.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.drift.training import (
    UNIT_FACTORS,
    TrainingStatistics,
    check_noise,
    rate_noise_dph,
    unit_mistake,
)

from synthetic import ramp_run

EXPECTED_MAD = 0.6745 * 2.0 * math.sqrt(2.0)  # white noise 2 °/h: MAD of differences


@pytest.fixture(scope="module")
def statistics():
    return TrainingStatistics.from_runs([ramp_run(seed=11, hours=1.0),
                                         ramp_run(seed=12, hours=1.0)])


def test_the_noise_of_the_training_runs_is_the_simulated_one(statistics):
    assert statistics.rate_noise_dph == pytest.approx(EXPECTED_MAD, rel=0.03)
    assert statistics.sample_rate_hz == 10.0 and statistics.runs == 2
    # the slow drift (a ramp of several °/h in bias) does not enter the differences
    assert statistics.rate_level_dph == pytest.approx(10.0 + 1.5, abs=30.0)
    back = TrainingStatistics.from_dict(statistics.to_dict())
    assert back == statistics


@pytest.mark.parametrize("factor", [f for f, _, _ in UNIT_FACTORS])
@pytest.mark.parametrize("direction", [1, -1])
def test_unit_factors_either_way_are_refused_naming_the_mistake(statistics, factor,
                                                                direction):
    run = ramp_run(seed=3, start_c=5.0, end_c=0.0, hours=0.3)
    scaled = run.rate_dph * factor ** direction
    with pytest.raises(InputError) as raised:
        check_noise(statistics, scaled, 10.0, "run.csv")
    message = str(raised.value)
    assert message.startswith("run.csv: column 'rate_dph': its noise")
    _, larger, smaller = next(u for u in UNIT_FACTORS if u[0] == factor)
    assert (larger if direction == 1 else smaller) in message
    assert "np." not in message


def test_the_dps_mistake_of_the_issue_names_the_option(statistics):
    """`--rate-unit dps` on °/h data: every value × 3600 (bias stability 1.169 -> 4208)."""
    run = ramp_run(seed=3, start_c=5.0, end_c=0.0, hours=0.3)
    with pytest.raises(InputError, match=r"3600.*--rate-unit dps on a rate in °/h"):
        check_noise(statistics, run.rate_dph * 3600.0, 10.0)


@pytest.mark.parametrize("level_dph", [360_000.0, 14_400.0, -14_400.0])
def test_another_level_is_accepted(statistics, level_dph):
    """A 100 °/s rate-table run and a MEMS file with a ±4 °/s offset: same noise."""
    run = ramp_run(seed=4, start_c=5.0, end_c=0.0, hours=0.3)
    ratio = check_noise(statistics, run.rate_dph + level_dph, 10.0)
    assert ratio == pytest.approx(1.0, rel=0.1)


def test_noise_is_compared_at_the_training_rate(statistics):
    """White noise of the same density at 40 Hz has twice the per-sample noise: scaled by
    √(10/40) it is the training noise."""
    rng = np.random.default_rng(5)
    density = 2.0 / math.sqrt(10.0)  # the training noise's σ/√fs
    rate = rng.normal(0.0, density * math.sqrt(40.0), 200_000)
    assert rate_noise_dph(rate) == pytest.approx(2.0 * EXPECTED_MAD, rel=0.03)
    assert statistics.noise_ratio(rate, 40.0) == pytest.approx(1.0, rel=0.05)


def test_no_statistics_or_a_quantised_rate_is_not_compared(statistics):
    assert math.isnan(check_noise(None, np.arange(100.0), 10.0))
    steps = np.repeat(np.arange(50.0), 20)  # mostly equal neighbours: MAD 0
    assert math.isnan(check_noise(statistics, steps, 10.0))
    assert unit_mistake(1.0) is None and unit_mistake(5.0) is None
    assert unit_mistake(math.nan) is None


# -- calibrate, where there is no model ------------------------------------------------------
def test_an_hrg_with_mems_noise_is_refused_naming_the_unit():
    from hrgtc.drift.training import check_resonator_gyro

    run = ramp_run(seed=3, start_c=5.0, end_c=0.0, hours=0.3)
    check_resonator_gyro(run.rate_dph, 10.0, 10.0, "run.csv")  # a plausible HRG: no error
    with pytest.raises(InputError) as raised:
        check_resonator_gyro(run.rate_dph * 3600.0, 10.0, 10.0, "run.csv")
    message = str(raised.value)
    assert message.startswith("run.csv: column 'rate_dph': a noise density of")
    assert "only a MEMS gyro could have" in message
    assert "--rate-unit dps on a rate in °/h) (values × 3600)" in message
    # a bias of 4 °/s at rest: a MEMS bias
    with pytest.raises(InputError, match=r"a bias of 1\.44\d*e\+04 °/h at rest"):
        check_resonator_gyro(run.rate_dph + 14_400.0, 10.0, 10.0)


def test_a_noise_density_beyond_any_gyro_is_warned_about():
    from hrgtc.drift.training import implausible_for_any_gyro, noise_density

    run = ramp_run(seed=3, start_c=5.0, end_c=0.0, hours=0.3)
    # the simulated 2 °/h per sample at 10 Hz: 0.63 °/h/√Hz
    assert noise_density(run.rate_dph, 10.0) == pytest.approx(2.0 / math.sqrt(10.0), rel=0.05)
    assert implausible_for_any_gyro(run.rate_dph, 10.0) is None
    # a MEMS-like 36 °/h/√Hz read ×3600 (°/h data as dps) is beyond every gyro ...
    rng = np.random.default_rng(1)
    mems = rng.normal(0.0, 36.0 * math.sqrt(10.0), 20_000)
    assert implausible_for_any_gyro(mems, 10.0) is None
    assert "above the noisiest gyro's" in implausible_for_any_gyro(mems * 3600.0, 10.0)
    # ... but ÷3600 (dps data read as °/h) looks like a good HRG: it cannot be told
    assert implausible_for_any_gyro(mems / 3600.0, 10.0) is None


def test_calibrate_refuses_rate_unit_dps_on_an_hrg(paper_campaign):
    """The issue's case: calibrate fitted a model on °/h data read with --rate-unit dps."""
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.recording import ReadOptions

    files = paper_campaign
    with pytest.raises(InputError, match=r"cooldown.*only a MEMS gyro.*--rate-unit dps"):
        calibrate(files.soaks[:3], [files.cooldown],
                  read_options=ReadOptions(units={"rate": "dps"}))


def test_the_pan_mems_recording_by_its_noise():
    """Reality check on the real PAN recording (3-axis MEMS, rad/s, 50 Hz bursts): the
    statistics of its rad/s reading accept the same reading, and refuse it read as °/s
    (× 1/57.3), naming rad/s (read as °/h, the reader itself finds it too small). Its rate
    is quantised (few distinct steps), which the MAD of differences survives."""
    from pathlib import Path

    from hrgtc.recording import ReadOptions

    pan = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
    columns = {"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s", "rate_dph_y": "gyroy rad/s",
               "rate_dph_z": "gyroz rad/s", "temperature_c": "temp"}

    def read_as(rate_unit):
        options = ReadOptions(columns=columns, units={"time": "ms", "rate": rate_unit,
                                                      "temp": "count"},
                              temp_scale=0.00582219, temp_offset_c=24.1839,  # its map
                              gaps="split", thermometer="sensor", axis="x")
        return options.head(pan, rows=6000)

    right = read_as("rad/s")
    statistics = TrainingStatistics.from_runs([right])
    assert statistics.rate_noise_dph > 0.0
    fs = right.metadata.sample_rate_hz
    assert check_noise(statistics, right.rate_dph, fs) == pytest.approx(1.0)
    wrong = read_as("dps")
    with pytest.raises(InputError, match=r"rad/s data read as °/s \(pass --rate-unit rad/s\)"):
        check_noise(statistics, wrong.rate_dph, fs, "pan.csv", "rate_dph_x")


# -- calibrate --thermometer sensor: is the thermometer column a temperature? ----------------
def test_channel_shape_of_a_temperature_and_of_a_rate():
    """A temperature changes smoothly (noise 1e-4 of its span on the simulator), a rate at
    rest is noise (the MAD of differences of white noise 0.954σ over its 1-99 % span 4.65σ:
    0.205). Chunked accumulation equals one pass."""
    from hrgtc.drift.training import ChannelShape

    run = ramp_run(seed=3, start_c=10.0, end_c=0.0, hours=0.25, ramp_hours=0.5)
    temperature, rate = ChannelShape(), ChannelShape()
    for start in range(0, len(run), 1000):
        temperature.partial_fit(run["resonator_c"][start:start + 1000])
        rate.partial_fit(run.rate_dph[start:start + 1000])
    assert temperature.smoothness < 1e-3
    white = ChannelShape()
    white.partial_fit(np.random.default_rng(2).normal(5.0, 2.0, 50_000))
    assert white.smoothness == pytest.approx(0.6745 * math.sqrt(2.0) / (2 * 2.326), rel=0.05)
    assert 0.05 < rate.smoothness < 0.3  # noise plus the simulator's slow drift


def test_swapped_rate_and_temperature_of_a_sensor_gyro_are_named():
    """Issue 21's audit: calibrate --thermometer sensor on a file whose rate_dph and
    temperature_c headers are swapped said the run "spans only 0.7 °C" of temperature."""
    from hrgtc.drift.training import ChannelShape, check_sensor_swap

    run = ramp_run(seed=3, start_c=10.0, end_c=0.0, hours=0.25, ramp_hours=0.5)
    temperature, rate = ChannelShape(), ChannelShape()
    temperature.partial_fit(run["resonator_c"])
    rate.partial_fit(run.rate_dph)
    check_sensor_swap(temperature, rate, "run.csv", "temperature_c", "rate_dph")  # no error
    with pytest.raises(InputError) as raised:
        check_sensor_swap(rate, temperature, "run.csv", "temperature_c", "rate_dph")
    message = str(raised.value)
    assert message.startswith("run.csv: the headers rate_dph and temperature_c look swapped")
    assert "--col rate_dph=temperature_c --col temperature_c=rate_dph" in message


def test_the_pan_mems_recording_is_no_swap_and_its_swap_is_found():
    """Reality check on the real PAN recording (MEMS, 12 °C of cooling, quantised
    temperature, a rate of 80-100 °/h of noise per sample): its columns pass, the same
    columns swapped are found on every axis."""
    from pathlib import Path

    from hrgtc.drift.training import ChannelShape, check_sensor_swap
    from hrgtc.recording import ReadOptions

    pan = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
    columns = {"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s", "rate_dph_y": "gyroy rad/s",
               "rate_dph_z": "gyroz rad/s", "temperature_c": "temp"}
    for axis in "xyz":
        options = ReadOptions(columns=columns, units={"time": "ms", "rate": "rad/s",
                                                      "temp": "count"},
                              temp_scale=0.00582219, temp_offset_c=24.1839, gaps="split",
                              thermometer="sensor", axis=axis)
        temperature, rate = ChannelShape(), ChannelShape()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for chunk in options.chunks(pan):
                temperature.partial_fit(chunk.freq_hz)
                rate.partial_fit(chunk.rate_dph)
        check_sensor_swap(temperature, rate, "pan.csv", "temp", f"rate_dph_{axis}")
        with pytest.raises(InputError, match="look swapped"):
            check_sensor_swap(rate, temperature, "pan.csv", "temp", f"rate_dph_{axis}")


def test_a_chamber_set_point_taken_for_the_thermometer_is_refused(tmp_path):
    """Issue 27's audit: chamber_c and temperature_c swapped were fitted without a word
    by calibrate --thermometer sensor (the set-point runs ahead of the gyro)."""
    from hrgtc.drift.training import check_setpoint_thermometer, is_setpoint_ramp
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.recording import ReadOptions, Recording, write

    from corruptions import base_run

    run = base_run("1")
    assert is_setpoint_ramp(run["chamber_c"]) and not is_setpoint_ramp(run["temperature_c"])
    # a measured temperature at 0.01 °C resolution, steady or moving, is no set-point
    rng = np.random.default_rng(2)
    slow = np.round(20.0 + np.cumsum(rng.normal(0.0, 0.002, 5000)), 2)
    assert not is_setpoint_ramp(slow)
    assert not is_setpoint_ramp(np.round(np.linspace(20.0, 30.0, 5000), 2))
    check_setpoint_thermometer(run["temperature_c"], run["chamber_c"])  # as logged: fine
    columns = {k: np.array(run[k]) for k in run.names}
    columns["chamber_c"], columns["temperature_c"] = columns["temperature_c"], columns["chamber_c"]
    path = write(Recording(columns, run.metadata), tmp_path / "swapped.csv")
    with pytest.raises(InputError, match=r"swapped.csv: the headers chamber_c and temperature_c "
                                         r"look swapped: .*noise-free straight ramps.*"
                                         r"--col temperature_c=chamber_c"):
        calibrate([], [path], read_options=ReadOptions(thermometer="sensor"))
