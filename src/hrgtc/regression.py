"""Ordinary least squares with a constant, Eq. (19)-(20) of [1].

The statistics of the rows are gathered in one pass by :class:`GramAccumulator`
(the tall-skinny QR factor of [1, X, y] of :mod:`hrgtc.qr_accumulator`; chunks
and partial accumulators merge), so tens of millions of rows take O(p^2) memory
and any subset of columns is fitted from the small triangular factor without
touching the rows again. No normal equations are formed: accuracy is that of
Householder QR on the rows. A constant column, or columns whose centred,
equilibrated triangular factor has a reciprocal condition number below ``tol``,
raise :class:`RankDeficientError` naming the columns.

Stepwise selection on these statistics is in :mod:`hrgtc.stepwise`.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from hrgtc.qr_accumulator import (
    COLLINEARITY_TOL,
    OLSResult,
    QRAccumulator,
    _check_names,
)

GramAccumulator = QRAccumulator
"""The library's accumulator of regression statistics (the name callers use)."""

__all__ = [
    "COLLINEARITY_TOL",
    "GramAccumulator",
    "OLSResult",
    "QRAccumulator",
    "newey_west_inflation",
    "ols",
    "ols_from_accumulator",
]


def ols(X: Any, y: Any, names: Sequence[str] | None = None, *, weights: Any = None,
        tol: float = COLLINEARITY_TOL) -> OLSResult:
    """Ordinary (or weighted) least squares with a constant, Eq. (19)-(20) of [1].

    Parameters
    ----------
    X
        Regressors, shape (rows, p), without a column of ones. [units of each term]
    y
        Response, shape (rows,). [units of y]
    names
        Name of each column (default ``x1, x2, ...``).
    weights
        Optional non-negative weight per row.
    tol
        Collinearity tolerance, see :meth:`GramAccumulator.fit`.

    Returns
    -------
    OLSResult
        ``params`` intercept first, then the columns of X. Raises
        :class:`RankDeficientError` for a constant column or collinear columns.
    """
    X = np.asarray(X, dtype=np.float64)
    acc = GramAccumulator(_check_names(names, X.shape[1]) if X.ndim == 2 else names)
    return acc.partial_fit(X, y, weights).fit(tol=tol)


def ols_from_accumulator(acc: GramAccumulator, columns: Sequence[str | int] | None = None, *,
                         tol: float = COLLINEARITY_TOL) -> OLSResult:
    """Fit ``columns`` (default all) from accumulated statistics: ``acc.fit(columns)``."""
    return acc.fit(columns, tol=tol)


def newey_west_inflation(residuals: Any, bandwidth: int | None = None) -> tuple[float, int]:
    """Long-run over plain variance of autocorrelated residuals (Bartlett kernel).

    Newey & West (1987), Econometrica 55(3), 703-708: the long-run variance is
    gamma_0 + 2 sum_{k=1}^{L} (1 - k/(L+1)) gamma_k. Dividing F statistics by the
    returned ratio c (never below 1) corrects tests on window means whose noise
    (bias instability, rate random walk) is correlated from window to window.

    Parameters
    ----------
    residuals
        Residuals in time order, one per window.
    bandwidth
        Largest lag L; default floor(n^(1/3)).

    Returns
    -------
    (c, L)
        The inflation factor and the bandwidth used.
    """
    e = np.asarray(residuals, dtype=np.float64)
    n = e.size
    if n < 3:
        return 1.0, 0
    lag_max = int(n ** (1.0 / 3.0)) if bandwidth is None else int(bandwidth)
    lag_max = max(0, min(lag_max, n - 1))
    e = e - e.mean()
    gamma0 = float(e @ e) / n
    if gamma0 <= 0.0:
        return 1.0, lag_max
    total = gamma0
    for k in range(1, lag_max + 1):
        total += 2.0 * (1.0 - k / (lag_max + 1.0)) * float(e[k:] @ e[:-k]) / n
    return max(1.0, total / gamma0), lag_max
