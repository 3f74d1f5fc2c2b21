"""NIST StRD linear regression: certified coefficients and standard errors.

Two paths are held to NIST's values: :func:`hrgtc.drift.regression.ols` on the rows
(QR factor, then extended-precision refinement of the augmented system) and the
streaming :class:`GramAccumulator` (QR factor only; no rows kept, no refinement).
Accuracy is the log relative error LRE = -log10(|estimate - certified| / |certified|)
(-log10 |estimate| where the certified value is 0), the measure NIST and
McCullough (1998), Am. Stat. 52(4), 358-366, use. Data and certified values are
in :mod:`nist_strd_data` with their sources.
"""

from __future__ import annotations

import numpy as np
import pytest
import statsmodels.api as sm

import nist_strd_data as nist
from hrgtc.core.errors import InputError, PrecisionWarning, RankDeficientError
from hrgtc.drift.regression import EXTENDED_PRECISION, GramAccumulator, ols, refine
from hrgtc.drift.stepwise import StepwiseRules, stepwise

from exact import exact_least_squares

needs_long_double = pytest.mark.skipif(
    not EXTENDED_PRECISION, reason="numpy.longdouble is float64 here: no refinement")


def lre(estimate, certified) -> np.ndarray:
    """Log relative error of each estimate, capped at 15 (NIST's certified digits)."""
    estimate, certified = np.asarray(estimate, float), np.asarray(certified, float)
    error = np.abs(estimate - certified)
    error = np.where(certified != 0, error / np.where(certified != 0, np.abs(certified), 1), error)
    with np.errstate(divide="ignore"):
        return np.minimum(-np.log10(error), 15.0)


def _powers(x: np.ndarray, degree: int) -> np.ndarray:
    return np.column_stack([x ** k for k in range(1, degree + 1)])


def _longley():
    data = sm.datasets.longley.load()
    return np.asarray(data.exog, float), np.asarray(data.endog, float)


# name: (X, y, certified params, certified standard errors, minimum LRE of the factor's fit)
# The factor's coefficients on Wampler5 are capped near LRE 5.6 (see
# test_wampler5_factor_coefficients_as_accurate_as_lstsq); its minimum applies to the SEs.
PROBLEMS = {
    "Norris": (nist.NORRIS_DATA[:, 1:], nist.NORRIS_DATA[:, 0], nist.NORRIS_PARAMS,
               nist.NORRIS_BSE, 7),
    "Pontius": (_powers(nist.PONTIUS_DATA[:, 1], 2), nist.PONTIUS_DATA[:, 0],
                nist.PONTIUS_PARAMS, nist.PONTIUS_BSE, 8),
    "Filip": (_powers(nist.FILIP_DATA[:, 1], 10), nist.FILIP_DATA[:, 0], nist.FILIP_PARAMS,
              nist.FILIP_BSE, 7),
    "Longley": (*_longley(), nist.LONGLEY_PARAMS, nist.LONGLEY_BSE, 8),
    **{f"Wampler{k}": (_powers(nist.WAMPLER_X, 5), getattr(nist, f"WAMPLER{k}_Y"),
                       nist.WAMPLER_PARAMS[f"Wampler{k}"], nist.WAMPLER_BSE[f"Wampler{k}"],
                       8 if k == 5 else 7) for k in range(1, 6)},
}


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_certified_standard_errors(name):
    X, y, _, bse, minimum = PROBLEMS[name]
    result = ols(X, y)
    assert lre(result.bse, bse).min() >= minimum, lre(result.bse, bse)


# minimum LRE of refined coefficients; Filip's float64 powers of x are themselves
# 7.6 digits from NIST's decimal data (the exact solution of the float64 data has LRE 7.6)
REFINED_MINIMUM = {"Longley": 8, "Pontius": 8, "Wampler5": 8}


@needs_long_double
@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_certified_coefficients(name):
    X, y, params, _, _ = PROBLEMS[name]
    result = ols(X, y)
    assert lre(result.params, params).min() >= REFINED_MINIMUM.get(name, 7), \
        lre(result.params, params)


@pytest.mark.parametrize("name", sorted(set(PROBLEMS) - {"Wampler5"}))
def test_certified_coefficients_from_the_factor(name):
    X, y, params, _, minimum = PROBLEMS[name]
    for result in (GramAccumulator().partial_fit(X, y).fit(), ols(X, y, refine=False)):
        assert lre(result.params, params).min() >= minimum, lre(result.params, params)


def test_wampler5_factor_coefficients_as_accurate_as_lstsq():
    # Wampler5's residual is 1e4 times its fit: the LS sensitivity eps * cond^2 * tan(theta)
    # caps any float64 QR or SVD solver near LRE 5.9 (numpy.linalg.lstsq gets 5.86).
    X, y, params, _, _ = PROBLEMS["Wampler5"]
    design = np.column_stack([np.ones(len(y)), X])
    reference = np.linalg.lstsq(design, y, rcond=None)[0]
    for result in (GramAccumulator().partial_fit(X, y).fit(), ols(X, y, refine=False)):
        ours = lre(result.params, params).min()
        assert ours >= lre(reference, params).min() - 0.5
        assert ours >= 5.5


