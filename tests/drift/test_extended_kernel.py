"""The double-double pass of the refinement against exact rational arithmetic.

:func:`hrgtc.drift._extended_kernel.residual_pass` computes r = b - A x (first pass),
f = b - r - A x (later passes) and g = -A' r for the centred, scaled and weighted design of
:func:`hrgtc.drift.regression.refine`. Every input is a float64 (or a sum of two), so the
exact values follow from :class:`fractions.Fraction`; the kernel must agree to about
2^-100 of the size of the terms it sums, far beyond float64 (2^-52) and the 2^-63 of an x87
``numpy.longdouble``.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from hrgtc.drift._extended_kernel import add_to, residual_pass


def _exact_sqrt(w: float) -> Fraction:
    """sqrt(w) to far more than 106 bits (Newton in rationals from the float64 root)."""
    target = Fraction(w)
    root = Fraction(math.sqrt(w))
    for _ in range(3):
        root = (root + target / root) / 2
        root = Fraction(round(root * 2**400), 2**400)
    return root


@pytest.mark.parametrize("weighted", [False, True])
def test_residual_pass_matches_exact_rationals(weighted):
    rng = np.random.default_rng(11)
    n, k = 40, 3
    X = rng.standard_normal((n, k)) * [1.0, 30.0, 1e-3] + [0.5, 4425.0, -2.0]
    y = 4.0 + X @ [0.3, 2e-3, 50.0] + 1e-9 * rng.standard_normal(n)
    shift = np.array([0.5, 4425.0, -2.0, 12.0])
    inverse = np.array([0.5, 0.03125, 1024.0, 0.25])  # powers of two
    weights = rng.uniform(0.1, 3.0, n) if weighted else np.empty(0)
    x_hi = rng.standard_normal(k + 1)
    x_lo = x_hi * 1e-17 * rng.standard_normal(k + 1)
    r_hi, r_lo = np.empty(n), np.empty(n)
    f = np.zeros(n)
    g_hi, g_lo = np.empty(k + 1), np.empty(k + 1)
    residual_pass(X, y, (shift, inverse), weights, (x_hi, x_lo), (r_hi, r_lo), f, (g_hi, g_lo),
                  True)

    x = [Fraction(a) + Fraction(b) for a, b in zip(x_hi, x_lo, strict=True)]
    rows = []
    for i in range(n):
        a = [Fraction(1)] + [(Fraction(X[i, j]) - Fraction(shift[j])) * Fraction(inverse[j])
                             for j in range(k)]
        b = (Fraction(y[i]) - Fraction(shift[k])) * Fraction(inverse[k])
        if weighted:
            root = _exact_sqrt(float(weights[i]))
            a = [v * root for v in a]
            b *= root
        rows.append((a, b))
    size = max(abs(float(v)) for a, b in rows for v in [*a, b]) * max(abs(float(v)) for v in x)
    for i, (a, b) in enumerate(rows):
        exact = b - sum(ai * xi for ai, xi in zip(a, x, strict=True))
        got = Fraction(r_hi[i]) + Fraction(r_lo[i])
        assert abs(float(got - exact)) <= 2.0**-100 * size, i
    g_exact = [-sum(a[j] * (Fraction(r_hi[i]) + Fraction(r_lo[i]))
                    for i, (a, _) in enumerate(rows)) for j in range(k + 1)]
    for j in range(k + 1):
        got = Fraction(g_hi[j]) + Fraction(g_lo[j])
        assert abs(float(got - g_exact[j])) <= 2.0**-98 * size * n * 4, j

    # a later pass: f = b - r - A x of a perturbed r is the perturbation, to double-double
    delta = 1e-3 * rng.standard_normal(n)
    add_to(r_hi, r_lo, -delta)
    residual_pass(X, y, (shift, inverse), weights, (x_hi, x_lo), (r_hi, r_lo), f, (g_hi, g_lo),
                  False)
    np.testing.assert_allclose(f, delta, rtol=1e-15, atol=2.0**-95 * size)


def test_add_to_keeps_what_float64_loses():
    hi, lo = np.array([1.0, 1e16]), np.zeros(2)
    add_to(hi, lo, np.array([1e-20, 1.0]))
    assert Fraction(hi[0]) + Fraction(lo[0]) == 1 + Fraction(1e-20)
    assert Fraction(hi[1]) + Fraction(lo[1]) == Fraction(1e16) + 1
