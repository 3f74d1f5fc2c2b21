"""The extended-precision pass of :func:`hrgtc.drift.regression.refine`, in C.

One pass over the rows computes the residuals of the augmented least-squares system,
f = b - r - A x, and g = -A' r, in double-double arithmetic: every quantity is an
unevaluated sum hi + lo of two float64 numbers, and every product and sum keeps its
rounding error through the error-free transformations of Dekker and Knuth (TwoProduct by
Veltkamp splitting, TwoSum), accumulated as in Ogita, Rump and Oishi's Dot2 ("Accurate sum
and dot product", SIAM J. Sci. Comput. 26(6), 1955-1988, 2005, doi:10.1137/030601818).
The result is as accurate as if computed in twice the working precision (about 106 bits),
more than the 64 bits of an x87 ``numpy.longdouble``, in one fused loop instead of numpy's
extended-precision temporaries: the refinement's pass over a million rows drops from most
of a second to a fraction of it.

The design is formed here, row by row, exactly as :func:`refine` defines it: a constant
column and the columns of X shifted by ``shift`` and scaled by ``inverse`` (powers of two,
so the scaling is exact), both rows and response multiplied by the square root of the
row's weight when there are weights.

The loops are the compiled module ``_extended_native`` (``_extended_native.c``, built by
``pip install -e .``); they were numba kernels, kept as the reference of
``tests/drift/test_extended_native.py``, which checks the two agree bit for bit. numba is
not imported: its import and start cost a command more than the pass
(docs/architecture.md, "The native kernels"). When the module is missing this raises
``ImportError`` saying how to build it.
"""

from __future__ import annotations

import numpy as np

from hrgtc.core.native import native_module

_native = native_module("hrgtc.drift._extended_native", "double-double pass")


def residual_pass(X: np.ndarray, y: np.ndarray, scaling: tuple, weights: np.ndarray,
                  x: tuple, r: tuple, f: np.ndarray, g: tuple, first: bool) -> None:
    """One pass over the rows in double-double arithmetic.

    ``X`` is C-contiguous (n, k) and every array float64 and contiguous. ``scaling`` is
    ``(shift, inverse)`` (k + 1 each); ``x``, ``r`` and ``g`` are the (hi, lo) pairs of
    arrays of x, r and g. ``first``: r = b - A x is written to (r_hi, r_lo) and f is left
    alone; otherwise f = b - r - A x of the current (r, x) is written to ``f`` (rounded to
    float64). In both cases g = -A' r, with the r after the pass, goes to (g_hi, g_lo).
    ``weights`` is empty for an unweighted fit.
    """
    _native.residual_pass(X, y, scaling, weights, x, r, f, g, bool(first))


def add_to(hi: np.ndarray, lo: np.ndarray, increment: np.ndarray) -> None:
    """(hi, lo) += increment, element by element, in double-double."""
    _native.add_to(hi, lo, np.ascontiguousarray(increment, dtype=np.float64))
