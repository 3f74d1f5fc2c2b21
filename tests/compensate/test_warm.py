"""The fused kernel loaded ahead (``AxisCompensator.warm``) for the types the real call uses."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.compensate import _kernel as kernel
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Metadata, Recording

from synthetic import THERMOMETER, ramp_run


@pytest.fixture(scope="module")
def paper_model():
    return Model.single(
        AxisModel(THERMOMETER, drift.fit([ramp_run(seed=21, hours=3.0)], THERMOMETER)))


def _chunk(model, rows: int, readonly: bool) -> Recording:
    rate_hz = model.drift.settings.sample_rate_hz
    columns = {"time_s": np.arange(rows) / rate_hz,
               "freq_hz": np.full(rows, model.thermometer.frequency(20.0)),
               "rate_dph": np.zeros(rows), "housing_c": np.full(rows, 20.0)}
    for values in columns.values():
        values.flags.writeable = not readonly  # a reader's zero-copy columns are read-only
    return Recording(columns, Metadata(sample_rate_hz=rate_hz))


@pytest.mark.parametrize("readonly", [False, True])
def test_warm_loads_the_signatures_the_real_call_uses_and_compensates_nothing(
        paper_model, readonly):
    chunk = _chunk(paper_model, kernel.PARALLEL_ROWS + 10, readonly)
    warmed = Compensator(paper_model)
    warmed.warm(chunk)
    loaded = (set(kernel.compensate_block.signatures), set(kernel.advance_filter.signatures))
    assert warmed.samples == 0  # nothing compensated, no state kept
    result = warmed.transform(chunk)
    # the real call (two halves on two threads: advance_filter too) added no signature
    assert (set(kernel.compensate_block.signatures),
            set(kernel.advance_filter.signatures)) == loaded
    again = Compensator(paper_model).transform(chunk)
    for name in ("rate_comp_dph", "bias_model_dph", "in_range"):
        assert np.array_equal(result[name], again[name])
