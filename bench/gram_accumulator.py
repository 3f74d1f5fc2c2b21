"""The former normal-equations accumulator of hrgtc, kept only as a benchmark baseline.

Until issue 13, :class:`hrgtc.drift.regression.GramAccumulator` held the column means
(double-double) and the centred co-moment matrix of [X, y], merged with the
pairwise update of Chan, Golub & LeVeque (1979). The library now accumulates the
QR factor instead (:mod:`hrgtc.drift.qr_accumulator`); ``bench_accumulator.py`` times
this class against it on the same chunks. Accumulation only: no fitting here.
"""

from __future__ import annotations

import numpy as np


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Knuth's TwoSum: hi + lo == a + b exactly, hi = fl(a + b)."""
    hi = a + b
    bb = hi - a
    return hi, (a - (hi - bb)) + (b - bb)


class OldGramAccumulator:
    """Means and centred co-moment matrix of [X, y], unweighted, chunk by chunk."""

    def __init__(self) -> None:
        self.n_ = 0
        self.mean_: np.ndarray | None = None
        self.mean_low_: np.ndarray | None = None
        self.comoment_: np.ndarray | None = None

    def partial_fit(self, X: np.ndarray, y: np.ndarray) -> OldGramAccumulator:
        """Add a chunk (the old code's validation, centring and one matrix product)."""
        X = np.asarray(X, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        if not (np.isfinite(X).all() and np.isfinite(y).all()):
            raise ValueError("non-finite values")
        z = np.empty((X.shape[0], X.shape[1] + 1), order="F")
        z[:, :-1] = X
        z[:, -1] = y
        mean = z.mean(axis=0)
        z -= mean
        refine = z.mean(axis=0)
        z -= refine
        comoment = z.T @ z
        comoment = 0.5 * (comoment + comoment.T)
        rows = X.shape[0]
        if self.mean_ is None or self.mean_low_ is None or self.comoment_ is None:
            self.n_ = rows
            self.mean_, self.mean_low_ = _two_sum(mean, refine)
            self.comoment_ = comoment
            return self
        total = self.n_ + rows
        delta = (mean - self.mean_) + (refine - self.mean_low_)
        self.comoment_ = self.comoment_ + comoment + np.outer(delta, delta) * (self.n_ * rows
                                                                                / total)
        self.mean_, self.mean_low_ = _two_sum(self.mean_, self.mean_low_ + delta * (rows / total))
        self.n_ = total
        return self
