"""A NaN temperature estimate (beyond the thermometer's calibrated span) is warned about once.

Truth: a warm-up from 95 to 140 °C against a thermometer calibrated to 40 °C; the inverse of
f(T) is extrapolated only to 100 °C, so the estimate is NaN beyond, and the compensator must
say so once per run (not once per chunk or per engine block) and count the samples.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.core.errors import ExtrapolationWarning
from hrgtc.model import AxisModel, Model

from synthetic import THERMOMETER, ramp_run


@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_nan_temperature_estimate_warns_once_and_is_counted(engine):
    model = Model.single(
        AxisModel(THERMOMETER, drift.fit([ramp_run(seed=21, hours=3.0)], THERMOMETER)))
    hot = ramp_run(seed=23, start_c=95.0, end_c=140.0, hours=1.0, ramp_hours=0.3)  # > 100 °C
    compensator = Compensator(model, engine=engine)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        parts = [compensator.transform(hot.slice(a, a + 9000)) for a in range(0, len(hot), 9000)]
    estimate = np.concatenate([p["resonator_c_est"] for p in parts])
    nan = np.isnan(estimate)
    assert nan.any() and compensator.axis.temperature_nan == int(nan.sum())
    said = [w for w in caught if issubclass(w.category, ExtrapolationWarning)
            and "is NaN from sample" in str(w.message)]
    assert len(said) == 1
    assert f"from sample {int(np.argmax(nan))} " in str(said[0].message)
