"""A run that compensation made worse than raw is said, with its shares beyond the trained
ranges; a difference inside the two figures' intervals is not (a real case: the CATS tag's
held-out fridge part, axis x, 245.7 against 200 °/h, in docs/real-loggers/corpus.md)."""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import pytest

from hrgtc.core.errors import CompensationWarning
from hrgtc.evaluation.run_evaluation import warn_worse_than_raw, worse_than_raw


def _evaluation(raw, compensated, raw_bounds, bounds, beyond=0.0, rate_beyond=0.0):
    figures = {"raw": (raw, raw_bounds), "compensated": (compensated, bounds)}
    return SimpleNamespace(
        file="run.csv", out_of_range_fraction=beyond, rate_out_of_range_fraction=rate_beyond,
        stability=lambda series, tau_s: figures[series][0],
        stability_interval=lambda series, tau_s: figures[series][1])


def test_worse_beyond_the_intervals_is_said_with_the_shares_beyond_the_ranges():
    said = worse_than_raw(_evaluation(200.0, 245.7, (198.0, 202.0), (243.0, 248.0),
                                      beyond=0.39, rate_beyond=0.0001), "x")
    assert said.startswith("run.csv, axis x: compensated, the 10 s bias stability is worse "
                           "than raw (245.7 against 200 °/h")
    assert "39.0% of it lies beyond the trained temperatures" in said
    assert "df/dt" not in said  # 0.01 %: 0.0 % printed would say nothing


@pytest.mark.parametrize(("compensated", "bounds", "said"), [
    (2.10, (2.00, 2.20), False),   # the lower bound at the raw upper bound: not apart
    (2.10, (2.0001, 2.20), True),  # just apart
    (1.90, (1.80, 2.00), False),   # better than raw
    (1.00, None, False),           # better, no interval
    (2.50, None, True),            # worse, no interval to judge by: said
])
def test_only_a_difference_beyond_both_intervals_is_said(compensated, bounds, said):
    evaluation = _evaluation(1.90, compensated, (1.80, 2.00), bounds)
    assert (worse_than_raw(evaluation) is not None) is said


def test_each_axis_made_worse_gets_its_warning():
    result = SimpleNamespace(axes={
        "x": _evaluation(1.0, 3.0, (0.9, 1.1), (2.8, 3.2)),
        "y": _evaluation(1.0, 0.5, (0.9, 1.1), (0.4, 0.6)),
        "z": _evaluation(1.0, 2.0, (0.9, 1.1), (1.8, 2.2))})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warn_worse_than_raw(result)
    assert [w.category for w in caught] == [CompensationWarning] * 2
    assert ["axis x" in str(caught[0].message), "axis z" in str(caught[1].message)] == [True] * 2
