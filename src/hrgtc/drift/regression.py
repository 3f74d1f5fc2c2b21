"""Ordinary least squares on sufficient statistics, Eq. (19)-(20) of [1].

Everything works from sufficient statistics gathered in one pass over the rows
by :class:`GramAccumulator`: the row count, the column means and the centred
co-moment matrix of [X, y]. Chunks are merged with the pairwise update of Chan,
Golub & LeVeque (1979), so the statistics of tens of millions of rows take
O(p^2) memory and any subset of columns is fitted by a p-by-p solve without
touching the rows again. Numerics: the raw Gram matrix X'X is never formed; the
co-moment matrix is scaled to a correlation matrix before it is factored
(Cholesky), the intercept is recovered from the means, and a correlation matrix
whose condition number exceeds 1/``tol`` raises :class:`RankDeficientError`
naming the collinear columns.

Stepwise selection on these statistics is in :mod:`hrgtc.drift.stepwise`.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from scipy import linalg, stats

from hrgtc.errors import InputError, RankDeficientError

COLLINEARITY_TOL = 1e-12
"""Default ``tol``: smallest allowed eigenvalue ratio of the correlation matrix."""


def _readonly(values: Any) -> np.ndarray:
    array = np.array(values, dtype=np.float64)
    array.setflags(write=False)
    return array


def _default_names(p: int) -> tuple[str, ...]:
    return tuple(f"x{k + 1}" for k in range(p))


def _check_names(names: Sequence[str] | None, p: int) -> tuple[str, ...]:
    if names is None:
        return _default_names(p)
    names = tuple(str(n) for n in names)
    if len(names) != p:
        raise InputError(f"names has {len(names)} entries but X has {p} columns; "
                         "pass one name per column")
    if len(set(names)) != p or "const" in names:
        raise InputError(f"names must be unique and must not be 'const', got {list(names)}")
    return names


# --------------------------------------------------------------------------- accumulator
class GramAccumulator:
    """Sufficient statistics of a linear regression, gathered chunk by chunk.

    Keeps the number of rows, the sum of weights, the (weighted) column means of
    [X, y] and their centred co-moment matrix sum_i w_i (z_i - mean)(z_i - mean)'.
    Memory is O(p^2), independent of the number of rows. Chunks are combined with
    the pairwise update of Chan, Golub & LeVeque; within a chunk the means are
    computed with one refining pass and the cross-products with one matrix
    product. The means are held as unevaluated sums hi + lo of two float64
    (double-double), so merging chunks of data with a large offset (a frequency
    of 4425 Hz varying by mHz) loses nothing to the rounding of the means.
    X'X of uncentred data is never formed. Solves Eq. (20) of [1] for any subset
    of columns.

    Parameters
    ----------
    names
        Name of each column of X (default ``x1, x2, ...``, set by the first chunk).

    Attributes
    ----------
    n_, sum_weights_ : int, float
        Rows seen (zero-weight rows not counted) and sum of weights (= ``n_`` unweighted).
    mean_, mean_low_ : numpy.ndarray
        Column means of [X, y] as ``mean_ + mean_low_``, shape (p + 1,). [units of columns]
    comoment_ : numpy.ndarray
        Centred co-moment matrix of [X, y], shape (p + 1, p + 1).
    names_ : tuple of str
        Column names of X.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> X = rng.normal(size=(1000, 3)); y = 2 + X @ [1.0, 0.0, -0.5] + rng.normal(size=1000)
    >>> acc = GramAccumulator()
    >>> for rows in np.array_split(np.arange(1000), 4):
    ...     _ = acc.partial_fit(X[rows], y[rows])
    >>> acc.fit(["x1", "x3"]).names
    ('const', 'x1', 'x3')
    """

    def __init__(self, names: Sequence[str] | None = None) -> None:
        self.names_: tuple[str, ...] | None = None if names is None else tuple(names)
        if self.names_ is not None:
            _check_names(self.names_, len(self.names_))
        self.n_ = 0
        self.sum_weights_ = 0.0
        self.mean_: np.ndarray | None = None
        self.mean_low_: np.ndarray | None = None
        self.comoment_: np.ndarray | None = None

    def partial_fit(self, X: Any, y: Any, weights: Any = None) -> GramAccumulator:
        """Add a chunk: X (rows, p) [units of each term], y (rows,) [units of y], and
        optional non-negative ``weights`` (rows,) for weighted least squares. Returns self."""
        X, y, w = _validate_chunk(X, y, weights, self.names_)
        if self.names_ is None:
            self.names_ = _default_names(X.shape[1])
        if X.shape[0] == 0:
            return self
        z = np.empty((X.shape[0], X.shape[1] + 1), order="F")  # columns contiguous: pairwise sums
        z[:, :-1] = X
        z[:, -1] = y
        rows = X.shape[0] if w is None else int(np.count_nonzero(w))
        self._combine(rows, *_chunk_moments(z, w))
        return self

    update = partial_fit

    def _combine(self, rows: int, weight: float, mean: np.ndarray, mean_low: np.ndarray,
                 comoment: np.ndarray) -> None:
        if weight <= 0:
            return
        if self.mean_ is None or self.mean_low_ is None or self.comoment_ is None:
            self.n_, self.sum_weights_ = rows, weight
            self.mean_, self.mean_low_ = _two_sum(mean, mean_low)
            self.comoment_ = comoment.copy()
            return
        total = self.sum_weights_ + weight
        delta = (mean - self.mean_) + (mean_low - self.mean_low_)
        self.comoment_ = (self.comoment_ + comoment
                          + np.outer(delta, delta) * (self.sum_weights_ * weight / total))
        self.mean_, self.mean_low_ = _two_sum(self.mean_, self.mean_low_ + delta * (weight / total))
        self.n_ += rows
        self.sum_weights_ = total

    def merge(self, other: GramAccumulator) -> GramAccumulator:
        """A new accumulator holding the rows of both (same columns); inputs unchanged."""
        if self.names_ is not None and other.names_ is not None and self.names_ != other.names_:
            raise InputError(f"cannot merge accumulators with different columns: "
                             f"{list(self.names_)} vs {list(other.names_)}")
        merged = GramAccumulator(self.names_ or other.names_)
        for part in (self, other):
            if part.mean_ is not None and part.mean_low_ is not None:
                merged._combine(part.n_, part.sum_weights_, part.mean_, part.mean_low_,
                                part.comoment_)
        return merged

    def fit(self, columns: Sequence[str | int] | None = None, *,
            tol: float = COLLINEARITY_TOL, variance_inflation: float = 1.0) -> OLSResult:
        """Fit y on the constant and ``columns`` (names or indices; default all).

        Eq. (20) of [1] from the stored statistics: a p-by-p solve, no pass over
        the rows. The result lists the columns in column order. Raises
        :class:`RankDeficientError` for a constant column or collinear columns
        (eigenvalue ratio of their correlation matrix below ``tol``).
        """
        names = self._require_data()
        idx = sorted(_resolve_terms(columns, names, "columns")) if columns is not None \
            else list(range(len(names)))
        return _solve(self, idx, names, tol, variance_inflation)

    def _require_data(self) -> tuple[str, ...]:
        if self.names_ is None or self.mean_ is None:
            raise InputError("the accumulator holds no rows yet; call partial_fit(X, y) first")
        return self.names_

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON form of the statistics (for saving a long accumulation)."""
        return {"names": list(self.names_ or ()), "n": self.n_,
                "sum_weights": self.sum_weights_,
                "mean": None if self.mean_ is None else self.mean_.tolist(),
                "mean_low": None if self.mean_low_ is None else self.mean_low_.tolist(),
                "comoment": None if self.comoment_ is None else self.comoment_.tolist()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> GramAccumulator:
        """Inverse of :meth:`to_dict`."""
        acc = cls(data["names"] or None)
        acc.n_, acc.sum_weights_ = int(data["n"]), float(data["sum_weights"])
        if data["mean"] is not None:
            acc.mean_ = np.asarray(data["mean"], dtype=np.float64)
            acc.mean_low_ = np.asarray(data["mean_low"], dtype=np.float64)
            acc.comoment_ = np.asarray(data["comoment"], dtype=np.float64)
        return acc


def _validate_chunk(X: Any, y: Any, weights: Any, names: tuple[str, ...] | None
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2:
        raise InputError(f"X must be 2-D (rows, columns), got shape {X.shape}; "
                         "reshape a single column with X.reshape(-1, 1)")
    y = np.asarray(y, dtype=np.float64)
    if y.shape != (X.shape[0],):
        raise InputError(f"y must be 1-D with one value per row of X ({X.shape[0]} rows), "
                         f"got shape {y.shape}")
    if names is not None and X.shape[1] != len(names):
        raise InputError(f"X has {X.shape[1]} columns but the accumulator has {len(names)} "
                         f"({list(names)}); pass the same columns in every chunk")
    names = names or _default_names(X.shape[1])
    if not np.isfinite(X).all():
        row, col = np.argwhere(~np.isfinite(X))[0]
        raise InputError(f"X column {names[col]!r} has non-finite value {X[row, col]} at row "
                         f"{row}; drop or fill such rows before fitting")
    if not np.isfinite(y).all():
        row = int(np.flatnonzero(~np.isfinite(y))[0])
        raise InputError(f"y has non-finite value {y[row]} at row {row}; drop or fill such rows")
    w = None if weights is None else np.asarray(weights, dtype=np.float64)
    if w is not None and not (w.shape == y.shape and np.isfinite(w).all() and (w >= 0).all()):
        raise InputError(f"weights must be finite, >= 0 and of shape {y.shape}; got shape "
                         f"{w.shape}, min {np.min(w, initial=np.inf)}")
    return X, y, w


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knuth's TwoSum: hi + lo == a + b exactly, hi = fl(a + b)."""
    hi = a + b
    bb = hi - a
    return hi, (a - (hi - bb)) + (b - bb)


def _chunk_moments(z: np.ndarray, w: np.ndarray | None
                   ) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Weight, mean (hi, lo) and centred co-moment of one chunk (``z`` is overwritten)."""
    if w is None:
        weight = float(z.shape[0])
        mean = z.mean(axis=0)
        z -= mean
        refine = z.mean(axis=0)  # corrected two-pass: removes the rounding of the first mean
    else:
        weight = float(w.sum())
        if weight <= 0:
            return 0.0, z[0], z[0], np.zeros((z.shape[1], z.shape[1]))
        mean = (w @ z) / weight
        z -= mean
        refine = (w @ z) / weight
    z -= refine
    if w is not None:
        z *= np.sqrt(w)[:, None]
    comoment = z.T @ z
    return weight, mean, refine, 0.5 * (comoment + comoment.T)


def _resolve_terms(terms: Any, names: tuple[str, ...], argument: str) -> set[int]:
    """Column indices from names, indices or a boolean mask."""
    terms = list(terms)
    if terms and all(isinstance(t, bool | np.bool_) for t in terms):
        if len(terms) != len(names):
            raise InputError(f"{argument} mask has {len(terms)} entries, expected {len(names)}")
        return {k for k, t in enumerate(terms) if t}
    out = set()
    for t in terms:
        if isinstance(t, str):
            if t not in names:
                raise InputError(f"{argument}: unknown term {t!r}; known terms are {list(names)}")
            out.add(names.index(t))
        elif isinstance(t, int | np.integer) and 0 <= int(t) < len(names):
            out.add(int(t))
        else:
            raise InputError(f"{argument}: {t!r} is neither a term name nor a column index "
                             f"0..{len(names) - 1}")
    return out


# --------------------------------------------------------------------------- OLS
@dataclass(frozen=True, eq=False)
class OLSResult:
    """Least-squares fit with a constant, Eq. (19)-(20) of [1].

    Attributes
    ----------
    names
        ``("const", *terms)``.
    params
        Coefficients, intercept first then the terms in column order. [units of y per term]
    bse
        Standard errors of ``params``.
    tvalues
        ``params / bse``.
    pvalues
        Two-sided p-values of the t statistics with ``df_resid`` degrees of freedom.
    cov_params
        Covariance matrix of ``params``.
    residual_std
        sqrt(RSS / df_resid). [units of y]
    rsquared
        Coefficient of determination.
    nobs
        Number of rows.
    df_resid
        nobs - number of terms - 1.
    """

    names: tuple[str, ...]
    params: np.ndarray
    bse: np.ndarray
    tvalues: np.ndarray
    pvalues: np.ndarray
    cov_params: np.ndarray
    residual_std: float
    rsquared: float
    nobs: int
    df_resid: int

    def predict(self, X: Any) -> np.ndarray:
        """Fitted values for rows of X whose columns are ``names[1:]`` in that order."""
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != len(self.names) - 1:
            raise InputError(f"X must have shape (rows, {len(self.names) - 1}) with columns "
                             f"{list(self.names[1:])}, got {X.shape}")
        return self.params[0] + X @ self.params[1:]

    def summary(self) -> str:
        """Coefficient table and fit statistics as text."""
        lines = [f"OLS: {self.nobs} rows, {self.df_resid} residual dof, "
                 f"R^2 = {self.rsquared:.6g}, residual std = {self.residual_std:.6g}",
                 f"{'term':<14}{'coef':>14}{'std err':>12}{'t':>10}{'P>|t|':>11}"]
        for name, b, s, t, p in zip(self.names, self.params, self.bse, self.tvalues,
                                    self.pvalues, strict=True):
            lines.append(f"{name:<14}{b:>14.6g}{s:>12.4g}{t:>10.3f}{p:>11.3g}")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        return {k: v.tolist() if isinstance(v, np.ndarray) else list(v) if isinstance(v, tuple)
                else v for k, v in out.items()}

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> OLSResult:
        """Inverse of :meth:`to_dict`."""
        arrays = {k: _readonly(data[k]) for k in ("params", "bse", "tvalues", "pvalues",
                                                   "cov_params")}
        return cls(names=tuple(data["names"]), residual_std=float(data["residual_std"]),
                   rsquared=float(data["rsquared"]), nobs=int(data["nobs"]),
                   df_resid=int(data["df_resid"]), **arrays)


def _solve(acc: GramAccumulator, idx: list[int], names: tuple[str, ...], tol: float,
           variance_inflation: float = 1.0) -> OLSResult:
    """Fit y on the constant and columns ``idx`` from the statistics in ``acc``.

    The co-moment block is scaled to a correlation matrix R and its Cholesky factor
    L solves R b = r; slopes are b * sd(y) / sd(x), the intercept is mean(y) - slopes . mean(x).
    ``variance_inflation`` c >= 1 scales the covariance of the estimates (the long-run over
    the plain residual variance of autocorrelated errors); ``residual_std`` is not scaled.
    """
    if not (math.isfinite(variance_inflation) and variance_inflation >= 1.0):
        raise InputError(f"variance_inflation must be a finite number >= 1, got "
                         f"{variance_inflation!r}")
    assert acc.mean_ is not None and acc.mean_low_ is not None and acc.comoment_ is not None
    k, iy = len(idx), len(names)
    df = acc.n_ - k - 1
    if df < 1:
        raise InputError(f"{acc.n_} rows cannot fit the constant and {k} terms; "
                         f"need at least {k + 2} rows")
    m, mean = acc.comoment_, acc.mean_
    syy = m[iy, iy]
    if not syy > 0:
        raise InputError(f"the response y is constant ({mean[iy]!r}); nothing to regress")
    sxx = np.diag(m)[idx]
    flat = sxx <= acc.sum_weights_ * (4 * np.finfo(float).eps * np.abs(mean[idx])) ** 2
    if flat.any():
        term = names[idx[int(np.flatnonzero(flat)[0])]]
        raise RankDeficientError(f"column {term!r} is constant (variance {sxx[flat][0]:.3g}); "
                                 "the intercept already covers it: drop the column")
    d = np.sqrt(sxx)
    corr = m[np.ix_(idx, idx)] / np.outer(d, d)
    r = m[idx, iy] / (d * math.sqrt(syy))
    eig, vec = np.linalg.eigh(corr)
    if k and not eig[0] > tol * eig[-1]:
        weight = np.abs(vec[:, 0])
        involved = [names[idx[j]] for j in np.flatnonzero(weight > 0.1 * weight.max())]
        cond = eig[-1] / eig[0] if eig[0] > 0 else math.inf
        raise RankDeficientError(
            f"columns {involved} are collinear: condition number of their correlation "
            f"matrix {cond:.3g} exceeds {1 / tol:.3g}; drop one of them or combine them")
    chol = np.linalg.cholesky(corr)
    beta = linalg.cho_solve((chol, True), r)
    rinv = linalg.cho_solve((chol, True), np.eye(k))
    rsquared = float(r @ beta)
    sigma2 = max(syy * (1.0 - rsquared), 0.0) / df
    slopes = beta * math.sqrt(syy) / d
    sigma2_params = sigma2 * variance_inflation
    cov_slopes = sigma2_params * rinv / np.outer(d, d)
    u = linalg.solve_triangular(chol, mean[idx] / d, lower=True)
    var0 = sigma2_params * (1.0 / acc.sum_weights_ + float(u @ u))  # a sum of squares
    cov = np.empty((k + 1, k + 1))
    cov[0, 0] = var0
    cov[1:, 1:] = cov_slopes
    cov[0, 1:] = cov[1:, 0] = -(cov_slopes @ mean[idx])
    low = acc.mean_low_
    intercept = (mean[iy] - slopes @ mean[idx]) + (low[iy] - slopes @ low[idx])
    params = np.concatenate([[intercept], slopes])
    bse = np.sqrt(np.diag(cov))
    with np.errstate(divide="ignore", invalid="ignore"):
        tvalues = params / bse
    pvalues = 2.0 * stats.t.sf(np.abs(tvalues), df)
    return OLSResult(names=("const", *(names[j] for j in idx)), params=_readonly(params),
                     bse=_readonly(bse), tvalues=_readonly(tvalues), pvalues=_readonly(pvalues),
                     cov_params=_readonly(cov), residual_std=math.sqrt(sigma2),
                     rsquared=rsquared, nobs=acc.n_, df_resid=df)


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
