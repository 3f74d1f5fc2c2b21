"""Fused numba kernels of the overlapping Allan, modified Allan and Hadamard variances.

Private to :mod:`hrgtc.evaluation._allan_sums`, which imports this module on first use so
that ``import hrgtc.evaluation.allan`` (and the CLI start) does not pay numba's import; the
overlapping Allan sums at power-of-two factors (``taus="octave"``) come from the C module
``_allan_octave`` instead, and never import numba.

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
#: Threads for the blocks of one τ, or for the τ of a long list (two pay on a two-core
#: machine; more only share bandwidth).
THREADS = 2

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
def _second_difference(y, mean, marks, i, m):
    """d_i = X[i+2m] − 2X[i+m] + X[i], exact up to the final rounding.

    Double-double sum, the integer coefficients applied by repeated addition in
    index order, rounded once; written out, so no small arrays are allocated at
    each block start.
    """
    x0h, x0l = _phase_at(y, mean, marks, i)
    x1h, x1l = _phase_at(y, mean, marks, i + m)
    x2h, x2l = _phase_at(y, mean, marks, i + 2 * m)
    sh, sl = _dd_add(0.0, 0.0, x0h, x0l)
    sh, sl = _dd_add(sh, sl, -x1h, -x1l)
    sh, sl = _dd_add(sh, sl, -x1h, -x1l)
    sh, sl = _dd_add(sh, sl, x2h, x2l)
    return sh + sl


@njit(inline="always", **_JIT)
def _third_difference(y, mean, marks, i, m, level):
    """Q[i+3m] − 3Q[i+2m] + 3Q[i+m] − Q[i] for Q = X (level 1) or P (level 2).

    As :func:`_second_difference`, with the coefficients (−1, 3, −3, 1).
    """
    if level == 1:
        q0h, q0l = _phase_at(y, mean, marks, i)
        q1h, q1l = _phase_at(y, mean, marks, i + m)
        q2h, q2l = _phase_at(y, mean, marks, i + 2 * m)
        q3h, q3l = _phase_at(y, mean, marks, i + 3 * m)
    else:
        q0h, q0l = _phase_sum_at(y, mean, marks, i)
        q1h, q1l = _phase_sum_at(y, mean, marks, i + m)
        q2h, q2l = _phase_sum_at(y, mean, marks, i + 2 * m)
        q3h, q3l = _phase_sum_at(y, mean, marks, i + 3 * m)
    sh, sl = _dd_add(0.0, 0.0, -q0h, -q0l)
    for _ in range(3):
        sh, sl = _dd_add(sh, sl, q1h, q1l)
    for _ in range(3):
        sh, sl = _dd_add(sh, sl, -q2h, -q2l)
    sh, sl = _dd_add(sh, sl, q3h, q3l)
    return sh + sl


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
    """e[k] = d_{start+k+1} − d_{start+k}, the step of the second difference (vectorises).

    Indexed through slices from 0, so that no negative-index wrap-around check is
    left in the loop (numba adds one for ``y[i + m]``; it stopped LLVM vectorising,
    at 1.8 instead of 0.37 ns a term).
    """
    n = e.size
    y0, y1, y2, _ = _lagged(y, start, m, n)
    for k in range(n):
        e[k] = ((y2[k] - mean) + (y0[k] - mean)) - 2.0 * (y1[k] - mean)


@njit(**_JIT)
def _oadev_block(y, mean, marks, m, start, stop):
    """One block's Σ d_i² (see :func:`oadev_sum`)."""
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
    return acc


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
        partial[b] = _oadev_block(y, mean, marks, m, start, min(start + BLOCK, terms))
    return compensated_sum(partial)


@njit(parallel=True, **_JIT)
def oadev_sums(y, mean, marks, factors):
    """:func:`oadev_sum` of every factor, the factors shared out among the threads.

    For many τ (``taus="all"``), where one call per τ would cost more in thread
    start-ups than in arithmetic. Each τ is summed by one thread through the same
    blocks in the same order, so the sums equal :func:`oadev_sum`'s bit for bit.
    """
    out = np.empty(factors.size)
    for t in prange(THREADS):
        for j in range(t, factors.size, THREADS):
            m = factors[j]
            terms = y.size + 1 - 2 * m
            blocks = (terms + BLOCK - 1) // BLOCK
            partial = np.empty(blocks)
            for b in range(blocks):
                start = b * BLOCK
                partial[b] = _oadev_block(y, mean, marks, m, start, min(start + BLOCK, terms))
            out[j] = compensated_sum(partial)
    return out


@njit(inline="always", **_JIT)
def _lagged(y, start, m, n):
    """y[start + k·m :][:n] for k = 0..3: slices indexed from 0, so that no
    wrap-around check is left in the loops over them (see :func:`_increments`)."""
    return (y[start:start + n], y[start + m:start + m + n],
            y[start + 2 * m:start + 2 * m + n], y[start + 3 * m:start + 3 * m + n])


@njit(**_JIT)
def _ohdev_block(y, mean, marks, m, start, stop):
    """One block's Σ h_i² (see :func:`ohdev_sum`)."""
    h = _third_difference(y, mean, marks, start, m, 1)
    acc = h * h
    n = stop - 1 - start
    y0, y1, y2, y3 = _lagged(y, start, m, n)
    for k in range(n):
        h += ((y3[k] - mean) - (y0[k] - mean)) - 3.0 * ((y2[k] - mean) - (y1[k] - mean))
        acc += h * h
    return acc


