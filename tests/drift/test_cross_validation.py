"""Tests of hrgtc.drift.cross_validation: leave-one-run-out residuals and selection by them."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.core.errors import InputError
from hrgtc.drift.cross_validation import (
    CrossValidation,
    Windowed,
    cross_validate,
    select_terms,
)
from hrgtc.drift.stepwise import stepwise

from synthetic import THERMOMETER, ramp_run

NAMES = ("a", "b", "c")


def _runs(seed=41, n=300, runs=4):
    rng = np.random.default_rng(seed)
    run = np.repeat(np.arange(runs), n)
    x = rng.normal(size=(run.size, 3))
    y = 1.0 + 2.0 * x[:, 0] - 0.5 * x[:, 1] + rng.normal(0.0, 0.1, run.size)
    rate = np.where(np.arange(run.size) % 2 == 0, 1.0, -1.0)  # heating, cooling alternately
    return x, y, run, rate


def test_cross_validation_equals_refits_by_hand():
    x, y, run, rate = _runs()
    sources = tuple(f"run{r}" for r in range(4))
    cv = cross_validate(x, y, run, NAMES, ("a", "b"), sources, rate)
    held = np.empty(y.size)
    for r in range(4):
        test = run == r
        design = np.column_stack([np.ones(y.size), x[:, :2]])
        beta = np.linalg.lstsq(design[~test], y[~test], rcond=None)[0]
        held[test] = y[test] - design[test] @ beta
        assert cv.per_run_dph[f"run{r}"] == pytest.approx(np.std(held[test], ddof=1), rel=1e-12)
    assert cv.heating_dph == pytest.approx(np.std(held[rate > 0], ddof=1), rel=1e-12)
    assert cv.cooling_dph == pytest.approx(np.std(held[rate < 0], ddof=1), rel=1e-12)
    values = np.array(list(cv.per_run_dph.values()))
    assert cv.score_dph == pytest.approx(np.sqrt(np.mean(values ** 2)))
    again = CrossValidation.from_dict(json.loads(json.dumps(cv.to_dict())))
    assert again.per_run_dph == cv.per_run_dph and again.score_dph == cv.score_dph


def test_selection_by_cross_validation_finds_the_law():
    x, y, run, rate = _runs(seed=42)
    runs = ("r0", "r1", "r2", "r3")
    assert select_terms(Windowed(x, y, run, NAMES, runs, rate)) == ("a", "b")
    # a slope that only run 0 shows does not carry over to the others: the F-test keeps
    # it (in-sample), cross-validation does not
    y2 = y + np.where(run == 0, 3.0 * x[:, 2], 0.0)
    assert "c" in stepwise(x, y2, names=NAMES).selected
    assert "c" not in select_terms(Windowed(x, y2, run, NAMES, runs, rate),
                                   initial=("a", "b", "c"))


def test_drift_fit_reports_cross_validation_per_run():
    cool = ramp_run(seed=43, hours=3.0)
    warm = ramp_run(seed=44, start_c=-20.0, end_c=20.0, hours=3.0)
    model = drift.fit([cool, warm], THERMOMETER)
    cv = model.cross_validation
    assert cv is not None and len(cv.per_run_dph) == 2
    assert all(np.isfinite(v) and v > 0 for v in cv.per_run_dph.values())
    assert np.isfinite(cv.heating_dph) and np.isfinite(cv.cooling_dph)
    assert "cross-validation" in model.summary().text()
    by_cv = drift.fit([cool, warm], THERMOMETER, select="cv")
    assert by_cv.selection == "cv" and by_cv.selected
    assert by_cv.cross_validation.score_dph <= cv.score_dph  # never worse than stepwise
    restored = drift.DriftModel.from_dict(json.loads(json.dumps(by_cv.to_dict())))
    assert restored.cross_validation.per_run_dph == by_cv.cross_validation.per_run_dph
    with pytest.raises(InputError, match="two training runs"):
        drift.fit([cool], THERMOMETER, select="cv")
    with pytest.raises(InputError, match="select must be"):
        drift.fit([cool, warm], THERMOMETER, select="lasso")


def test_folds_of_one_run_are_its_coldest_and_hottest_time_blocks():
    from hrgtc.drift.cross_validation import EXTREME_BLOCKS, folds_of

    time_s = np.arange(20) * 60.0
    ramp = np.linspace(25.0, 5.0, 20)  # a cool-down: the first block is the hottest
    folds, kind = folds_of(np.zeros(20, dtype=int), time_s, ramp, blocks=5)
    assert kind == EXTREME_BLOCKS
    assert folds.tolist() == [1] * 4 + [-1] * 12 + [0] * 4
    cycle = 15.0 + 10.0 * np.cos(2.0 * np.pi * time_s / time_s[-1])  # coldest in the middle
    folds, _ = folds_of(np.zeros(20, dtype=int), time_s, cycle, blocks=5)
    assert set(np.flatnonzero(folds == 0)) == {8, 9, 10, 11}
    assert set(np.flatnonzero(folds == 1)) in ({0, 1, 2, 3}, {16, 17, 18, 19})
    # a missing burst (a gap in the window times) is where a block ends
    gapped = np.r_[np.arange(7), np.arange(12, 25)] * 60.0
    folds, _ = folds_of(np.zeros(20, dtype=int), gapped, ramp, blocks=2)
    assert folds.tolist() == [1] * 7 + [0] * 13
    runs = np.repeat([0, 1], 10)
    assert folds_of(runs, time_s, ramp)[1] == "runs"


def test_pruning_follows_the_path_past_a_rise_to_the_model_that_generalises():
    from hrgtc.drift.cross_validation import held_out_rms, prune_terms

    # truth: a line in f plus a random walk (a gyro's slow noise), which the cubic and
    # the square fit in the middle of the run; predicting the end blocks, f, f², f³ is
    # worse than f alone, and f, f² worse still: a stop at the first rise keeps all three
    n = 60
    f = np.linspace(-1.0, 1.0, n)
    x = np.column_stack([f, f**2, f**3])
    y = f + np.cumsum(np.random.default_rng(1).normal(0.0, 0.05, n))
    folds = np.full(n, -1)
    folds[:12], folds[-12:] = 1, 0
    names = ("f", "f^2", "f^3")
    parents = {"f^3": ["f^2"], "f^2": ["f"]}
    scores = {t: held_out_rms(x, y, folds, names, t) for t in [("f",), ("f", "f^2"), names]}
    assert scores[("f", "f^2")] > scores[names] > 2.0 * scores[("f",)]
    assert prune_terms(x, y, folds, names, names, parents=parents)[0] == names
    kept, before, after = prune_terms(x, y, folds, names, names, parents=parents, through=True)
    assert kept == ("f",) and after == pytest.approx(scores[("f",)]) and after < before
