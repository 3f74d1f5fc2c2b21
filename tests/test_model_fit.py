"""Tests of hrgtc.model_fit.check_recording_noise: a unit factor on any axis is
refused naming the file and the column, whether the model is one unit's or an instrument's.

Written for mutants that no test of the compensate package killed (make mutation, issue 21;
the commands' tests in tests/cli exercise it too). Truth: the model's own training run, its
rate scaled by the °/h -> °/s factor 3600, and swapped rate/temperature columns.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.model import Model
from hrgtc.model_fit import check_recording_noise
from hrgtc.recording import Metadata, Recording

from fuzzing import make_model, make_run


@pytest.fixture(scope="module")
def model():
    return make_model()


def _three_axis(run: Recording, factors: dict[str, float]) -> Recording:
    columns = {"time_s": run.time_s}
    for axis in "xyz":
        columns[f"freq_hz_{axis}"] = run.freq_hz
        columns[f"rate_dph_{axis}"] = run.rate_dph * factors.get(axis, 1.0)
    return Recording(columns, run.metadata)


def test_a_recording_in_the_training_unit_passes(model):
    run = make_run()
    check_recording_noise(model, run, "run.csv")
    check_recording_noise(Model({a: model.axis for a in "xy"}, unit="FZ-3"),
                          _three_axis(run, {}), "run.csv")


def test_a_unit_factor_on_a_single_axis_recording_names_the_file_and_column(model):
    run = make_run()
    scaled = Recording({**{n: run[n] for n in run.names}, "rate_dph": run.rate_dph * 3600.0},
                       run.metadata)
    with pytest.raises(InputError, match=r"^run\.csv: column 'rate_dph': its noise"):
        check_recording_noise(model, scaled, "run.csv")
    with pytest.raises(InputError, match=r"^run\.csv: column 'rate_dph_z': its noise"):
        check_recording_noise(model, scaled, "run.csv", axis="z")  # an axis view of z


@pytest.mark.parametrize("axis", ["x", "y"])
def test_a_unit_factor_on_one_axis_of_an_instrument_names_that_axis(model, axis):
    instrument = Model({a: model.axis for a in "xy"}, unit="FZ-3")
    run = _three_axis(make_run(), {axis: 3600.0, "z": 3600.0})  # z: not in the model
    with pytest.raises(InputError, match=rf"^run\.csv: column 'rate_dph_{axis}': its noise"):
        check_recording_noise(instrument, run, "run.csv")


def test_swapped_rate_and_temperature_headers_are_named(model):
    run = make_run()
    rng = np.random.default_rng(2)
    housing_c = 20.0 + np.cumsum(rng.normal(0.0, 1e-4, len(run)))  # a temperature's noise
    swapped = Recording({"time_s": run.time_s, "freq_hz": run.freq_hz, "rate_dph": housing_c,
                         "housing_c": run.rate_dph}, Metadata(sample_rate_hz=10.0))
    with pytest.raises(InputError, match=r"^run\.csv: the headers rate_dph and housing_c "
                                         r"look swapped"):
        check_recording_noise(model, swapped, "run.csv")


def _swapped(run: Recording, rate_dph: np.ndarray, housing_c: np.ndarray) -> Recording:
    return Recording({"time_s": run.time_s, "freq_hz": run.freq_hz, "rate_dph": rate_dph,
                      "housing_c": housing_c}, Metadata(sample_rate_hz=10.0))


def test_the_swapped_headers_message_names_both_columns_their_noise_and_the_fix(model):
    import re

    run = make_run()
    housing_c = 20.0 + np.cumsum(np.random.default_rng(2).normal(0.0, 1e-4, len(run)))
    with pytest.raises(InputError) as caught:
        check_recording_noise(model, _swapped(run, housing_c, run.rate_dph), "run.csv")
    assert re.fullmatch(
        r"run\.csv: the headers rate_dph and housing_c look swapped: column 'rate_dph' has "
        r"[0-9.e-]+× the noise of the model's training rate \(a temperature's, not a gyro's\) "
        r"and column 'housing_c' [0-9.]+× \(the rate's\); fix the header line of the file, "
        r"or map the columns with --col rate_dph=housing_c --col housing_c=rate_dph",
        str(caught.value))
    constant = np.full(len(run), 10.0)  # a constant (or quantised) column: no noise at all
    with pytest.raises(InputError, match=r"column 'rate_dph' has none of the noise"):
        check_recording_noise(model, _swapped(run, constant, run.rate_dph), "run.csv")


def test_a_quiet_rate_alone_or_a_model_without_statistics_is_not_refused(model):

    run = make_run()
    rng = np.random.default_rng(3)
    quiet_rate = 10.0 + rng.normal(0.0, 0.1, len(run))  # 1/20 the noise: no unit factor
    housing_c = 20.0 + np.cumsum(rng.normal(0.0, 1e-4, len(run)))
    check_recording_noise(model, _swapped(run, quiet_rate, housing_c), "run.csv")
    bare = model.with_parts(training=None)  # a model written before the statistics
    check_recording_noise(bare, _swapped(run, housing_c, run.rate_dph), "run.csv")


def test_swapped_headers_on_an_axis_of_an_instrument_are_named(model):
    run = make_run()
    housing_c = 20.0 + np.cumsum(np.random.default_rng(2).normal(0.0, 1e-4, len(run)))
    three = _three_axis(run, {})
    columns = {n: three[n] for n in three.names}
    columns["rate_dph_y"], columns["housing_c"] = housing_c, run.rate_dph
    instrument = Model({a: model.axis for a in "xyz"}, unit="FZ-3")
    with pytest.raises(InputError, match=r"the headers rate_dph_y and housing_c look swapped"):
        check_recording_noise(instrument, Recording(columns, run.metadata), "run.csv")


# -- the calibrated span, the plausible band, the thermometer's kind --------------------------
def test_the_calibrated_span_covers_the_thermometer_and_the_trained_f(model):
    import dataclasses

    from hrgtc.model_fit import frequency_span

    thermometer_span = model.thermometer.frequency_range_hz
    assert frequency_span(model) == thermometer_span  # the training stayed inside
    reference = model.drift.settings.reference_freq_hz
    wider = dataclasses.replace(model.drift, ranges={**model.drift.ranges, "f": (-20.0, 20.0)})
    assert frequency_span(model.with_parts(drift=wider)) == (
        reference - 20.0, reference + 20.0)
    no_f = dataclasses.replace(model.drift, ranges={k: v for k, v in model.drift.ranges.items()
                                                    if k != "f"})
    assert frequency_span(model.with_parts(drift=no_f)) == thermometer_span


def test_the_plausible_band_is_the_span_widened_by_100_c_at_the_steepest_slope(model):
    from hrgtc.model_fit import plausible_frequency_band

    thermometer = model.thermometer
    low, high = thermometer.frequency_range_hz
    t_low, t_high = thermometer.temperature_range_c
    h = 1e-3  # slope by central differences of f(T), not the thermometer's own slope
    slopes = [abs(float(thermometer.frequency(t + h) - thermometer.frequency(t - h))) / (2 * h)
              for t in (t_low, t_high)]
    margin = 100.0 * max(slopes)
    band = plausible_frequency_band(model)
    assert band == pytest.approx((low - margin, high + margin), rel=1e-9)
    assert plausible_frequency_band(model, margin_c=10.0) == pytest.approx(
        (low - margin / 10.0, high + margin / 10.0), rel=1e-9)


def test_a_model_of_the_other_thermometer_kind_is_refused_naming_the_file_and_option(model):
    import dataclasses

    from hrgtc.model_fit import check_thermometer_kind, with_model_band
    from hrgtc.recording.io import ReadOptions

    resonator, sensor = ReadOptions(), ReadOptions(thermometer="sensor")
    check_thermometer_kind(resonator, model)
    with pytest.raises(InputError) as caught:
        check_thermometer_kind(sensor, model, "m.json")
    assert str(caught.value) == (
        "m.json: the model of unit 'FZ-1' is a resonator-thermometer model (its thermometer "
        "turns the resonator frequency into temperature), but the recording is read with "
        "--thermometer sensor (a temperature sensor in the place of freq_hz); drop "
        "--thermometer sensor for this model, or calibrate one with --thermometer sensor")
    sensor_model = model.with_parts(
        thermometer=dataclasses.replace(model.thermometer, source="sensor"))
    check_thermometer_kind(sensor, sensor_model)
    with pytest.raises(InputError) as caught:
        check_thermometer_kind(resonator, sensor_model)
    assert str(caught.value) == (
        "the model of unit 'FZ-1' is a sensor-thermometer model (calibrated with "
        "--thermometer sensor on the gyro's temperature sensor, -20 to 40 °C), but the "
        "recording is read as a resonator frequency (freq_hz); pass --thermometer sensor (and "
        "--col temperature_c=... for the sensor's column), or use a model calibrated on the "
        "resonator frequency")
    with pytest.raises(InputError, match="is a resonator-thermometer model"):
        with_model_band(sensor, model)
    banded = with_model_band(resonator, model)
    assert banded.freq_span_hz == model.thermometer.frequency_range_hz
    assert banded.freq_band_hz[0] < banded.freq_span_hz[0]


def test_the_noise_check_skips_axes_the_recording_lacks_and_checks_the_others(model):
    instrument = Model({a: model.axis for a in "xyz"}, unit="FZ-3")
    three = _three_axis(make_run(), {"z": 3600.0})
    yz = Recording({n: three[n] for n in three.names if not n.endswith("_x")}, three.metadata)
    with pytest.raises(InputError, match=r"column 'rate_dph_z': its noise"):
        check_recording_noise(instrument, yz, "run.csv")  # x missing: z still checked
    y_only = Recording({n: three[n] for n in three.names if not n.endswith(("_x", "_z"))},
                       three.metadata)
    check_recording_noise(instrument, y_only, "run.csv")  # left to the compensator's error
    run = make_run()
    scaled = Recording({**{n: run[n] for n in run.names}, "rate_dph": run.rate_dph * 3600.0},
                       run.metadata)
    check_recording_noise(instrument, scaled, "run.csv")  # single-axis file: likewise


def test_swapped_headers_without_a_file_name_and_at_other_noise_levels(model):
    import dataclasses

    run = make_run()
    housing_c = 20.0 + np.cumsum(np.random.default_rng(2).normal(0.0, 1e-4, len(run)))
    with pytest.raises(InputError, match=r"^the headers rate_dph and housing_c look swapped"):
        check_recording_noise(model, _swapped(run, housing_c, run.rate_dph))
    # the other column at half the rate's noise still has "the rate's" noise (within 2.5×)
    with pytest.raises(InputError, match=r"column 'housing_c' 0\.4\d\d× \(the rate's\)"):
        check_recording_noise(model, _swapped(run, housing_c, 0.5 * run.rate_dph), "run.csv")
    # a constant rate column of an axis view: named by the file's axis
    constant = np.full(len(run), 10.0)
    with pytest.raises(InputError, match=r"headers rate_dph_z and housing_c look swapped"):
        check_recording_noise(model, _swapped(run, constant, run.rate_dph), "run.csv", axis="z")
    # a quiet gyro (0.5 °/h of training noise, below 1 °/h) is checked all the same
    quiet = model.with_parts(training=dataclasses.replace(
        model.training, rate_noise_dph=model.training.rate_noise_dph / 4.0))
    with pytest.raises(InputError, match=r"look swapped"):
        check_recording_noise(quiet, _swapped(run, housing_c / 10.0, 0.25 * run.rate_dph),
                              "run.csv")


def test_a_rate_at_a_seventh_of_the_training_noise_is_not_a_temperature(model):
    run = make_run()
    rng = np.random.default_rng(4)
    rate = 10.0 + rng.normal(0.0, 2.0 / 7.0, len(run))  # 1/7 of the noise: not 10× quieter
    with_noise = Recording({"time_s": run.time_s, "freq_hz": run.freq_hz, "rate_dph": rate,
                            "housing_c": run.rate_dph}, Metadata(sample_rate_hz=10.0))
    check_recording_noise(model, with_noise, "run.csv")
