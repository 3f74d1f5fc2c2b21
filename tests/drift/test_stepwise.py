"""Tests of hrgtc.drift.stepwise: OLS and stepwise regression on sufficient statistics.

Truth comes from statsmodels (a second, QR/pinv-based implementation), NIST's
certified values for Longley, an exact rational solution, and the published
Hald cement stepwise example.
"""

from __future__ import annotations

import json
from fractions import Fraction

import numpy as np
import pytest
import statsmodels.api as sm
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from hrgtc.core.errors import InputError, RankDeficientError
from hrgtc.drift.regression import newey_west_inflation
from hrgtc.drift.stepwise import (
    GramAccumulator,
    OLSResult,
    StepwiseResult,
    StepwiseRules,
    ols,
    ols_from_accumulator,
    stepwise,
    stepwise_from_accumulator,
)

# Hald (1952) cement data, as tabulated in Draper & Smith, Applied Regression
# Analysis, 3rd ed. (1998), and shipped as MATLAB's `hald` data set:
# x1 tricalcium aluminate, x2 tricalcium silicate, x3 tetracalcium alumino ferrite,
# x4 dicalcium silicate [% weight]; heat evolved after 180 days [cal/g].
HALD = np.array([
    [7, 26, 6, 60, 78.5],
    [1, 29, 15, 52, 74.3],
    [11, 56, 8, 20, 104.3],
    [11, 31, 8, 47, 87.6],
    [7, 52, 6, 33, 95.9],
    [11, 55, 9, 22, 109.2],
    [3, 71, 17, 6, 102.7],
    [1, 31, 22, 44, 72.5],
    [2, 54, 18, 22, 93.1],
    [21, 47, 4, 26, 115.9],
    [1, 40, 23, 34, 83.8],
    [11, 66, 9, 12, 113.3],
    [10, 68, 8, 12, 109.4],
])


