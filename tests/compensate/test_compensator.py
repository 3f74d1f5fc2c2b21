"""Tests of hrgtc.compensate: batch and streaming compensation agree."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc import drift
from hrgtc.compensate import Compensator, compensate
from hrgtc.errors import InputError
from hrgtc.model import UnitModel
from hrgtc.recording import concatenate

from synthetic import THERMOMETER, ramp_run


@pytest.fixture(scope="module")
def unit_model():
    return UnitModel(THERMOMETER, drift.fit([ramp_run(seed=21, hours=3.0)], THERMOMETER))


@pytest.fixture(scope="module")
def run():
    return ramp_run(seed=22, start_c=-15.0, end_c=15.0, hours=1.0)


@settings(max_examples=25, deadline=None)
@given(cuts=st.lists(st.integers(1, 35_999), min_size=1, max_size=8, unique=True))
def test_any_chunking_equals_batch(unit_model, run, cuts):
    batch = compensate(run, unit_model)
    compensator = Compensator(unit_model)
    bounds = [0, *sorted(cuts), len(run)]
    parts = [compensator.process(run.slice(a, b)) for a, b in itertools.pairwise(bounds)]
    streamed = concatenate(parts)
    for name in ("rate_comp_dph", "bias_model_dph", "resonator_c_est", "in_range"):
        np.testing.assert_allclose(streamed[name], batch[name], rtol=0, atol=1e-12)


def test_compensated_is_raw_minus_model(unit_model, run):
    out = compensate(run, unit_model)
    np.testing.assert_array_equal(out["rate_comp_dph"], run.rate_dph - out["bias_model_dph"])
    # frequency noise 2 mHz at 0.37 Hz/°C is 0.0054 °C per sample: 6 sigma
    np.testing.assert_allclose(out["resonator_c_est"], run["resonator_c"], atol=0.033)
    np.testing.assert_array_equal(out["bias_model_dph"], unit_model.drift.predict_recording(run))


def test_out_of_range_samples_are_counted(unit_model):
    hot = ramp_run(seed=23, start_c=20.0, end_c=60.0, hours=1.0)
    compensator = Compensator(unit_model)
    out = compensator.process(hot)
    assert compensator.out_of_range_fraction == pytest.approx(1 - out["in_range"].mean())
    assert compensator.out_of_range_fraction > 0.2


def test_housing_baseline_missing_is_a_clear_error(unit_model):
    with pytest.raises(InputError, match="no housing-thermistor baseline"):
        Compensator(unit_model, drift="housing")