@needs_long_double
def test_wampler5_refined_coefficients_match_the_exact_rational_solution():
    # Independent truth: the exact least-squares solution of the float64 data in
    # rational arithmetic (tests/exact.py); it equals NIST's certified values to 15 digits.
    X, y, params, _, _ = PROBLEMS["Wampler5"]
    design = np.column_stack([np.ones(len(y)), X])
    exact = np.array([float(v) for v in exact_least_squares(design.tolist(), y.tolist())])
    assert lre(exact, params).min() >= 14
    result = ols(X, y)
    assert lre(result.params, exact).min() >= 8, lre(result.params, exact)
    factor_only = ols(X, y, refine=False)
    assert lre(result.params, exact).min() > lre(factor_only.params, exact).min() + 2
    np.testing.assert_array_equal(result.bse, factor_only.bse)  # SEs from R as before


@needs_long_double
def test_weighted_refinement_matches_the_exact_weighted_solution():
    # Integer weights w: weighted LS equals OLS on rows repeated w times, solved exactly.
    X, y, *_ = PROBLEMS["Wampler5"]
    weights = np.arange(len(y)) % 3 + 1.0
    weights[4] = 0.0
    repeat = weights.astype(int)
    design = np.column_stack([np.ones(len(y)), X])
    exact = np.array([float(v) for v in exact_least_squares(
        np.repeat(design, repeat, axis=0).tolist(), np.repeat(y, repeat).tolist())])
    result = ols(X, y, weights=weights)
    assert lre(result.params, exact).min() >= 8, lre(result.params, exact)


@needs_long_double
def test_stepwise_refines_the_selected_model():
    X, y, params, _, _ = PROBLEMS["Wampler5"]
    names = [f"x{k}" for k in range(1, 6)]
    full = StepwiseRules(initial=names, max_steps=0)  # the full model, as certified
    kept = stepwise(X, y, rules=full)
    assert kept.selected == tuple(names)
    assert lre(kept.result.params, params).min() >= 8
    assert lre(stepwise(X, y, rules=full, refine=False).result.params,
               params).min() < 7
    # a free selection keeps few terms (their p-values are near 1): exact fit of those
    found = stepwise(X, y)
    columns = [names.index(n) for n in found.selected]
    design = np.column_stack([np.ones(len(y)), X[:, columns]])
    exact = np.array([float(v) for v in exact_least_squares(design.tolist(), y.tolist())])
    assert lre(found.result.params, exact).min() >= 8
    assert found.history == stepwise(X, y, refine=False).history


def test_refine_without_long_double_keeps_the_fit_and_warns(monkeypatch):
    import hrgtc.drift.regression

    X, y, *_ = PROBLEMS["Wampler5"]
    monkeypatch.setattr(hrgtc.drift.regression, "EXTENDED_PRECISION", False)
    with pytest.warns(PrecisionWarning, match="numpy.longdouble is float64"):
        result = ols(X, y)
    np.testing.assert_array_equal(result.params, ols(X, y, refine=False).params)


def test_refine_rejects_rows_that_are_not_those_of_the_fit():
    X, y, *_ = PROBLEMS["Longley"]
    result = ols(X, y, refine=False)
    with pytest.raises(InputError, match=r"X has 15 rows with positive weight but the fit used 16"):
        refine(result, X[1:], y[1:])


@pytest.mark.parametrize(("name", "residual_sd", "rsquared"), [
    ("Norris", nist.NORRIS_RESIDUAL_SD, nist.NORRIS_RSQUARED),
    ("Pontius", nist.PONTIUS_RESIDUAL_SD, nist.PONTIUS_RSQUARED),
    ("Filip", nist.FILIP_RESIDUAL_SD, nist.FILIP_RSQUARED),
    ("Longley", nist.LONGLEY_RESIDUAL_SD, nist.LONGLEY_RSQUARED),
])
def test_certified_residual_sd_and_rsquared(name, residual_sd, rsquared):
    X, y, *_ = PROBLEMS[name]
    result = ols(X, y)
    assert lre(result.residual_std, residual_sd) >= 7
    assert lre(result.rsquared, rsquared) >= 7


@pytest.mark.parametrize(("name", "minimum"), [("Filip", 6.5), ("Longley", 8), ("Wampler4", 7)])
def test_chunked_and_merged_accumulation_keeps_the_digits(name, minimum):
    # Merging accumulators whose first chunks gave different shifts re-centres one
    # factor in floating point; on Filip (condition 4e9) that costs about one digit.
    X, y, params, bse, _ = PROBLEMS[name]
    parts = [GramAccumulator().partial_fit(X[rows], y[rows])
             for rows in np.array_split(np.arange(len(y)), 4)]
    merged = parts[0].merge(parts[1]).merge(parts[2].merge(parts[3]))
    result = merged.fit()
    assert lre(result.params, params).min() >= minimum
    assert lre(result.bse, bse).min() >= minimum


def test_filip_with_a_duplicated_column_is_refused():
    X, y, *_ = PROBLEMS["Filip"]
    with pytest.raises(RankDeficientError, match=r"are collinear: condition number"):
        ols(np.column_stack([X, 2.0 * X[:, 3]]), y)
