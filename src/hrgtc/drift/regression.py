"""Ordinary least squares with a constant, Eq. (19)-(20) of [1].

The statistics of the rows are gathered in one pass by :class:`GramAccumulator`
(the tall-skinny QR factor of [1, X, y] of :mod:`hrgtc.drift.qr_accumulator`; chunks
and partial accumulators merge), so tens of millions of rows take O(p^2) memory
and any subset of columns is fitted from the small triangular factor without
touching the rows again. No normal equations are formed: accuracy is that of
Householder QR on the rows. A constant column, or columns whose centred,
equilibrated triangular factor has a reciprocal condition number below ``tol``,
raise :class:`RankDeficientError` naming the columns.

For rows held in memory, :func:`ols` (and :func:`hrgtc.drift.stepwise.stepwise`) go
one step further: :func:`refine` polishes the coefficients by iterative
refinement of the augmented system ``[I A; A' 0] [r; x] = [b; 0]`` with residuals in
extended precision (Bjorck 1967), which removes the eps * cond^2 * |r| term that
caps every float64 QR or SVD solver on large-residual problems (NIST's Wampler5:
LRE 5.6 from the factor, >= 8 refined). The streaming accumulator keeps no rows,
so its fits are those of the factor alone.

Stepwise selection on these statistics is in :mod:`hrgtc.drift.stepwise`.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError, PrecisionWarning
from hrgtc.core.student_t import t_sf
from hrgtc.drift.qr_accumulator import (
    COLLINEARITY_TOL,
    OLSResult,
    QRAccumulator,
    _check_names,
    _readonly,
    _validate_chunk,
)

GramAccumulator = QRAccumulator
"""The library's accumulator of regression statistics (the name callers use)."""

__all__ = [
    "COLLINEARITY_TOL",
    "EXTENDED_PRECISION",
    "GramAccumulator",
    "OLSResult",
    "QRAccumulator",
    "newey_west_inflation",
    "ols",
    "ols_from_accumulator",
    "refine",
]

EXTENDED_PRECISION = bool(np.finfo(np.longdouble).eps < np.finfo(np.float64).eps)
"""Whether ``numpy.longdouble`` carries more digits than float64 (80-bit x87 on
x86-64 Linux, IEEE quad on aarch64 Linux). Where it does not (Windows, Apple
silicon), :func:`refine` returns the fit unchanged with a :class:`PrecisionWarning`."""

_REFINE_MAX_STEPS = 10


