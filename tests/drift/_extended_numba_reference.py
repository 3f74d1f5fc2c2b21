"""The refinement's double-double pass as numba compiled it before it was written in C
(``src/hrgtc/drift/_extended_native.c``): the reference ``test_extended_native.py``
compares the C kernel with, bit for bit. Imported by the tests only (it imports numba).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_SPLITTER = 134217729.0  # 2^27 + 1: Veltkamp's splitting constant of float64


@njit(cache=True, nogil=True, inline="always")
def _two_sum(a, b):  # pragma: no cover - compiled
    """s + e = a + b exactly, s = fl(a + b) (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@njit(cache=True, nogil=True, inline="always")
def _split(a):  # pragma: no cover - compiled
    """hi + lo = a with hi, lo of at most 26 significant bits each (Veltkamp)."""
    c = _SPLITTER * a
    hi = c - (c - a)
    return hi, a - hi


@njit(cache=True, nogil=True, inline="always")
def _two_product(a, a_hi, a_lo, b, b_hi, b_lo):  # pragma: no cover - compiled
    """p + e = a * b exactly, p = fl(a * b), from the splits of a and b (Dekker)."""
    p = a * b
    return p, a_lo * b_lo - (((p - a_hi * b_hi) - a_lo * b_hi) - a_hi * b_lo)


@njit(cache=True, nogil=True, error_model="numpy")
def residual_pass(X, y, scaling, weights, x, r, f, g, first):  # pragma: no cover - compiled
    """One pass over the rows in double-double arithmetic.

    ``scaling`` is ``(shift, inverse)``; ``x``, ``r`` and ``g`` are the (hi, lo) pairs of
    arrays of x, r and g. ``first``: r = b - A x is written to (r_hi, r_lo) and f is left
    alone; otherwise f = b - r - A x of the current (r, x) is written to ``f`` (rounded to
    float64). In both cases g = -A' r, with the r after the pass, goes to (g_hi, g_lo).
    ``weights`` is empty for an unweighted fit.
    """
    shift, inverse = scaling
    x_hi, x_lo = x
    r_hi, r_lo = r
    g_hi, g_lo = g
    n, k = X.shape
    weighted = weights.size > 0
    xs_hi = np.empty(k + 1)
    xs_lo = np.empty(k + 1)
    for j in range(k + 1):
        xs_hi[j], xs_lo[j] = _split(x_hi[j])
    a_hi = np.empty(k + 1)
    a_lo = np.empty(k + 1)
    acc_hi = np.zeros(k + 1)
    acc_err = np.zeros(k + 1)
    for i in range(n):
        # the row of the design and the response, exact before the weight: the shifts are
        # float64 TwoSums, the scales powers of two
        a_hi[0], a_lo[0] = 1.0, 0.0
        for j in range(k):
            s, e = _two_sum(X[i, j], -shift[j])
            a_hi[j + 1], a_lo[j + 1] = s * inverse[j], e * inverse[j]
        b_hi, b_lo = _two_sum(y[i], -shift[k])
        b_hi, b_lo = b_hi * inverse[k], b_lo * inverse[k]
        if weighted:
            w = weights[i]
            rw = math.sqrt(w)  # sqrt(w) to double-double by one Newton step
            rw_s_hi, rw_s_lo = _split(rw)
            p, e = _two_product(rw, rw_s_hi, rw_s_lo, rw, rw_s_hi, rw_s_lo)
            rw_lo = ((w - p) - e) / (2.0 * rw)
            rs_hi, rs_lo = _split(rw)
            for j in range(k + 1):
                h_hi, h_lo = _split(a_hi[j])
                p, e = _two_product(a_hi[j], h_hi, h_lo, rw, rs_hi, rs_lo)
                e += a_hi[j] * rw_lo + a_lo[j] * rw
                a_hi[j], a_lo[j] = _two_sum(p, e)
            h_hi, h_lo = _split(b_hi)
            p, e = _two_product(b_hi, h_hi, h_lo, rw, rs_hi, rs_lo)
            e += b_hi * rw_lo + b_lo * rw
            b_hi, b_lo = _two_sum(p, e)
        # s = b - r - A x, by Dot2: the float64 sum in s, every rounding error in err
        s, err = b_hi, b_lo
        if not first:
            s, e = _two_sum(s, -r_hi[i])
            err += e - r_lo[i]
        for j in range(k + 1):
            h_hi, h_lo = _split(a_hi[j])
            p, e = _two_product(a_hi[j], h_hi, h_lo, x_hi[j], xs_hi[j], xs_lo[j])
            s, e2 = _two_sum(s, -p)
            err += e2 - e - (a_hi[j] * x_lo[j] + a_lo[j] * x_hi[j])
        s, err = _two_sum(s, err)
        if first:
            r_hi[i], r_lo[i] = s, err
        else:
            f[i] = s
        # g -= a r, with the row's residual after the pass
        rh, rl = r_hi[i], r_lo[i]
        rh_hi, rh_lo = _split(rh)
        for j in range(k + 1):
            h_hi, h_lo = _split(a_hi[j])
            p, e = _two_product(a_hi[j], h_hi, h_lo, rh, rh_hi, rh_lo)
            acc_hi[j], e2 = _two_sum(acc_hi[j], -p)
            acc_err[j] += e2 - e - (a_hi[j] * rl + a_lo[j] * rh)
    for j in range(k + 1):
        g_hi[j], g_lo[j] = _two_sum(acc_hi[j], acc_err[j])


@njit(cache=True, nogil=True)
def add_to(hi, lo, increment):  # pragma: no cover - compiled
    """(hi, lo) += increment, element by element, in double-double."""
    for i in range(hi.size):
        s, e = _two_sum(hi[i], increment[i])
        hi[i], lo[i] = _two_sum(s, e + lo[i])
