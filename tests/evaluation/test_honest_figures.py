"""Mean and RMS beside bias stability, and samples not at rest left out of the figures."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.drift.features import settle_rows
from hrgtc.evaluation import evaluate
from hrgtc.model import AxisModel, Model
from hrgtc.recording import ReadOptions, Recording
from hrgtc.settings.compensation import BIAS_ONLY

from synthetic import THERMOMETER, ramp_run


@pytest.fixture(scope="module")
def model():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted = drift.fit([ramp_run(seed=1)], THERMOMETER)
    return Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted), unit="synthetic")


def test_a_constant_offset_shows_in_the_mean_not_in_the_bias_stability(model):
    run = ramp_run(seed=2)
    shifted = Recording({**run.columns, "rate_dph": run.rate_dph + 136.0}, run.metadata,
                        run.source)
    plain = evaluate(model, run, settings=BIAS_ONLY).axis
    moved = evaluate(model, shifted, settings=BIAS_ONLY).axis
    assert moved.compensated_10s == pytest.approx(plain.compensated_10s, rel=1e-9)
    assert moved.mean_dph["compensated"] - plain.mean_dph["compensated"] == \
        pytest.approx(136.0, rel=1e-9)
    # the figures are those of the compensated output after the filter settles, by numpy
    out = Compensator(model).transform(shifted)
    comp = (out["rate_comp_dph"] - run.metadata.input_rate_dph)[settle_rows(model.drift.settings):]
    assert moved.mean_dph["compensated"] == pytest.approx(float(np.mean(comp)), rel=1e-9)
    assert moved.rms_dph["compensated"] == pytest.approx(float(np.sqrt(np.mean(comp ** 2))),
                                                         rel=1e-9)
    assert moved.rms_dph["compensated"] > 136.0 > 10 * moved.compensated_10s
    data = moved.to_dict()
    assert data["mean_dph"]["compensated"] == pytest.approx(moved.mean_dph["compensated"])
    assert "compensated (frequency, Eq. 22) mean: 136" in moved.summary().text()


def test_handling_is_left_out_of_the_figures_and_counted(model):
    run = ramp_run(seed=3)
    rate = run.rate_dph.copy()
    t = run.time_s
    handled = np.zeros(t.size, dtype=bool)
    for start in (4000.0, 9000.0, 14000.0):
        inside = (t >= start) & (t < start + 20.0)
        rate[inside] += 3600.0 * 200.0 * np.sin(np.linspace(0, 2 * np.pi, inside.sum()))
        handled |= inside
    moved = Recording({**run.columns, "rate_dph": rate}, run.metadata, run.source)
    clean = evaluate(model, run, settings=BIAS_ONLY).axis
    excluded = evaluate(model, moved, settings=BIAS_ONLY).axis
    kept = evaluate(model, moved, settings=BIAS_ONLY, read_options=ReadOptions(motion="keep")).axis
    assert handled.sum() <= excluded.n_not_at_rest <= handled.sum() + 3 * 10 * (6 + 2 * 3.2)
    assert kept.n_not_at_rest == 0
    assert excluded.compensated_10s == pytest.approx(clean.compensated_10s, rel=0.1)
    assert kept.compensated_10s > 100 * clean.compensated_10s
    assert "not at rest" in excluded.summary().text()
