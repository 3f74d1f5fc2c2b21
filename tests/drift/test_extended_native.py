"""The refinement's double-double pass in C (``_extended_native.c``) computes the bits of
the numba kernels it replaced (``drift/_extended_numba_reference.py``), and its module
does not import numba.

Compared bit for bit (``.view(np.int64)``: a zero's sign too) over first and later
passes, weighted and not, 0 to 8 columns and 0 to 200 000 rows, columns far from zero
(a clock, a frequency), repeated rows, zero weights and zero values of both signs; the
error-free transformations are exact only with the rounding as written, so any fused or
reordered operation shows here.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from drift import _extended_numba_reference as reference
from hrgtc.drift import _extended_kernel as native


def bits(values) -> np.ndarray:
    return np.asarray(values, dtype=np.float64).view(np.int64)


def problem(rng: np.random.Generator, n: int, k: int, weighted: bool):
    offsets = np.array([1.7e9, 4425.0, -2.0, 0.0, 1e-3, 37.0, 1e6, -5e4])[:k]
    X = rng.standard_normal((n, k)) * np.geomspace(1.0, 1e-3, k) + offsets
    if n > 4:
        X[1] = X[0]  # a repeated row
        X[2, :] = -0.0
        X[3, :] = 0.0
    y = 4417.0 + X @ rng.standard_normal(k) * 1e-3 + 1e-9 * rng.standard_normal(n)
    shift = np.append(np.round(offsets), 4417.0)
    inverse = 2.0 ** rng.integers(-10, 10, k + 1).astype(np.float64)
    weights = rng.uniform(0.0, 3.0, n) if weighted else np.empty(0)
    if weighted and n > 5:
        weights[5] = 0.0
    x_hi = rng.standard_normal(k + 1)
    x_lo = x_hi * 1e-17 * rng.standard_normal(k + 1)
    return X, y, (shift, inverse), weights, (x_hi, x_lo)


def both(X, y, scaling, weights, x, r, f, first: bool) -> list[np.ndarray]:
    """The pass of the C and of the numba kernel from copies of (r, f), compared bit for
    bit; the C kernel's (r_hi, r_lo, f, g_hi, g_lo)."""
    out = []
    for kernel in (native, reference):
        r_copy, f_copy = (r[0].copy(), r[1].copy()), f.copy()
        g = (np.full(x[0].size, -7.0), np.full(x[0].size, -7.0))
        kernel.residual_pass(X, y, scaling, weights, x, r_copy, f_copy, g, first)
        out.append([*r_copy, f_copy, *g])
    for mine, theirs in zip(*out, strict=True):
        np.testing.assert_array_equal(bits(mine), bits(theirs))
    return out[0]


@pytest.mark.parametrize("k", [0, 1, 3, 8])
@pytest.mark.parametrize("n", [0, 1, 2, 1000, 200_000])
@pytest.mark.parametrize("weighted", [False, True])
def test_first_and_later_passes_are_the_numba_kernels(k, n, weighted):
    rng = np.random.default_rng(100 * k + n + weighted)
    X, y, scaling, weights, x = problem(rng, n, k, weighted)
    unset = np.full(n, -7.0)
    # the first pass as refine calls it: r written, f left alone
    r_hi, r_lo, f, _, _ = both(X, y, scaling, weights, x, (unset, unset), np.zeros(n), True)
    assert np.array_equal(f, np.zeros(n))
    # a later pass from that r and a moved x, and one from an r of no relation to x
    moved = (x[0] * (1.0 + 1e-9), x[1])
    both(X, y, scaling, weights, moved, (r_hi, r_lo), unset, False)
    both(X, y, scaling, weights, x, (unset, -unset * 1e-17), unset, False)


@pytest.mark.parametrize("n", [0, 1, 7, 100_000])
def test_add_to_is_the_numba_kernels(n):
    rng = np.random.default_rng(n)
    hi = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    lo = hi * 1e-17 * rng.standard_normal(n)
    increment = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300, n)
    if n > 4:
        hi[:3], lo[:3], increment[:3] = [0.0, -0.0, 1.0], [-0.0, 0.0, 0.0], [-0.0, -0.0, -1.0]
    out = []
    for m in (native, reference):
        h, low = hi.copy(), lo.copy()
        m.add_to(h, low, increment)
        out.append((h, low))
    for mine, theirs in zip(*out, strict=True):
        np.testing.assert_array_equal(bits(mine), bits(theirs))


def test_wrong_arrays_are_refused_not_read():
    rng = np.random.default_rng(1)
    X, y, scaling, weights, x = problem(rng, 10, 2, False)
    r = (np.empty(10), np.empty(10))
    g = (np.empty(3), np.empty(3))
    with pytest.raises(TypeError, match="X"):
        native.residual_pass(np.asfortranarray(X), y, scaling, weights, x, r, np.zeros(10), g,
                             True)
    with pytest.raises(ValueError, match="y has 9"):
        native.residual_pass(X, y[:9], scaling, weights, x, r, np.zeros(10), g, True)
    with pytest.raises(ValueError, match="f has 0"):
        native.residual_pass(X, y, scaling, weights, x, r, np.empty(0), g, False)
    with pytest.raises(ValueError, match="one length"):
        native.add_to(np.zeros(3), np.zeros(3), np.zeros(2))


def test_the_module_does_not_import_numba():
    code = ("import sys; import hrgtc.drift._extended_kernel; import hrgtc.drift.regression; "
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"