@njit(parallel=True, **_JIT)
def ohdev_sum(y, mean, marks, m):
    """Σ_i h_i² over the N+1−3m overlapping third differences of the phase."""
    terms = y.size + 1 - 3 * m
    blocks = (terms + BLOCK - 1) // BLOCK
    partial = np.empty(blocks)
    for b in prange(blocks):
        start = b * BLOCK
        partial[b] = _ohdev_block(y, mean, marks, m, start, min(start + BLOCK, terms))
    return compensated_sum(partial)


@njit(parallel=True, **_JIT)
def ohdev_sums(y, mean, marks, factors):
    """:func:`ohdev_sum` of every factor, the factors shared out among the threads.

    For many τ (``taus="all"``), where one call per τ would cost more in thread
    start-ups than in arithmetic. Each τ is summed by one thread through the same
    blocks in the same order, so the sums equal :func:`ohdev_sum`'s bit for bit.
    """
    out = np.empty(factors.size)
    for t in prange(THREADS):
        for j in range(t, factors.size, THREADS):
            m = factors[j]
            terms = y.size + 1 - 3 * m
            blocks = (terms + BLOCK - 1) // BLOCK
            partial = np.empty(blocks)
            for b in range(blocks):
                start = b * BLOCK
                partial[b] = _ohdev_block(y, mean, marks, m, start, min(start + BLOCK, terms))
            out[j] = compensated_sum(partial)
    return out


@njit(**_JIT)
def _mdev_block(y, mean, marks, m, start, stop):
    """One block's Σ v_j² (see :func:`mdev_sum`)."""
    v = _third_difference(y, mean, marks, start, m, 2)
    acc = v * v
    if stop - start > 1:
        d0h = _second_difference(y, mean, marks, start, m)
        d1h = _second_difference(y, mean, marks, start + m, m)
        d0l = 0.0
        d1l = 0.0
        vl = 0.0
        n = stop - 1 - start
        s0, s1, s2, s3 = _lagged(y, start, m, n)
        for k in range(n):
            step, e = _two_sum(d1h, -d0h)
            v, e2 = _two_sum(v, step)
            vl += e + e2 + (d1l - d0l)
            value = v + vl
            acc += value * value
            if k == n - 1:
                break
            y0 = s0[k] - mean
            y1 = s1[k] - mean
            y2 = s2[k] - mean
            y3 = s3[k] - mean
            d0h, e = _two_sum(d0h, (y2 + y0) - 2.0 * y1)
            d0l += e
            d1h, e = _two_sum(d1h, (y3 + y1) - 2.0 * y2)
            d1l += e
    return acc


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
        partial[b] = _mdev_block(y, mean, marks, m, start, min(start + BLOCK, terms))
    return compensated_sum(partial)


@njit(parallel=True, **_JIT)
def mdev_sums(y, mean, marks, factors):
    """:func:`mdev_sum` of every factor, the factors shared out among the threads.

    For many τ (``taus="all"``), where one call per τ would cost more in thread
    start-ups than in arithmetic. Each τ is summed by one thread through the same
    blocks in the same order, so the sums equal :func:`mdev_sum`'s bit for bit.
    """
    out = np.empty(factors.size)
    for t in prange(THREADS):
        for j in range(t, factors.size, THREADS):
            m = factors[j]
            terms = y.size + 2 - 3 * m
            blocks = (terms + BLOCK - 1) // BLOCK
            partial = np.empty(blocks)
            for b in range(blocks):
                start = b * BLOCK
                partial[b] = _mdev_block(y, mean, marks, m, start, min(start + BLOCK, terms))
            out[j] = compensated_sum(partial)
    return out


#: Kernels (one τ, blocks in parallel; many τ, τ in parallel) and checkpoint levels. One
#: pair per statistic, each compiled on its first use only: one kernel for all three
#: (chosen by number) compiled them all, 30-60 s, and a block function passed as an
#: argument defeats numba's cache (it recompiled in every process).
KERNELS = {"allan": (oadev_sum, oadev_sums, 1), "hadamard": (ohdev_sum, ohdev_sums, 1),
           "modified": (mdev_sum, mdev_sums, 2)}
#: From this many τ on, the τ (not the blocks of each) are shared among the threads.
MANY_TAUS = 64
#: τ per call of a many-τ kernel (progress is reported after each call).
TAU_BATCH = 256


def sums_of_squares(y, kind, factors, progress=None):
    """Sum of squared stencil terms of ``kind`` for each averaging factor in ``factors``.

    ``y`` is a C-contiguous float64 array; ``factors`` must leave at least one
    term each. ``progress(done, total)`` is called after each factor (after each
    batch of :data:`TAU_BATCH` when there are :data:`MANY_TAUS` or more). Either
    way the sums are the same bit for bit.
    """
    import numba

    one, many, levels = KERNELS[kind]
    mean = float(np.mean(y))  # pairwise, as allantools' frequency2phase (np.nanmean)
    marks = checkpoints(y, mean, levels)
    previous = numba.get_num_threads()
    numba.set_num_threads(min(THREADS, numba.config.NUMBA_NUM_THREADS))
    total = len(factors)
    try:
        out = np.empty(total)
        if total >= MANY_TAUS:
            factors = np.ascontiguousarray(factors, dtype=np.int64)
            for start in range(0, total, TAU_BATCH):
                stop = min(start + TAU_BATCH, total)
                out[start:stop] = many(y, mean, marks, factors[start:stop])
                if progress is not None:
                    progress(float(stop), float(total))
        else:
            for done, m in enumerate(factors, start=1):
                out[done - 1] = one(y, mean, marks, int(m))
                if progress is not None:
                    progress(float(done), float(total))
    finally:
        numba.set_num_threads(previous)
    return out