def _random_problem(seed: int, n: int = 200):
    """Columns of very different scales and offsets, moderate p-values."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, 4)) * [1.0, 10.0, 1e3, 0.1] + [0.0, 5.0, 1e4, -3.0]
    X[:, 1] += 3.0 * X[:, 0]  # correlated columns
    y = 1.0 + X @ [0.2, 0.02, 1e-4, 1.0] + rng.normal(size=n) * 1.5
    return X, y


# ----------------------------------------------------------------------------- OLS
@pytest.mark.parametrize("seed", [0, 1])
def test_ols_matches_statsmodels(seed):
    X, y = _random_problem(seed)
    ours = ols(X, y, names=["a", "b", "c", "d"])
    ref = sm.OLS(y, sm.add_constant(X)).fit()
    assert 1e-4 < ref.pvalues.min() and ref.pvalues.max() < 0.95  # relative test is meaningful
    assert ours.names == ("const", "a", "b", "c", "d")
    for attr in ("params", "bse", "tvalues", "pvalues"):
        np.testing.assert_allclose(getattr(ours, attr), getattr(ref, attr), rtol=1e-10)
    np.testing.assert_allclose(ours.cov_params, ref.cov_params(), rtol=1e-9)
    assert ours.residual_std == pytest.approx(np.sqrt(ref.scale), rel=1e-12)
    assert ours.rsquared == pytest.approx(ref.rsquared, rel=1e-12)
    assert (ours.nobs, ours.df_resid) == (200, 195)
    np.testing.assert_allclose(ours.predict(X), ref.fittedvalues, rtol=1e-10, atol=1e-10)


def test_weighted_ols_matches_statsmodels_wls():
    X, y = _random_problem(2)
    w = np.random.default_rng(5).uniform(0.1, 3.0, size=len(y))
    ours = ols(X, y, weights=w)
    ref = sm.WLS(y, sm.add_constant(X), weights=w).fit()
    for attr in ("params", "bse", "pvalues"):
        np.testing.assert_allclose(getattr(ours, attr), getattr(ref, attr), rtol=1e-10)


def test_longley_nist_certified_values():
    # NIST StRD Longley, certified values (https://www.itl.nist.gov/div898/strd/lls/data/Longley.shtml)
    from nist_strd_data import LONGLEY_BSE, LONGLEY_PARAMS, LONGLEY_RESIDUAL_SD, LONGLEY_RSQUARED

    data = sm.datasets.longley.load()
    result = ols(np.asarray(data.exog, float), np.asarray(data.endog, float))
    np.testing.assert_allclose(result.params, LONGLEY_PARAMS, rtol=1e-9)  # NIST asks >= 7
    np.testing.assert_allclose(result.bse, LONGLEY_BSE, rtol=1e-9)
    assert result.residual_std == pytest.approx(LONGLEY_RESIDUAL_SD, rel=1e-10)
    assert result.rsquared == pytest.approx(LONGLEY_RSQUARED, rel=1e-12)


def _exact_least_squares(X: np.ndarray, y: np.ndarray) -> list[Fraction]:
    """Normal equations with a constant, solved in exact rational arithmetic."""
    rows = [[Fraction(1), *(Fraction(float(v)) for v in r)] for r in X]
    ys = [Fraction(float(v)) for v in y]
    k = len(rows[0])
    a = [[sum(r[i] * r[j] for r in rows) for j in range(k)] + [sum(r[i] * t for r, t in
                                                                  zip(rows, ys, strict=True))]
         for i in range(k)]
    for c in range(k):  # Gauss-Jordan, exact
        piv = next(r for r in range(c, k) if a[r][c] != 0)
        a[c], a[piv] = a[piv], a[c]
        a[c] = [v / a[c][c] for v in a[c]]
        for r in range(k):
            if r != c and a[r][c] != 0:
                a[r] = [vr - a[r][c] * vc for vr, vc in zip(a[r], a[c], strict=True)]
    return [a[i][k] for i in range(k)]


def test_badly_scaled_columns_against_exact_rational_solution():
    rng = np.random.default_rng(7)
    t = np.arange(40.0)
    X = np.column_stack([1e6 + t + rng.normal(0, 0.3, 40),
                         3e6 + 0.05 * t**2 + rng.normal(0, 0.3, 40),
                         -2e6 + 0.5 * np.sin(t)])
    y = 5.0 + 2e-3 * X[:, 0] - 1e-3 * X[:, 1] + 0.1 * X[:, 2] + rng.normal(0, 1e-3, 40)
    exact = np.array([float(v) for v in _exact_least_squares(X, y)])
    ours = ols(X, y)
    np.testing.assert_allclose(ours.params[1:], exact[1:], rtol=1e-9)
    # the intercept is itself ill-conditioned (|slope * mean| ~ 2e5 >> intercept)
    assert abs(ours.params[0] - exact[0]) < 1e-9 * np.abs(exact[1:] * X.mean(0)).sum()
    # the problem is hard: raw normal equations in float64 lose most digits
    A = np.column_stack([np.ones(40), X])
    with np.errstate(all="ignore"):
        raw = np.linalg.solve(A.T @ A, A.T @ y)
    assert np.max(np.abs(raw[1:] / exact[1:] - 1)) > 1e-6


def test_collinear_columns_raise_and_name_terms():
    X, y = _random_problem(3)
    X = np.column_stack([X[:, :3], 2.0 * X[:, 0] - 0.002 * X[:, 2]])
    with pytest.raises(RankDeficientError, match=r"\['a', 'c', 'd'\] are collinear"):
        ols(X, y, names=["a", "b", "c", "d"])


def test_constant_column_raises():
    X, y = _random_problem(4)
    X[:, 2] = 1e6 + 0.1
    with pytest.raises(RankDeficientError, match="column 'x3' is constant"):
        ols(X, y)


@pytest.mark.parametrize(("X", "y", "match"), [
    (np.ones(5), np.ones(5), "must be 2-D"),
    (np.ones((5, 2)), np.ones(4), "one value per row"),
    (np.array([[1.0, 2.0], [np.nan, 1.0], [3.0, 1.0], [4.0, 0.0]]), np.arange(4.0),
     r"column 'x1' has non-finite value nan at row 1"),
    (np.array([[1.0, 2.0], [2.0, 1.0], [3.0, 5.0]]), np.arange(3.0), "need at least 4 rows"),
])
def test_bad_input_raises(X, y, match):
    with pytest.raises(InputError, match=match):
        ols(X, y)


# ----------------------------------------------------------------------------- accumulator
def test_chunked_and_merged_accumulation_equal_one_shot():
    X, y = _random_problem(5, n=1000)
    one = ols(X, y)
    parts = []
    for rows in np.array_split(np.arange(1000), 7):
        parts.append(GramAccumulator().partial_fit(X[rows], y[rows]))
    merged = parts[0]
    for part in parts[1:]:
        merged = merged.merge(part)
    assert parts[0].n_ == len(np.array_split(np.arange(1000), 7)[0])  # inputs untouched
    assert merged.n_ == 1000
    chunked = GramAccumulator()
    for rows in np.array_split(np.arange(1000), 13):
        chunked.partial_fit(X[rows], y[rows])
    for acc in (merged, chunked):
        res = ols_from_accumulator(acc)
        np.testing.assert_allclose(res.params, one.params, rtol=1e-12)
        np.testing.assert_allclose(res.bse, one.bse, rtol=1e-12)
    sub = merged.fit(["x4", "x1"])
    ref = sm.OLS(y, sm.add_constant(X[:, [0, 3]])).fit()
    assert sub.names == ("const", "x1", "x4")
    np.testing.assert_allclose(sub.params, ref.params, rtol=1e-10)
    back = GramAccumulator.from_dict(json.loads(json.dumps(merged.to_dict())))
    np.testing.assert_allclose(back.fit().params, one.params, rtol=1e-12)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(cuts=st.lists(st.integers(0, 300), max_size=6),
       offset=st.sampled_from([0.0, 1e5, -1e8, 1e12]))
def test_any_chunking_equals_one_shot(cuts, offset):
    X, y = _random_problem(6, n=300)
    X = X + offset
    one = ols(X, y)
    acc = GramAccumulator()
    for rows in np.split(np.arange(300), sorted(cuts)):
        acc.partial_fit(X[rows], y[rows])
    res = acc.fit()  # double-double means: merging loses nothing even at offset 1e12
    np.testing.assert_allclose(res.params[1:], one.params[1:], rtol=1e-12)
    np.testing.assert_allclose(res.bse, one.bse, rtol=1e-12)


# ----------------------------------------------------------------------------- stepwise
def test_hald_stepwise_matlab_example():
    # MathWorks documentation, stepwiselm(ingredients, heat, 'PEnter', 0.06) on `hald`:
    # 1. Adding x4, FStat = 22.7985, pValue = 0.000576232
    # 2. Adding x1, FStat = 108.2239, pValue = 1.105281e-06
    # 3. Adding x2, FStat = 5.0259, pValue = 0.051687
    # 4. Removing x4, FStat = 1.8633, pValue = 0.2054
    # final heat ~ 52.5773 + 1.4683 x1 + 0.6623 x2 (Draper & Smith 1998 give the same model).
    res = stepwise(HALD[:, :4], HALD[:, 4], rules=StepwiseRules(penter=0.06))
    assert [(s.action, s.term) for s in res.history] == [
        ("added", "x4"), ("added", "x1"), ("added", "x2"), ("removed", "x4")]
    # (F, p, half a unit of the last printed digit of p)
    published = [(22.7985, 0.000576232, 5e-10), (108.2239, 1.105281e-06, 5e-13),
                 (5.0259, 0.051687, 5e-7), (1.8633, 0.2054, 5e-5)]
    for step, (f, p, tol) in zip(res.history, published, strict=True):
        assert step.fstat == pytest.approx(f, abs=5e-5)
        assert step.pvalue == pytest.approx(p, abs=tol)
    assert res.selected == ("x1", "x2")
    np.testing.assert_allclose(res.result.params, [52.5773, 1.4683, 0.6623], atol=5e-5)
    assert res.premove == 0.10 and res.stop_reason == "converged"


def test_hald_stepwise_default_thresholds():
    # MathWorks documentation, stepwisefit(ingredients, heat) with penter 0.05: x2 would enter
    # with p = 0.0517 > 0.05, so the search stops at x1, x4 ("Final columns included: 1 4",
    # stats.intercept 103.0974, b(1) = 1.4400, b(4) = -0.6140).
    res = stepwise(HALD[:, :4], HALD[:, 4])
    assert [(s.action, s.term) for s in res.history] == [("added", "x4"), ("added", "x1")]
    np.testing.assert_allclose(res.result.params, [103.0974, 1.4400, -0.6140], atol=5e-5)


def test_hald_backward_from_full_model():
    # Draper & Smith (1998), backward elimination on the Hald data: drop x3, then x4.
    res = stepwise(HALD[:, :4], HALD[:, 4], rules=StepwiseRules(initial=["x1", "x2", "x3", "x4"]))
    assert [(s.action, s.term) for s in res.history] == [("removed", "x3"), ("removed", "x4")]
    assert res.selected == ("x1", "x2")
    assert res.history[0].pvalue == pytest.approx(0.8959, abs=1e-4)


def _reference_stepwise(X, y, penter, premove):
    """Naive stepwisefit with a statsmodels refit for every candidate."""
    included: list[int] = []
    history = []
    while True:
        best = None
        for j in (j for j in range(X.shape[1]) if j not in included):
            cols = sorted([*included, j])
            fit = sm.OLS(y, sm.add_constant(X[:, cols])).fit()
            p = fit.pvalues[cols.index(j) + 1]
            if best is None or p < best[1]:
                best = (j, p)
        if best is not None and best[1] < penter:
            included.append(best[0])
            history.append(("added", best[0], best[1]))
            continue
        if not included:
            break
        cols = sorted(included)
        pvalues = sm.OLS(y, sm.add_constant(X[:, cols])).fit().pvalues[1:]
        if pvalues.max() <= premove:
            break
        included.remove(cols[int(np.argmax(pvalues))])
        history.append(("removed", cols[int(np.argmax(pvalues))], pvalues.max()))
    return history


@pytest.mark.parametrize("seed", [10, 11, 12])
def test_stepwise_matches_naive_statsmodels_refits(seed):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(120, 7))
    X[:, 3] = X[:, 1] + 0.3 * rng.normal(size=120)
    y = 0.4 * X[:, 1] + 0.25 * X[:, 3] - 0.3 * X[:, 5] + rng.normal(size=120)
    ours = stepwise(X, y, rules=StepwiseRules(penter=0.05, premove=0.10))
    ref = _reference_stepwise(X, y, 0.05, 0.10)
    assert [(s.action, f"x{j + 1}") for s, (_, j, _) in zip(ours.history, ref, strict=True)] \
        == [(a, f"x{j + 1}") for a, j, _ in ref]
    np.testing.assert_allclose([s.pvalue for s in ours.history], [p for *_, p in ref], rtol=1e-9)


@settings(max_examples=20, deadline=None, derandomize=True)
@given(subset=st.sets(st.integers(0, 5), min_size=1, max_size=4),
       coefficients=st.lists(st.floats(0.5, 3.0), min_size=6, max_size=6),
       signs=st.lists(st.sampled_from([-1.0, 1.0]), min_size=6, max_size=6),
       seed=st.integers(0, 2**16))
def test_stepwise_recovers_true_subset(subset, coefficients, signs, seed):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(150, 6)) * 3.0 + 10.0
    beta = np.zeros(6)
    for j in subset:
        beta[j] = coefficients[j] * signs[j]
    y = 2.0 + X @ beta + rng.normal(0.0, 1e-3, 150)
    res = stepwise(X, y, rules=StepwiseRules(penter=1e-6, premove=1e-5))
    assert set(res.selected) == {f"x{j + 1}" for j in subset}
    # within 6 standard errors of the truth (noise 1e-3: a fixed rtol would be flaky)
    error = np.abs(res.result.params[1:] - beta[sorted(subset)])
    np.testing.assert_array_less(error, 6.0 * res.result.bse[1:])


def test_collinear_candidate_is_skipped_not_fatal():
    rng = np.random.default_rng(8)
    X = rng.normal(size=(100, 3))
    X[:, 2] = X[:, 0] + X[:, 1]
    y = 2.0 * X[:, 0] + 0.5 * X[:, 1] + 0.1 * rng.normal(size=100)
    res = stepwise(X, y)
    assert len(res.selected) == 2
    assert np.isnan(res.excluded_pvalues[0])  # the third column is a sum of the other two


def test_stepwise_from_accumulator_equals_stepwise():
    X, y = _random_problem(9, n=600)
    acc = GramAccumulator(["f", "f2", "fdot", "g"])
    for rows in np.array_split(np.arange(600), 5):
        acc.partial_fit(X[rows], y[rows])
    a = stepwise_from_accumulator(acc)
    b = stepwise(X, y, names=["f", "f2", "fdot", "g"])
    assert a.selected == b.selected and len(a.history) == len(b.history)
    np.testing.assert_allclose(a.result.params, b.result.params, rtol=1e-10)


def test_stepwise_options_and_serialisation():
    X, y = HALD[:, :4], HALD[:, 4]
    with pytest.raises(InputError, match=r"penter \(0.2\) must not exceed premove \(0.1\)"):
        stepwise(X, y, rules=StepwiseRules(penter=0.2, premove=0.1))
    with pytest.raises(InputError, match="unknown term 'x9'"):
        stepwise(X, y, rules=StepwiseRules(initial=["x9"]))
    assert stepwise(X, y, rules=StepwiseRules(penter=0.2)).premove == 0.2
    short = stepwise(X, y, rules=StepwiseRules(max_steps=1))
    assert len(short.history) == 1 and short.stop_reason == "max_steps"
    res = stepwise(X, y, rules=StepwiseRules(penter=0.06))
    back = StepwiseResult.from_dict(json.loads(json.dumps(res.to_dict())))
    assert back.history == res.history and back.selected == res.selected
    np.testing.assert_array_equal(back.result.params, res.result.params)
    assert OLSResult.from_dict(res.result.to_dict()).names == res.result.names
    assert "removed x4" in res.summary().text() and "const" in res.result.summary().text()


def test_variance_inflation_scales_errors_and_f_statistics():
    rng = np.random.default_rng(5)
    X = rng.normal(size=(400, 3))
    y = 1 + 0.6 * X[:, 0] + 0.15 * X[:, 2] + rng.normal(size=400)
    plain = ols(X, y, refine=False)  # both from the factor
    acc = GramAccumulator().partial_fit(X, y)
    inflated = acc.fit(variance_inflation=4.0)
    np.testing.assert_allclose(inflated.bse, 2.0 * plain.bse, rtol=1e-13)
    np.testing.assert_allclose(inflated.tvalues, plain.tvalues / 2.0, rtol=1e-13)
    np.testing.assert_array_equal(inflated.params, plain.params)
    assert inflated.residual_std == plain.residual_std
    first_plain = stepwise(X, y).history[0]
    first_inflated = stepwise(X, y, rules=StepwiseRules(variance_inflation=4.0)).history[0]
    assert first_inflated.term == first_plain.term
    assert first_inflated.fstat == pytest.approx(first_plain.fstat / 4.0, rel=1e-12)
    # the weak term x3 enters at c = 1 but stays out once F is deflated 25-fold
    assert stepwise(X, y).selected == ("x1", "x3")
    assert stepwise(X, y, rules=StepwiseRules(variance_inflation=25.0)).selected == ("x1",)
    with pytest.raises(InputError, match="variance_inflation must be a finite number >= 1"):
        acc.fit(variance_inflation=0.5)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(cuts=st.lists(st.integers(1, 299), min_size=1, max_size=6, unique=True),
       weighted=st.booleans())
def test_merged_factors_equal_sequential_factor(cuts, weighted):
    # TSQR: merging the R factors of any split equals factoring the rows in one go
    X, y = _random_problem(13, n=300)
    w = np.random.default_rng(1).uniform(0.5, 2.0, 300) if weighted else None
    pieces = np.split(np.arange(300), sorted(cuts))
    sequential, merged = GramAccumulator(), None
    for rows in pieces:
        part_w = None if w is None else w[rows]
        sequential.partial_fit(X[rows], y[rows], part_w)
        part = GramAccumulator().partial_fit(X[rows], y[rows], part_w)
        merged = part if merged is None else merged.merge(part)
    np.testing.assert_allclose(merged.r_, sequential.r_, rtol=0,
                               atol=1e-12 * np.abs(sequential.r_).max())
    one = ols(X, y, weights=w)
    for acc in (merged, sequential):
        fit = acc.fit()
        np.testing.assert_allclose(fit.params, one.params, rtol=1e-12)
        np.testing.assert_allclose(fit.bse, one.bse, rtol=1e-12)
    assert merged.n_ == sequential.n_ == 300


def test_accumulator_pickles_and_survives_json():
    import pickle

    X, y = _random_problem(14, n=500)
    acc = GramAccumulator(["a", "b", "c", "d"]).partial_fit(X, y)
    for back in (pickle.loads(pickle.dumps(acc)),
                 GramAccumulator.from_dict(json.loads(json.dumps(acc.to_dict())))):
        np.testing.assert_array_equal(back.r_, acc.r_)
        np.testing.assert_array_equal(back.fit().params, acc.fit().params)
        assert back.names_ == acc.names_ and back.n_ == acc.n_


@pytest.mark.parametrize("weighted", [False, True])
def test_blocks_folded_by_dtpqrt_equal_one_householder_qr(weighted):
    # Many blocks of rows (the last one short) folded into R one after another give
    # the R of a single Householder QR of all the shifted, scaled rows.
    from hrgtc.drift.qr_accumulator import _BLOCK_ROWS

    n = 2 * _BLOCK_ROWS + _BLOCK_ROWS // 2 + 17
    rng = np.random.default_rng(21)
    X = rng.normal(size=(n, 4)) * [1.0, 10.0, 1e3, 0.1] + [0.0, 5.0, 1e4, -3.0]
    y = 1.0 + X @ [0.2, 0.02, 1e-4, 1.0] + rng.normal(size=n)
    w = rng.uniform(0.0, 2.0, n) if weighted else np.ones(n)
    acc = GramAccumulator().partial_fit(X, y, w if weighted else None)
    z = np.column_stack([np.ones(n), (np.column_stack([X, y]) - acc.shift_) / acc.scale_])
    z *= np.sqrt(w)[:, None]
    reference = np.linalg.qr(z, mode="r")
    reference *= np.where(np.diag(reference) < 0, -1.0, 1.0)[:, None]
    np.testing.assert_allclose(acc.r_, reference, rtol=0, atol=1e-12 * np.abs(reference).max())
    ref = sm.WLS(y, sm.add_constant(X), weights=w).fit()
    fit = acc.fit()
    np.testing.assert_allclose(fit.params, ref.params, rtol=1e-9)
    np.testing.assert_allclose(fit.bse, ref.bse, rtol=1e-9)


# -- Newey-West long-run variance and the hierarchy option --------------------------------------
def _ar1(phi, n, seed):
    rng = np.random.default_rng(seed)
    return signal.lfilter([1.0], [1.0, -phi], rng.normal(0.0, 1.0, n))


@pytest.mark.parametrize("phi", [0.0, 0.3, 0.6, -0.4])
@pytest.mark.parametrize("bandwidth", [1, 4, 20])
def test_newey_west_equals_statsmodels_hac(phi, bandwidth):
    """The inflation is statsmodels' Bartlett HAC variance of the mean over the plain variance."""
    from statsmodels.regression.linear_model import OLS
    from statsmodels.stats.sandwich_covariance import cov_hac

    e = _ar1(phi, 5000, seed=31)
    fit = OLS(e, np.ones(e.size)).fit()
    hac = float(cov_hac(fit, nlags=bandwidth, use_correction=False)[0, 0]) * e.size
    plain = float(np.mean(fit.resid ** 2))
    inflation, used = newey_west_inflation(e, bandwidth)
    assert used == bandwidth
    assert inflation == pytest.approx(max(1.0, hac / plain), rel=1e-10)


