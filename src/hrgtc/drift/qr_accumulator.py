"""Least squares from a streamed QR factor (TSQR), Eq. (19)-(20) of [1].

One pass over the rows reduces the design [1, X, y] to the upper-triangular
factor R of its QR decomposition, chunk by chunk (tall-skinny QR: Demmel,
Grigori, Hoemmen & Langou, SIAM J. Sci. Comput. 34(1), A206-A239, 2012,
doi:10.1137/080731992). Each block of rows is shifted and scaled into a small
column-major buffer that stays in cache and folded into the running R by
LAPACK's triangular-pentagonal QR ``dtpqrt`` (the QR of [R; block]); two
accumulators are merged by a QR of their two stacked factors. Memory is
O(p^2), independent of the number of rows, and any subset of columns is fitted
from R alone by one more small QR of R's selected columns (plus y): the
residual sum of squares is the last diagonal entry squared, the coefficients
come from a triangular solve and their standard errors from the inverse of the
triangular factor. No Gram matrix X'X is ever formed, so the accuracy is that
of Householder QR on the rows: the condition number enters once, not squared
(Golub & Van Loan, Matrix Computations, 4th ed., Sec. 5.3).

Before factoring, every column is shifted by its mean in the first chunk and
divided by a power of two near its standard deviation there (exact), so data
with a large offset (a frequency of 4425 Hz varying by mHz) lose nothing to the
intercept. A subset whose centred, column-equilibrated triangular factor has a
reciprocal condition number below ``tol`` raises
:class:`~hrgtc.core.errors.RankDeficientError` naming the collinear columns.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError, RankDeficientError
from hrgtc.core.student_t import t_sf
from hrgtc.core.summary import Figure, Summary

COLLINEARITY_TOL = 1e-12
"""Default ``tol``: smallest allowed reciprocal condition number (2-norm) of the
centred, column-equilibrated triangular factor of the fitted columns (the square
root of the eigenvalue ratio of their correlation matrix). NIST's Filip
polynomial (2.6e-10) passes; exactly collinear columns (about 1e-16) do not."""

_BLOCK_ROWS = 8_192
"""Rows of a chunk shifted, scaled and folded into R at a time (under 1 MB for a dozen
columns: the buffer stays in cache through the Householder passes)."""
_PANEL_COLUMNS = 4
"""Block size ``nb`` of ``dtpqrt``: columns per panel of its compact-WY updates."""
_QR_ROWS = 256
"""Rows of each small QR within the TSQR tree of :func:`_r_factor` (merges and fits)."""


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


def _r_factor(z: np.ndarray) -> np.ndarray:
    """Upper-triangular R (columns x columns) of the rows of ``z``, by a TSQR tree.

    Blocks of ``_QR_ROWS`` rows are factored in one batched LAPACK call, their
    R factors stacked and factored again until one block is left; small batched
    QRs avoid the threading overhead of BLAS on tall, narrow matrices.
    """
    n = z.shape[1]
    q = max(_QR_ROWS, 2 * n)
    while z.shape[0] > q:
        blocks = -(-z.shape[0] // q)
        padded = np.zeros((blocks * q, n))
        padded[:z.shape[0]] = z
        z = np.linalg.qr(padded.reshape(blocks, q, n), mode="r").reshape(-1, n)
    if z.shape[0] < n:
        z = np.vstack([z, np.zeros((n - z.shape[0], n))])
    return np.linalg.qr(z, mode="r")[:n]


def _canonical(r: np.ndarray) -> np.ndarray:
    """R with a non-negative diagonal (the QR factor is unique up to row signs)."""
    sign = np.where(np.diag(r) < 0, -1.0, 1.0)
    return r * sign[:, None]


# --------------------------------------------------------------------------- accumulator
class QRAccumulator:
    """The R factor of [1, X, y], gathered chunk by chunk (tall-skinny QR).

    Keeps the row count, the sum of weights, the per-column shift and scale
    taken from the first chunk, and the (p + 2)-by-(p + 2) upper-triangular
    factor R of the shifted and scaled rows [sqrt(w), sqrt(w) (x - c) / s,
    sqrt(w) (y - c_y) / s_y]. Memory is O(p^2). Chunks and accumulators merge
    by a QR of stacked factors; the result does not depend on how the rows were
    split, up to rounding. Solves Eq. (20) of [1] for any subset of columns.
    This is the class the library calls ``GramAccumulator`` (its former,
    normal-equations implementation had that name).

    The accumulator keeps no rows, so its fits are those of the factor alone:
    on an ill-conditioned problem whose residual is large next to its fit their
    coefficients carry the eps * cond^2 * tan(theta) error of any float64 QR
    (NIST's Wampler5: LRE 5.6). :func:`hrgtc.drift.regression.ols` and
    :func:`hrgtc.drift.stepwise.stepwise`, which have the rows, refine them in extended
    precision (:func:`hrgtc.drift.regression.refine`).

    Parameters
    ----------
    names
        Name of each column of X (default ``x1, x2, ...``, set by the first chunk).

    Attributes
    ----------
    n_, sum_weights_ : int, float
        Rows seen (zero-weight rows not counted) and sum of weights (= ``n_`` unweighted).
    shift_, scale_ : numpy.ndarray
        Per-column shift (mean in the first chunk) and scale (a power of two near
        the standard deviation in the first chunk) of [X, y], shape (p + 1,).
        [units of columns]
    r_ : numpy.ndarray
        Upper-triangular factor of the shifted, scaled [1, X, y], shape
        (p + 2, p + 2), with a non-negative diagonal. [dimensionless]
    names_ : tuple of str
        Column names of X.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> X = rng.normal(size=(1000, 3)); y = 2 + X @ [1.0, 0.0, -0.5] + rng.normal(size=1000)
    >>> acc = QRAccumulator()
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
        self.shift_: np.ndarray | None = None
        self.scale_: np.ndarray | None = None
        self.r_: np.ndarray | None = None

    def partial_fit(self, X: Any, y: Any, weights: Any = None) -> QRAccumulator:
        """Add a chunk: X (rows, p) [units of each term], y (rows,) [units of y], and
        optional non-negative ``weights`` (rows,) for weighted least squares. Returns self."""
        X, y, w = _validate_chunk(X, y, weights, self.names_)
        if self.names_ is None:
            self.names_ = _default_names(X.shape[1])
        if w is not None:
            keep = w > 0
            if not keep.all():
                X, y, w = X[keep], y[keep], w[keep]
        if X.shape[0] == 0:
            return self
        if self.r_ is None:
            self.shift_, self.scale_ = _shift_and_scale(X, y, w)
        self.r_ = _canonical(self._fold_rows(X, y, w))
        self.n_ += X.shape[0]
        self.sum_weights_ += float(X.shape[0]) if w is None else float(w.sum())
        return self

    def _fold_rows(self, X: np.ndarray, y: np.ndarray, w: np.ndarray | None) -> np.ndarray:
        """R of the stored factor stacked on the shifted, scaled, weighted rows [1, X, y].

        Block by block: the rows are written transposed into a (p + 2, rows) C-order
        buffer, i.e. a column-major rows-by-(p + 2) matrix that LAPACK reads in
        place, and ``dtpqrt`` replaces R by the R of [R; block]. Starting from
        R = 0 gives the R of the first block.
        """
        from scipy.linalg import lapack  # imported on first use: a faster start

        assert self.shift_ is not None and self.scale_ is not None
        rows, p = X.shape
        inverse = 1.0 / self.scale_  # powers of two: exact
        r = np.zeros((p + 2, p + 2), order="F") if self.r_ is None \
            else np.array(self.r_, order="F")
        buffer = np.empty((p + 2, min(rows, _BLOCK_ROWS)))
        root_w = None if w is None else np.sqrt(w)
        for start in range(0, rows, _BLOCK_ROWS):
            stop = min(start + _BLOCK_ROWS, rows)
            z = buffer if stop - start == buffer.shape[1] else np.empty((p + 2, stop - start))
            z[0] = 1.0  # dtpqrt overwrites the block with its Householder vectors
            np.subtract(X[start:stop].T, self.shift_[:p, None], out=z[1:p + 1])
            z[1:p + 1] *= inverse[:p, None]
            np.subtract(y[start:stop], self.shift_[p], out=z[p + 1])
            z[p + 1] *= inverse[p]
            if root_w is not None:
                z *= root_w[start:stop]
            r, _, _, info = lapack.dtpqrt(0, min(_PANEL_COLUMNS, p + 2), r, z.T,
                                          overwrite_a=1, overwrite_b=1)
            if info != 0:  # pragma: no cover - LAPACK argument error
                raise RuntimeError(f"LAPACK dtpqrt failed with info={info}")
        return np.triu(r)

    def merge(self, other: QRAccumulator) -> QRAccumulator:
        """A new accumulator holding the rows of both (same columns); inputs unchanged."""
        if self.names_ is not None and other.names_ is not None and self.names_ != other.names_:
            raise InputError(f"cannot merge accumulators with different columns: "
                             f"{list(self.names_)} vs {list(other.names_)}")
        merged = type(self)(self.names_ or other.names_)
        parts = [a for a in (self, other) if a.r_ is not None]
        if not parts:
            return merged
        base = parts[0]
        assert base.shift_ is not None and base.scale_ is not None and base.r_ is not None
        merged.shift_, merged.scale_ = base.shift_.copy(), base.scale_.copy()
        factors = [base.r_]
        for part in parts[1:]:
            assert part.shift_ is not None and part.scale_ is not None and part.r_ is not None
            # rows of `part` in the coordinates of `base`: z' = (s/s') z + (c - c') / s'
            r = part.r_.copy()
            r[:, 1:] *= part.scale_ / base.scale_
            r[:, 1:] += np.outer(part.r_[:, 0], (part.shift_ - base.shift_) / base.scale_)
            factors.append(r)
        merged.r_ = _canonical(_r_factor(np.vstack(factors)))
        merged.n_ = sum(a.n_ for a in parts)
        merged.sum_weights_ = sum(a.sum_weights_ for a in parts)
        return merged

    def finish(self) -> OLSResult:
        """The fit on every column (:meth:`fit` fits a subset of them)."""
        return self.fit()

    def fit(self, columns: Sequence[str | int] | None = None, *,
            tol: float = COLLINEARITY_TOL, variance_inflation: float = 1.0) -> OLSResult:
        """Fit y on the constant and ``columns`` (names or indices; default all).

        Eq. (20) of [1] from the stored factor: a small QR and triangular solve,
        no pass over the rows. The result lists the columns in column order.
        Raises :class:`RankDeficientError` for a constant column or collinear
        columns (reciprocal condition number of their centred, equilibrated
        triangular factor below ``tol``).
        """
        names = self._require_data()
        idx = sorted(_resolve_terms(columns, names, "columns")) if columns is not None \
            else list(range(len(names)))
        return _solve(self, idx, names, tol, variance_inflation)

    def select(self, columns: Sequence[str | int]) -> QRAccumulator:
        """The accumulator of the same rows with only ``columns`` of X (names or indices).

        From the factor alone: the rows [1, X, y] = Q R give [1, X_sel, y] = Q R_sel with
        R_sel the columns [0, sel, y] of R, whose QR gives the subset's factor. Shift,
        scale and counts are those of the selected columns.
        """
        names = self._require_data()
        assert self.r_ is not None and self.shift_ is not None and self.scale_ is not None
        idx = sorted(_resolve_terms(columns, names, "columns"))
        p = len(names)
        subset = type(self)([names[j] for j in idx])
        subset.n_, subset.sum_weights_ = self.n_, self.sum_weights_
        subset.shift_ = self.shift_[[*idx, p]].copy()
        subset.scale_ = self.scale_[[*idx, p]].copy()
        subset.r_ = _canonical(_r_factor(self.r_[:, [0, *(j + 1 for j in idx), p + 1]]))
        return subset

    def _require_data(self) -> tuple[str, ...]:
        if self.names_ is None or self.r_ is None:
            raise InputError("the accumulator holds no rows yet; call partial_fit(X, y) first")
        return self.names_

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON form of the statistics, for saving a long accumulation
        (:class:`QRAccumulatorRecord`; every float as written, so a round trip is exact)."""
        return records.dump(self, QRAccumulatorRecord, names=list(self.names_ or ()),
                            n=self.n_, sum_weights=self.sum_weights_, shift=self.shift_,
                            scale=self.scale_, r=self.r_)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> QRAccumulator:
        """Inverse of :meth:`to_dict`."""
        values = records.load(data, QRAccumulatorRecord, "QR accumulator")
        acc = cls(list(values["names"]) or None)
        acc.n_, acc.sum_weights_ = values["n"], values["sum_weights"]
        if values["r"] is not None:
            acc.shift_ = np.asarray(values["shift"], dtype=np.float64)
            acc.scale_ = np.asarray(values["scale"], dtype=np.float64)
            acc.r_ = np.asarray(values["r"], dtype=np.float64)
        return acc


class QRAccumulatorRecord(records.Record, kw_only=True):
    """The record of :class:`QRAccumulator`'s state (``shift``, ``scale``: of the columns
    [X, y]; ``r``: the triangular factor of [1, X, y]; all three ``null`` before any row)."""

    names: list[str]
    n: records.Count
    sum_weights: records.NonNegative
    shift: list[float] | None = None
    scale: list[records.Positive] | None = None
    r: list[list[float]] | None = None


def _shift_and_scale(X: np.ndarray, y: np.ndarray, w: np.ndarray | None
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Mean and a power of two near the standard deviation of each column of [X, y].

    Block by block (``_BLOCK_ROWS`` rows at a time), so no copy of [X, y] and no
    temporary as large as X is made: on a chunk of a million rows the copies cost more
    than the QR itself. The scale only conditions the factor (any power of two is
    exact), so the standard deviation need not be correctly rounded.
    """
    n, p = X.shape
    shift = np.empty(p + 1)
    if w is None:
        shift[:p] = X.mean(axis=0)
        shift[p] = y.mean()
    else:
        total = w.sum()
        shift[:p] = (w @ X) / total
        shift[p] = (w @ y) / total
    squares = np.zeros(p + 1)
    for start in range(0, n, _BLOCK_ROWS):
        stop = min(start + _BLOCK_ROWS, n)
        dx = X[start:stop] - shift[:p]
        dy = y[start:stop] - shift[p]
        if w is None:
            squares[:p] += np.einsum("ij,ij->j", dx, dx)
            squares[p] += dy @ dy
        else:
            wb = w[start:stop]
            squares[:p] += np.einsum("i,ij,ij->j", wb, dx, dx)
            squares[p] += (wb * dy) @ dy
    spread = np.sqrt(squares / (n if w is None else w.sum()))
    ok = np.isfinite(spread) & (spread > 0)
    scale = np.ones_like(spread)
    scale[ok] = np.exp2(np.round(np.log2(spread[ok])))
    return shift, scale


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
class OLSResult(records.Written):
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
    params: records.Array[records.Statistic]
    bse: records.Array[records.Statistic]
    tvalues: records.Array[records.Statistic]
    pvalues: records.Array[records.Statistic]
    cov_params: records.Array[tuple[records.Statistic, ...]]
    residual_std: records.Statistic
    rsquared: records.Statistic
    nobs: records.Count
    df_resid: int

    def predict(self, X: Any) -> np.ndarray:
        """Fitted values for rows of X whose columns are ``names[1:]`` in that order."""
        X = np.asarray(X, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != len(self.names) - 1:
            raise InputError(f"X must have shape (rows, {len(self.names) - 1}) with columns "
                             f"{list(self.names[1:])}, got {X.shape}")
        return self.params[0] + X @ self.params[1:]

    def summary(self) -> Summary:
        """The coefficient table (coefficient, standard error, t, p of each term) and the
        fit statistics (its text: the table as statsmodels prints it, shortened)."""
        stats = (Figure("nobs", "rows", self.nobs, definition="Rows of the regression."),
                 Figure("df_resid", "residual dof", self.df_resid,
                        definition="Rows minus fitted coefficients."),
                 Figure("rsquared", "R²", self.rsquared,
                        definition="Share of the variance of y the fit explains."),
                 Figure("residual_std", "residual std", self.residual_std,
                        definition="Standard deviation of the residuals (dof-corrected)."))
        cells: list[Figure] = []
        rows = []
        for k, (name, b, s, t, p) in enumerate(zip(self.names, self.params, self.bse,
                                                   self.tvalues, self.pvalues, strict=True)):
            cells += [Figure(f"names[{k}]", f"term {k}", name, row=name, column="term"),
                      Figure(f"params[{k}]", f"coef of {name}", float(b), row=name,
                             column="coef", definition=f"The fitted coefficient of {name}."),
                      Figure(f"bse[{k}]", f"std err of {name}", float(s), digits=4,
                             row=name, column="std err"),
                      Figure(f"tvalues[{k}]", f"t of {name}", float(t), digits=4, row=name,
                             column="t"),
                      Figure(f"pvalues[{k}]", f"P>|t| of {name}", float(p), digits=3,
                             row=name, column="P>|t|")]
            rows.append(f"{{names[{k}]:<14}}{{params[{k}]:>14.6g}}{{bse[{k}]:>12.4g}}"
                        f"{{tvalues[{k}]:>10.3f}}{{pvalues[{k}]:>11.3g}}")
        layout = ("OLS: {nobs} rows, {df_resid} residual dof, R^2 = {rsquared:.6g}, "
                  "residual std = {residual_std:.6g}",
                  f"{'term':<14}{'coef':>14}{'std err':>12}{'t':>10}{'P>|t|':>11}", *rows)
        return Summary(f"OLS: {self.nobs} rows", (("fit", stats), ("coefficients",
                                                                     tuple(cells))),
                       layout=layout)


#: The record of :class:`OLSResult` (nested in other records).
OLSResultRecord = records.record_of(OLSResult)


def _solve(acc: QRAccumulator, idx: list[int], names: tuple[str, ...], tol: float,
           variance_inflation: float = 1.0) -> OLSResult:
    """Fit y on the constant and columns ``idx`` from the factor in ``acc``.

    A QR of R's columns [1, idx, y] gives the triangular factor T of the subset
    and its right-hand side: T a = t solves the scaled problem, RSS is the last
    diagonal entry squared, and cov(a) = sigma^2 T^-1 T^-T (Golub & Van Loan,
    Sec. 5.3). The slopes and intercept are then unshifted and unscaled by a
    linear map M, so cov(params) = sigma^2 (M T^-1)(M T^-1)'. ``variance_inflation``
    c >= 1 scales the covariance of the estimates (the long-run over the plain
    residual variance of autocorrelated errors); ``residual_std`` is not scaled.
    """
    if not (math.isfinite(variance_inflation) and variance_inflation >= 1.0):
        raise InputError(f"variance_inflation must be a finite number >= 1, got "
                         f"{variance_inflation!r}")
    assert acc.r_ is not None and acc.shift_ is not None and acc.scale_ is not None
    k, p = len(idx), len(names)
    df = acc.n_ - k - 1
    if df < 1:
        raise InputError(f"{acc.n_} rows cannot fit the constant and {k} terms; "
                         f"need at least {k + 2} rows")
    rs = _r_factor(acc.r_[:, [0, *(j + 1 for j in idx), p + 1]])
    shift, scale = acc.shift_, acc.scale_
    tss = float(rs[1:, -1] @ rs[1:, -1])  # centred sum of squares of y (scaled)
    if not tss > 0:
        raise InputError(f"the response y is constant ({shift[p]!r}); nothing to regress")
    # centred sum of squares and mean of each selected column (scaled units)
    sxx = np.einsum("ij,ij->j", rs[1:k + 1, 1:k + 1], rs[1:k + 1, 1:k + 1])
    mean = shift[idx] + scale[idx] * rs[0, 1:k + 1] / rs[0, 0]
    flat = sxx <= acc.sum_weights_ * (4 * np.finfo(float).eps * np.abs(mean) / scale[idx]) ** 2
    if flat.any():
        first = int(np.flatnonzero(flat)[0])
        raise RankDeficientError(f"column {names[idx[first]]!r} is constant (variance "
                                 f"{sxx[first] * scale[idx[first]] ** 2:.3g}); the intercept "
                                 "already covers it: drop the column")
    if k:
        equilibrated = rs[1:k + 1, 1:k + 1] / np.sqrt(sxx)
        _, sv, vt = np.linalg.svd(equilibrated)
        if not sv[-1] > tol * sv[0]:
            weight = np.abs(vt[-1])
            involved = [names[idx[j]] for j in np.flatnonzero(weight > 0.1 * weight.max())]
            cond = sv[0] / sv[-1] if sv[-1] > 0 else math.inf
            raise RankDeficientError(
                f"columns {involved} are collinear: condition number of their centred, "
                f"equilibrated triangular factor {cond:.3g} exceeds {1 / tol:.3g}; drop one "
                "of them or combine them")
    from scipy.linalg import lapack  # imported on first use: a faster start

    tri_inv, info = lapack.dtrtri(rs[:k + 1, :k + 1])  # small: LAPACK directly, no BLAS threads
    if info != 0:
        raise RankDeficientError(f"the triangular factor of columns {[names[j] for j in idx]} "
                                 "is singular; drop collinear columns")
    a = tri_inv @ rs[:k + 1, k + 1]
    sy = scale[p]
    slopes = sy * a[1:] / scale[idx]
    intercept = shift[p] + sy * a[0] - slopes @ shift[idx]
    unscale = np.diag(np.concatenate([[sy], sy / scale[idx]]))
    unscale[0, 1:] = -sy * shift[idx] / scale[idx]
    g = unscale @ tri_inv
    rss = float(rs[k + 1, k + 1]) ** 2
    sigma2 = rss / df  # scaled units of y
    cov = (sigma2 * variance_inflation) * (g @ g.T)
    bse = math.sqrt(sigma2 * variance_inflation) * np.sqrt(np.einsum("ij,ij->i", g, g))
    params = np.concatenate([[intercept], slopes])
    with np.errstate(divide="ignore", invalid="ignore"):
        tvalues = params / bse
    pvalues = 2.0 * t_sf(np.abs(tvalues), df)
    return OLSResult(names=("const", *(names[j] for j in idx)), params=_readonly(params),
                     bse=_readonly(bse), tvalues=_readonly(tvalues), pvalues=_readonly(pvalues),
                     cov_params=_readonly(cov), residual_std=sy * math.sqrt(sigma2),
                     rsquared=max(0.0, 1.0 - rss / tss), nobs=acc.n_, df_resid=df)
