"""Fused numba kernels of the overlapping Allan, modified Allan and Hadamard variances.

Private to :mod:`hrgtc.evaluation.allan`, which imports this module on first use so that
``import hrgtc.evaluation.allan`` (and the CLI start) does not pay numba's import.

How the kernels work
--------------------
No phase array is stored. With ``y'[k] = y[k] − μ`` (μ the mean, as in
``allantools.frequency2phase``) the phase is ``X[k] = Σ_{l<k} y'[l]`` and its
running sum ``P[k] = Σ_{l<k} X[l]``. Every statistic is a stencil on X (or P)
whose value at i+1 follows from the one at i by a short stencil on y':

- overlapping Allan, SP 1065 Eq. (11) [1]: ``d_i = X[i+2m] − 2X[i+m] + X[i]``,
  ``d_{i+1} = d_i + y'[i+2m] − 2y'[i+m] + y'[i]``;
- overlapping Hadamard, Eq. (20): ``h_i = X[i+3m] − 3X[i+2m] + 3X[i+m] − X[i]``,
  ``h_{i+1} = h_i + y'[i+3m] − 3y'[i+2m] + 3y'[i+m] − y'[i]``;
- modified Allan, Eq. (14): ``v_j = Σ_{i=j}^{j+m−1} d_i =
  P[j+3m] − 3P[j+2m] + 3P[j+m] − P[j]``, ``v_{j+1} = v_j + d_{j+m} − d_j``.

The terms are cut into blocks of ``BLOCK`` samples. At the start of each block
the stencil is evaluated exactly (double-double arithmetic, error-free
``two_sum``) from checkpoints of X and P kept every ``STRIDE`` samples
(2 × 8 bytes per checkpoint and level, i.e. 1/32 of the input per level), so
rounding can only accumulate over one block (≤ √BLOCK·ε relative, ~1e-14).
The squares of a block are summed in float64; the block sums go into one slot
per block and are added in a fixed order with Neumaier's compensated sum, so
the result is identical bit for bit whatever the number of threads. The blocks
of one τ run in parallel (``prange``).

References
----------
[1] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
    Publication 1065, 2008.
[2] T. Ogita, S. M. Rump, S. Oishi, "Accurate sum and dot product", SIAM J.
    Sci. Comput. 26(6), 1955-1988, 2005, Algorithm 3.1 (TwoSum).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

#: Samples between two stored checkpoints of the phase X and its sum P.
STRIDE = 64
#: Terms per block: the stencil is re-evaluated exactly at each block start.
BLOCK = 4000
#: Independent recursions walked side by side in a block (latency hiding).
LANES = 4

_JIT = {"cache": True, "nogil": True, "fastmath": False}


@njit(inline="always", **_JIT)
def _two_sum(a, b):
    """s + e == a + b exactly, s = fl(a + b) (Knuth's TwoSum, [2])."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@njit(inline="always", **_JIT)
def _acc(h, lo, value):
    """Add ``value`` to the unnormalised double-double h + lo (only h is on the chain)."""
    h, e = _two_sum(h, value)
    return h, lo + e


@njit(inline="always", **_JIT)
def _dd_add(ah, al, bh, bl):
    """Double-double sum (ah + al) + (bh + bl), renormalised."""
    s, e = _two_sum(ah, bh)
    e += al + bl
    return _two_sum(s, e)


@njit(**_JIT)
def checkpoints(y, mean, levels):
    """Phase X (and its sum P if ``levels == 2``) at every STRIDE-th index, double-double.

    Returns an array ``(levels, 2, (N + 1) // STRIDE + 1)``: ``[0, 0] + [0, 1]``
    is X[c·STRIDE] as hi + lo (0 ≤ c·STRIDE ≤ N), ``[1, ...]`` the same for P
    (0 ≤ c·STRIDE ≤ N + 1).
    """
    n = y.size
    out = np.zeros((levels, 2, (n + 1) // STRIDE + 1))
    xh = 0.0
    xl = 0.0
    ph = 0.0
    pl = 0.0
    for k in range(n + 2):
        if k % STRIDE == 0:
            c = k // STRIDE
            out[0, 0, c] = xh
            out[0, 1, c] = xl
            if levels == 2:
                out[1, 0, c] = ph
                out[1, 1, c] = pl
        if levels == 2 and k <= n:
            ph, pl = _acc(ph, pl, xh)
            pl += xl
        if k < n:
            xh, xl = _acc(xh, xl, y[k] - mean)
    return out


@njit(inline="always", **_JIT)
def _phase_at(y, mean, marks, j):
    """X[j] as double-double, from the checkpoint below j and at most STRIDE−1 samples."""
    c = j // STRIDE
    xh = marks[0, 0, c]
    xl = marks[0, 1, c]
    for k in range(c * STRIDE, j):
        xh, xl = _acc(xh, xl, y[k] - mean)
    return xh, xl


@njit(inline="always", **_JIT)
def _phase_sum_at(y, mean, marks, j):
    """P[j] = Σ_{l<j} X[l] as double-double (needs ``levels == 2`` checkpoints)."""
    c = j // STRIDE
    xh = marks[0, 0, c]
    xl = marks[0, 1, c]
    ph = marks[1, 0, c]
    pl = marks[1, 1, c]
    for k in range(c * STRIDE, j):
        ph, pl = _acc(ph, pl, xh)
        pl += xl
        if k + 1 < j:
            xh, xl = _acc(xh, xl, y[k] - mean)
    return ph, pl


@njit(inline="always", **_JIT)
def _stencil(values_h, values_l, coefficients):
    """Σ c_k · v_k in double-double, integer c_k applied by repeated addition; rounded."""
    sh = 0.0
    sl = 0.0
    for k in range(coefficients.size):
        c = coefficients[k]
        for _ in range(abs(c)):
            if c > 0:
                sh, sl = _dd_add(sh, sl, values_h[k], values_l[k])
            else:
                sh, sl = _dd_add(sh, sl, -values_h[k], -values_l[k])
    return sh + sl


@njit(inline="always", **_JIT)
def _second_difference(y, mean, marks, i, m):
    """d_i = X[i+2m] − 2X[i+m] + X[i], exact up to the final rounding."""
    h = np.empty(3)
    lo = np.empty(3)
    for k in range(3):
        h[k], lo[k] = _phase_at(y, mean, marks, i + k * m)
    return _stencil(h, lo, np.array((1, -2, 1)))


@njit(inline="always", **_JIT)
def _third_difference(y, mean, marks, i, m, level):
    """Q[i+3m] − 3Q[i+2m] + 3Q[i+m] − Q[i] for Q = X (level 1) or P (level 2)."""
    h = np.empty(4)
    lo = np.empty(4)
    for k in range(4):
        if level == 1:
            h[k], lo[k] = _phase_at(y, mean, marks, i + k * m)
        else:
            h[k], lo[k] = _phase_sum_at(y, mean, marks, i + k * m)
    return _stencil(h, lo, np.array((-1, 3, -3, 1)))


@njit(**_JIT)
def compensated_sum(values):
    """Neumaier's compensated sum, in index order (deterministic)."""
    s = 0.0
    c = 0.0
    for v in values:
        s, e = _two_sum(s, v)
        c += e
    return s + c


@njit(inline="always", **_JIT)
def _increments(y, mean, m, start, e):
    """e[k] = d_{start+k+1} − d_{start+k}, the step of the second difference (vectorises)."""
    for k in range(e.size):
        i = start + k
        e[k] = ((y[i + 2 * m] - mean) + (y[i] - mean)) - 2.0 * (y[i + m] - mean)


@njit(parallel=True, **_JIT)
def oadev_sum(y, mean, marks, m):
    """Σ_i d_i² over the N+1−2m overlapping second differences of the phase.

    Each block's steps d_{i+1} − d_i are computed first in one contiguous pass (SIMD),
    then walked as four interleaved lanes (quarters of the block, each started
    exactly) so that four independent dependency chains fill the floating-point
    pipeline; the arithmetic is that of one step at a time, so the sum is too.
    """
    terms = y.size + 1 - 2 * m
    blocks = (terms + BLOCK - 1) // BLOCK
    partial = np.empty(blocks)
    for b in prange(blocks):
        start = b * BLOCK
        stop = min(start + BLOCK, terms)
        quarter = (stop - start) // LANES
        e = np.empty(stop - start - 1)
        _increments(y, mean, m, start, e)
        acc = 0.0
        if quarter > 1:
            d0 = _second_difference(y, mean, marks, start, m)
            d1 = _second_difference(y, mean, marks, start + quarter, m)
            d2 = _second_difference(y, mean, marks, start + 2 * quarter, m)
            d3 = _second_difference(y, mean, marks, start + 3 * quarter, m)
            a0 = d0 * d0
            a1 = d1 * d1
            a2 = d2 * d2
            a3 = d3 * d3
            for k in range(quarter - 1):
                d0 += e[k]
                a0 += d0 * d0
                d1 += e[quarter + k]
                a1 += d1 * d1
                d2 += e[2 * quarter + k]
                a2 += d2 * d2
                d3 += e[3 * quarter + k]
                a3 += d3 * d3
            # the last lane also takes the remainder of the block
            for k in range(4 * quarter - 1, stop - start - 1):
                d3 += e[k]
                a3 += d3 * d3
            acc = (a0 + a1) + (a2 + a3)
        else:
            d = _second_difference(y, mean, marks, start, m)
            acc = d * d
            for k in range(stop - start - 1):
                d += e[k]
                acc += d * d
        partial[b] = acc
    return compensated_sum(partial)


@njit(parallel=True, **_JIT)
def ohdev_sum(y, mean, marks, m):
    """Σ_i h_i² over the N+1−3m overlapping third differences of the phase."""
    terms = y.size + 1 - 3 * m
    blocks = (terms + BLOCK - 1) // BLOCK
    partial = np.empty(blocks)
    for b in prange(blocks):
        start = b * BLOCK
        stop = min(start + BLOCK, terms)
        h = _third_difference(y, mean, marks, start, m, 1)
        acc = h * h
        for i in range(start, stop - 1):
            h += ((y[i + 3 * m] - mean) - (y[i] - mean)) - 3.0 * (
                (y[i + 2 * m] - mean) - (y[i + m] - mean)
            )
            acc += h * h
        partial[b] = acc
    return compensated_sum(partial)


@njit(parallel=True, **_JIT)
def mdev_sum(y, mean, marks, m):
    """Σ_j v_j² over the N+2−3m sums v_j of m consecutive second differences.

    The two second differences d_j and d_{j+m} that drive v are carried with
    their rounding errors (TwoSum), so that v, their running sum, stays exact
    to ~ε over the block.
    """
    terms = y.size + 2 - 3 * m
    blocks = (terms + BLOCK - 1) // BLOCK
    partial = np.empty(blocks)
    for b in prange(blocks):
        start = b * BLOCK
        stop = min(start + BLOCK, terms)
        v = _third_difference(y, mean, marks, start, m, 2)
        acc = v * v
        if stop - start > 1:
            d0h = _second_difference(y, mean, marks, start, m)
            d1h = _second_difference(y, mean, marks, start + m, m)
            d0l = 0.0
            d1l = 0.0
            vl = 0.0
            for j in range(start, stop - 1):
                step, e = _two_sum(d1h, -d0h)
                v, e2 = _two_sum(v, step)
                vl += e + e2 + (d1l - d0l)
                value = v + vl
                acc += value * value
                if j == stop - 2:
                    break
                y0 = y[j] - mean
                y1 = y[j + m] - mean
                y2 = y[j + 2 * m] - mean
                y3 = y[j + 3 * m] - mean
                d0h, e = _two_sum(d0h, (y2 + y0) - 2.0 * y1)
                d0l += e
                d1h, e = _two_sum(d1h, (y3 + y1) - 2.0 * y2)
                d1l += e
        partial[b] = acc
    return compensated_sum(partial)


#: Kernel and checkpoint levels of each statistic.
KERNELS = {"allan": (oadev_sum, 1), "hadamard": (ohdev_sum, 1), "modified": (mdev_sum, 2)}
#: Threads for the blocks of one τ (two pay on a two-core machine; more only share bandwidth).
THREADS = 2


def sums_of_squares(y, kind, factors, progress=None):
    """Sum of squared stencil terms of ``kind`` for each averaging factor in ``factors``.

    ``y`` is a C-contiguous float64 array; ``factors`` must leave at least one
    term each. ``progress(done, total)`` is called after each factor.
    """
    import numba

    kernel, levels = KERNELS[kind]
    mean = float(np.mean(y))  # pairwise, as allantools' frequency2phase (np.nanmean)
    marks = checkpoints(y, mean, levels)
    previous = numba.get_num_threads()
    numba.set_num_threads(min(THREADS, numba.config.NUMBA_NUM_THREADS))
    try:
        out = np.empty(len(factors))
        for done, m in enumerate(factors, start=1):
            out[done - 1] = kernel(y, mean, marks, int(m))
            if progress is not None:
                progress(float(done), float(len(factors)))
    finally:
        numba.set_num_threads(previous)
    return out
