"""Exact rational least squares, the independent reference for the fitting tests."""

from __future__ import annotations

from collections.abc import Sequence
from fractions import Fraction


def _exact(value: float | Fraction) -> Fraction:
    return value if isinstance(value, Fraction) else Fraction(float(value))


def exact_least_squares(design: Sequence[Sequence[float]], y: Sequence[float]) -> list[Fraction]:
    """Solve the normal equations of ``design @ b = y`` in exact rational arithmetic.

    Every float input is taken at its exact binary value, so the result is the
    exact least-squares solution of the floating-point data.
    """
    rows = [[_exact(v) for v in row] for row in design]
    rhs = [_exact(v) for v in y]
    p = len(rows[0])
    normal = [
        [sum((r[a] * r[b] for r in rows), Fraction(0)) for b in range(p)]
        + [sum((r[a] * v for r, v in zip(rows, rhs, strict=True)), Fraction(0))]
        for a in range(p)
    ]
    for column in range(p):
        pivot = next(r for r in range(column, p) if normal[r][column] != 0)
        normal[column], normal[pivot] = normal[pivot], normal[column]
        for r in range(p):
            if r != column and normal[r][column] != 0:
                factor = normal[r][column] / normal[column][column]
                normal[r] = [a - factor * b for a, b in zip(normal[r], normal[column], strict=True)]
    return [normal[i][p] / normal[i][i] for i in range(p)]


def exact_polynomial_fit(x: Sequence[float], y: Sequence[float], order: int) -> list[Fraction]:
    """Exact least-squares polynomial coefficients, ascending powers of raw x."""
    design = [[Fraction(float(v)) ** k for k in range(order + 1)] for v in x]
    return exact_least_squares(design, y)