@pytest.mark.parametrize("phi", [0.3, 0.6, 0.8])
def test_newey_west_recovers_the_ar1_long_run_variance(phi):
    """AR(1): long-run variance sigma^2/(1-phi)^2 over variance sigma^2/(1-phi^2) = (1+phi)/(1-phi).

    With bandwidth L the Bartlett estimator's expectation is 1 + 2 sum (1 - k/(L+1)) phi^k
    (Newey & West 1987); at L = 400 that is within 2 % of the limit for phi <= 0.8.
    """
    e = _ar1(phi, 2_000_000, seed=32)
    bandwidth = 400
    expected = 1.0 + 2.0 * sum((1.0 - k / (bandwidth + 1.0)) * phi ** k
                               for k in range(1, bandwidth + 1))
    limit = (1.0 + phi) / (1.0 - phi)
    assert expected == pytest.approx(limit, rel=0.02)
    inflation, _ = newey_west_inflation(e, bandwidth)
    assert inflation == pytest.approx(expected, rel=0.05)
    # white noise: no inflation (the factor never falls below 1)
    assert newey_west_inflation(_ar1(0.0, 100_000, seed=33))[0] == pytest.approx(1.0, abs=0.03)


def test_hierarchy_keeps_parents_in_and_changes_the_selection():
    """y = x^2 (+ x z) with x symmetric: x alone explains nothing, so under the marginality
    constraint x^2 cannot enter before x; without it, x^2 enters first."""
    from hrgtc.drift.features import hierarchy, parse_terms

    rng = np.random.default_rng(34)
    n = 4000
    x, z = rng.uniform(-1.0, 1.0, n), rng.uniform(-1.0, 1.0, n)
    terms = parse_terms(["f", "f^2", "df", "f*df"])
    names = [t.name for t in terms]
    X = np.column_stack([x, x * x, z, x * z])
    y = 2.0 * x * x + 1.5 * x * z + 0.5 * z + rng.normal(0.0, 0.05, n)
    parents = hierarchy(terms)
    assert {k: set(v) for k, v in parents.items()} == {
        "f": set(), "f^2": {"f"}, "df": set(), "f*df": {"f", "df"}}
    free = stepwise(X, y, names=names)
    assert "f^2" in free.selected and "f*df" in free.selected and "f" not in free.selected
    marginal = stepwise(X, y, names=names, rules=StepwiseRules(parents=parents))
    for name in marginal.selected:
        assert set(parents[name]) <= set(marginal.selected), (name, marginal.selected)
    assert marginal.selected != free.selected
    assert marginal.history[0].term in ("df", "f")  # a parent comes first
