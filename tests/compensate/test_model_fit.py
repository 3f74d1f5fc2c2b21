"""Tests of hrgtc.compensate.model_fit.check_recording_noise: a unit factor on any axis is
refused naming the file and the column, whether the model is one unit's or an instrument's.

Written for mutants that no test of the compensate package killed (make mutation, issue 21;
the commands' tests in tests/cli exercise it too). Truth: the model's own training run, its
rate scaled by the °/h -> °/s factor 3600, and swapped rate/temperature columns.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.compensate.model_fit import check_recording_noise
from hrgtc.core.errors import InputError
from hrgtc.model import InstrumentModel
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
    check_recording_noise(InstrumentModel({a: model for a in "xy"}, unit="FZ-3"),
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
    instrument = InstrumentModel({a: model for a in "xy"}, unit="FZ-3")
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
    import dataclasses

    run = make_run()
    rng = np.random.default_rng(3)
    quiet_rate = 10.0 + rng.normal(0.0, 0.1, len(run))  # 1/20 the noise: no unit factor
    housing_c = 20.0 + np.cumsum(rng.normal(0.0, 1e-4, len(run)))
    check_recording_noise(model, _swapped(run, quiet_rate, housing_c), "run.csv")
    bare = dataclasses.replace(model, training=None)  # a model written before the statistics
    check_recording_noise(bare, _swapped(run, housing_c, run.rate_dph), "run.csv")


def test_swapped_headers_on_an_axis_of_an_instrument_are_named(model):
    run = make_run()
    housing_c = 20.0 + np.cumsum(np.random.default_rng(2).normal(0.0, 1e-4, len(run)))
    three = _three_axis(run, {})
    columns = {n: three[n] for n in three.names}
    columns["rate_dph_y"], columns["housing_c"] = housing_c, run.rate_dph
    instrument = InstrumentModel({a: model for a in "xyz"}, unit="FZ-3")
    with pytest.raises(InputError, match=r"the headers rate_dph_y and housing_c look swapped"):
        check_recording_noise(instrument, Recording(columns, run.metadata), "run.csv")