def ols(X: Any, y: Any, names: Sequence[str] | None = None, *, weights: Any = None,
        tol: float = COLLINEARITY_TOL, refine: bool = True) -> OLSResult:
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
    refine
        Polish the coefficients by extended-precision iterative refinement of
        the augmented system (:func:`refine`); False gives the fit of the QR
        factor alone, as :class:`GramAccumulator` does.

    Returns
    -------
    OLSResult
        ``params`` intercept first, then the columns of X. Raises
        :class:`RankDeficientError` for a constant column or collinear columns.
    """
    X = np.asarray(X, dtype=np.float64)
    acc = GramAccumulator(_check_names(names, X.shape[1]) if X.ndim == 2 else names)
    result = acc.partial_fit(X, y, weights).fit(tol=tol)
    return _refine_module_level(result, X, y, weights) if refine else result


def ols_from_accumulator(acc: GramAccumulator, columns: Sequence[str | int] | None = None, *,
                         tol: float = COLLINEARITY_TOL) -> OLSResult:
    """Fit ``columns`` (default all) from accumulated statistics: ``acc.fit(columns)``."""
    return acc.fit(columns, tol=tol)


def refine(result: OLSResult, X: Any, y: Any, weights: Any = None, *,
           max_steps: int = _REFINE_MAX_STEPS,
           factor: QRAccumulator | None = None) -> OLSResult:
    """Coefficients of ``result`` polished by refinement of the augmented system.

    With A the design [1, X] (rows scaled by sqrt(weights)) and A = QR its
    float64 Householder factorization, each step computes the residuals of the
    augmented system ``[I A; A' 0] [r; x] = [b; 0]``,

        f = b - r - A x,    g = -A' r,

    in double-double arithmetic (about 106 bits, one compiled pass over the rows:
    :mod:`hrgtc.drift._extended_kernel`) and solves for corrections with
    the float64 factors: h = R^-T g, dr = Q h + (I - Q Q') f, R dx = Q' f - h
    (A. Bjorck, BIT 7, 257-278, 1967, doi:10.1007/BF01939321; Bjorck, Numerical
    Methods for Least Squares Problems, SIAM 1996, Sec. 2.9). Refining r with x
    is what removes the eps * cond(A)^2 * |r| / |x| term of the forward error;
    refining x alone against the same float64 solve does not. The columns are
    first centred and scaled by powers of two (exactly, so the problem is not
    changed) and the intercept restored at the end.

    Standard errors, residual_std and rsquared stay those of ``result`` (from
    the triangular factor); ``params``, ``tvalues`` and ``pvalues`` change.
    Needs the rows, so it applies to in-memory arrays, not to a streamed
    :class:`GramAccumulator`. R comes from the rows' TSQR (or ``factor``); where
    cond(R)^2 eps is small Q is not formed and Q h, Q' f are applied as A R^-1 h and
    R^-T A' f (the corrected seminormal equations, Bjorck, BIT 27, 303-313, 1987), so
    the corrections become dx = R^-1 R^-T (A' f - g), dr = f - A dx; otherwise Q comes
    from a Householder QR of A. Memory: the float64 design (as large as X) and Q only
    in the second case (the first applies A from X), plus a few vectors.

    Parameters
    ----------
    result
        A fit of y on a constant and the columns of X (e.g. ``ols(X, y, refine=False)``).
    X
        The fitted columns, shape (rows, len(result.names) - 1), in the order of
        ``result.names[1:]``. [units of each term]
    y
        Response, shape (rows,). [units of y]
    weights
        The weights of the fit, if any.
    max_steps
        Most refinement steps; it stops earlier once a correction is below
        float64 resolution or no longer shrinks.
    factor
        The :class:`QRAccumulator` of exactly these rows, weights and columns (e.g.
        ``acc.select(columns)`` of the accumulator the fit came from), to save a pass
        over the rows; default: built here.

    Returns
    -------
    OLSResult
        ``result`` with refined coefficients. Where ``numpy.longdouble`` is no
        wider than float64 (:data:`EXTENDED_PRECISION` False), ``result``
        itself, with a :class:`~hrgtc.core.errors.PrecisionWarning`.

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(21.0)  # NIST StRD Wampler5: y = 1 + x + ... + x^5 + 1e8 * noise
    >>> X = np.column_stack([x ** k for k in range(1, 6)])
    >>> fit = refine(ols(X, X.sum(axis=1) + 1.0, refine=False), X, X.sum(axis=1) + 1.0)
    >>> np.allclose(fit.params, 1.0, rtol=1e-12, atol=0)
    True
    """
    k = len(result.names) - 1
    X, y, w = _validate_chunk(X, y, weights, result.names[1:])
    if not EXTENDED_PRECISION:
        warnings.warn("numpy.longdouble is float64 on this platform: coefficients not refined "
                      "(large-residual fits keep the float64 QR accuracy)", PrecisionWarning,
                      stacklevel=2)
        return result
    if max_steps < 0:
        raise InputError(f"max_steps must be >= 0, got {max_steps}")
    if w is not None:
        keep = w > 0
        X, y, w = X[keep], y[keep], w[keep]
    if X.shape[0] != result.nobs:
        raise InputError(f"X has {X.shape[0]} rows with positive weight but the fit used "
                         f"{result.nobs}; pass the rows and weights of the fit")
    # The rows' triangular factor, shift and scale: the streamed TSQR of the accumulator
    # (cache-sized blocks, no Q), of the same centred, scaled, weighted [1, X, y] as below.
    if factor is None:
        factor = QRAccumulator().partial_fit(X, y, w)
    elif factor.n_ != X.shape[0] or factor.r_ is None or factor.r_.shape != (k + 2, k + 2):
        raise InputError(f"factor holds {factor.n_} rows and {len(factor.names_ or ())} "
                         f"columns but X has {X.shape[0]} rows and {k}; pass the "
                         "accumulator of these rows and columns")
    assert factor.shift_ is not None and factor.scale_ is not None and factor.r_ is not None
    from scipy.linalg import solve_triangular  # imported on first use: a faster start

    from hrgtc.drift._extended_kernel import add_to, residual_pass

    shift, scale = factor.shift_, factor.scale_
    inverse = 1.0 / scale  # powers of two: exact in float64 and in double-double
    n = X.shape[0]
    eps = np.finfo(np.float64).eps
    X_c = np.ascontiguousarray(X, dtype=np.float64)
    y_c = np.ascontiguousarray(y, dtype=np.float64)
    w_c = np.empty(0) if w is None else np.ascontiguousarray(w, dtype=np.float64)
    # The float64 factorization only preconditions the refinement: its design is formed in
    # float64 (no extended pass), its solution x0 is then corrected against residuals
    # computed in double-double (hrgtc.drift._extended_kernel).
    root_w = None if w is None else np.sqrt(w)
    r_factor = factor.r_[:k + 1, :k + 1]
    cond = float(np.linalg.cond(r_factor))
    # Well-conditioned (cond^2 eps small): the corrections solve the corrected seminormal
    # equations with R alone, Q = A R^-1 applied as A and R (Bjorck 1987, BIT 27, 303-313;
    # Bjorck 1996, Sec. 2.9), and x0 is the factor's own solution. Otherwise Q is formed
    # by a Householder QR of the design, as the augmented refinement needs.
    seminormal = 16.0 * (k + 1) * eps * cond * cond < 1e-3
    if seminormal:
        q = None
        x_hi = solve_triangular(r_factor, factor.r_[:k + 1, k + 1])
        # each step shrinks the error of x by about c (k + 1) eps cond(A)^2
        contraction = min(1.0, 16.0 * (k + 1) * eps * cond * cond)
    else:
        response = (y - shift[k]) * inverse[k]
        if w is not None:
            response *= root_w
        q, r_factor = np.linalg.qr(_design(X_c, shift[:k], inverse[:k], root_w))
        x_hi = solve_triangular(r_factor, q.T @ response)
        del response
        # each step shrinks the error of x by about c (k + 1) eps cond(A) (Bjorck 1967)
        contraction = min(1.0, 16.0 * (k + 1) * eps * cond)
    x_hi = np.ascontiguousarray(x_hi, dtype=np.float64)
    x_lo = np.zeros(k + 1)
    # One extended pass gives r0 = b - A x0 and g = -A' r0 together; the first
    # augmented residual f = b - r0 - A x0 is then zero by construction, and every
    # later pass computes f and g of the current (r, x) at once. Where the contraction
    # factor is tiny, the correction just applied leaves an error below float64
    # resolution and the next pass over the rows is skipped.
    r_hi, r_lo = np.empty(n), np.empty(n)
    f = np.zeros(n)
    g_hi, g_lo = np.empty(k + 1), np.empty(k + 1)
    residual_pass(X_c, y_c, (shift, inverse), w_c, (x_hi, x_lo), (r_hi, r_lo), f,
                  (g_hi, g_lo), True)
    previous = np.inf
    for step in range(max_steps):
        if step:
            residual_pass(X_c, y_c, (shift, inverse), w_c, (x_hi, x_lo), (r_hi, r_lo), f,
                          (g_hi, g_lo), False)
        h = solve_triangular(r_factor, g_hi + g_lo, trans="T")
        if q is None:  # Q' f = R^-T A' f
            d = solve_triangular(r_factor, _design_t(X_c, shift[:k], inverse[:k], root_w, f),
                                 trans="T") if step else np.zeros(k + 1)
        else:
            d = q.T @ f
        dx = solve_triangular(r_factor, d - h)
        size = float(np.max(np.abs(dx)))
        if size >= previous:  # no longer contracting: cond(A) * eps too large to gain more
            break
        add_to(x_hi, x_lo, dx)
        if q is None:  # dr = Q h + (I - Q Q') f = f - A dx
            add_to(r_hi, r_lo, f - _design_times(X_c, shift[:k], inverse[:k], root_w, dx))
        else:
            add_to(r_hi, r_lo, f + q @ (h - d))
        previous = size
        if contraction * size <= eps * float(np.max(np.abs(x_hi))):
            break
    x = x_hi.astype(np.longdouble) + x_lo.astype(np.longdouble)
    shift_ld = shift.astype(np.longdouble)
    scale_ld = scale.astype(np.longdouble)
    sy = scale_ld[k]
    slopes = sy * x[1:] / scale_ld[:k]
    intercept = shift_ld[k] + sy * x[0] - slopes @ shift_ld[:k]
    params = np.concatenate([[intercept], slopes]).astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        tvalues = params / result.bse
    pvalues = 2.0 * t_sf(np.abs(tvalues), result.df_resid)
    return dataclasses.replace(result, params=_readonly(params), tvalues=_readonly(tvalues),
                               pvalues=_readonly(pvalues))


_refine_module_level = refine  # ``ols`` has a parameter of the same name


# The float64 design A = sqrt(w) [1, (X - shift) / scale] of :func:`refine`, applied
# without forming it (a float64 copy as large as X): A v and A' f from X itself. These
# only precondition the refinement; its residuals are computed in double-double.
def _design(X: np.ndarray, shift: np.ndarray, inverse: np.ndarray,
            root_w: np.ndarray | None) -> np.ndarray:
    design = np.empty((X.shape[0], X.shape[1] + 1))
    design[:, 0] = 1.0
    np.subtract(X, shift, out=design[:, 1:])
    design[:, 1:] *= inverse
    if root_w is not None:
        design *= root_w[:, None]
    return design


def _design_times(X: np.ndarray, shift: np.ndarray, inverse: np.ndarray,
                  root_w: np.ndarray | None, v: np.ndarray) -> np.ndarray:
    slopes = inverse * v[1:]
    out = X @ slopes
    out += v[0] - float(shift @ slopes)
    if root_w is not None:
        out *= root_w
    return out


def _design_t(X: np.ndarray, shift: np.ndarray, inverse: np.ndarray,
              root_w: np.ndarray | None, f: np.ndarray) -> np.ndarray:
    g = f if root_w is None else f * root_w
    total = float(g.sum())
    return np.concatenate([[total], inverse * (X.T @ g - shift * total)])


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
