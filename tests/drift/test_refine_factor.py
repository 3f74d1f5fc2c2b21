"""The refinement reuses the selection's factor: the same coefficients, one pass fewer.

:meth:`QRAccumulator.select` derives the factor of a column subset from the full factor
alone; :func:`refine` given that factor must polish a fit exactly as when it factors the
rows itself, and refuse a factor of other rows or columns.
"""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.drift.regression import EXTENDED_PRECISION, QRAccumulator, ols, refine
from hrgtc.drift.stepwise import StepwiseRules, stepwise


def _data(weighted: bool):
    rng = np.random.default_rng(7)
    n = 20_000
    X = rng.standard_normal((n, 5)) * [1.0, 30.0, 0.01, 5.0, 1.0] + [0.0, 4425.0, -2.0, 1e3, 0.0]
    X[:, 3] += 0.7 * X[:, 0]
    y = 1.5 + 0.3 * X[:, 0] - 200.0 * X[:, 2] + 3e-3 * X[:, 1] + rng.standard_normal(n)
    w = rng.uniform(0.0, 2.0, n) if weighted else None
    if w is not None:
        w[::50] = 0.0  # zero-weight rows are left out by both
    return X, y, w


@pytest.mark.parametrize("weighted", [False, True])
def test_select_gives_the_factor_of_the_columns(weighted):
    X, y, w = _data(weighted)
    full = QRAccumulator().partial_fit(X, y, w)
    subset = full.select([1, 2, 4])
    direct = QRAccumulator().partial_fit(X[:, [1, 2, 4]], y, w)
    assert subset.names_ == ("x2", "x3", "x5")
    assert subset.n_ == direct.n_ and subset.sum_weights_ == pytest.approx(direct.sum_weights_)
    # the means of a column summed within X or within a copy of three columns differ by ulps
    np.testing.assert_allclose(subset.shift_, direct.shift_, rtol=1e-13, atol=0)
    np.testing.assert_array_equal(subset.scale_, direct.scale_)
    scale = np.abs(direct.r_).max()
    np.testing.assert_allclose(subset.r_, direct.r_, rtol=1e-10, atol=1e-9 * scale)
    np.testing.assert_allclose(subset.fit().params, direct.fit().params, rtol=1e-10)


@pytest.mark.skipif(not EXTENDED_PRECISION, reason="numpy.longdouble is float64 here")
@pytest.mark.parametrize("weighted", [False, True])
def test_refine_with_the_selections_factor_equals_refine_alone(weighted):
    X, y, w = _data(weighted)
    columns = [0, 1, 2]
    fit = ols(X[:, columns], y, weights=w, refine=False)
    alone = refine(fit, X[:, columns], y, w)
    reused = refine(fit, X[:, columns], y, w,
                    factor=QRAccumulator().partial_fit(X, y, w).select(columns))
    np.testing.assert_allclose(reused.params, alone.params, rtol=1e-13, atol=0)
    chosen = stepwise(X, y, weights=w, rules=StepwiseRules(penter=1e-3, premove=1e-2))
    assert chosen.selected == ("x1", "x2", "x3")
    np.testing.assert_allclose(chosen.result.params, alone.params, rtol=1e-13, atol=0)


def test_refine_refuses_a_factor_of_other_rows_or_columns():
    X, y, _ = _data(False)
    fit = ols(X[:, :2], y, refine=False)
    with pytest.raises(InputError, match="factor holds"):
        refine(fit, X[:, :2], y,
               factor=QRAccumulator().partial_fit(X[:100], y[:100]).select([0, 1]))
    with pytest.raises(InputError, match="factor holds"):
        refine(fit, X[:, :2], y, factor=QRAccumulator().partial_fit(X, y).select([0, 1, 2]))
