"""The thermometer's inverse per sample, compiled: what the fused kernel calls.

Start from the Chebyshev approximation of T(f), one Newton step when it suffices,
the full safeguarded Newton otherwise, and the bracketed search of the table as
the slow path, as :meth:`hrgtc.thermometry.Thermometer.temperature` does.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from hrgtc.thermometry.thermometer import _NEWTON_MAX_ITER as NEWTON_MAX_ITER

__all__ = ["CHEBYSHEV_SIZE", "NEWTON_MAX_ITER", "POLY_SIZE"]

#: Lengths of the thermometer's series in the kernel (zero-padded at the high-order end,
#: which leaves Horner's and Clenshaw's arithmetic unchanged): f(z) up to order 5 and
#: the Chebyshev start of :mod:`hrgtc.thermometry` (degree 9).
POLY_SIZE = 6
CHEBYSHEV_SIZE = 10


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _start_and_step(f, f_bracket, start_map, t_bracket, chebyshev, centre, scale_c, poly,
                    slope):  # pragma: no cover - compiled
    """Chebyshev start and one Newton step of one sample: (t after the step, the step).
    ``f_bracket``, ``start_map``, ``t_bracket``: the pairs (f_low, f_high), (map offset,
    map scale), (t_low, t_high) of the inverse."""
    f_low, f_high = f_bracket
    map_offset, map_scale = start_map
    t_low, t_high = t_bracket
    c = f
    c = f_low if c < f_low else c
    c = f_high if c > f_high else c
    u = map_offset + map_scale * c
    two_u = 2.0 * u
    b1 = 0.0
    b2 = 0.0
    for j in range(CHEBYSHEV_SIZE - 1, 0, -1):
        b1, b2 = two_u * b1 - b2 + chebyshev[j], b1
    t = u * b1 - b2 + chebyshev[0]
    t = t_low if t < t_low else t
    t = t_high if t > t_high else t
    z = (t - centre) / scale_c
    value = poly[POLY_SIZE - 1]
    for j in range(POLY_SIZE - 2, -1, -1):
        value = value * z + poly[j]
    derivative = slope[POLY_SIZE - 2]
    for j in range(POLY_SIZE - 3, -1, -1):
        derivative = derivative * z + slope[j]
    step = (value - c) / (derivative / scale_c)
    return t - step, step


@njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _value_and_slope(poly, slope, z):  # pragma: no cover - compiled
    """The thermometer polynomial and its derivative series at scaled z (Horner)."""
    value = poly[poly.size - 1]
    for j in range(poly.size - 2, -1, -1):
        value = value * z + poly[j]
    derivative = slope[slope.size - 1]
    for j in range(slope.size - 2, -1, -1):
        derivative = derivative * z + slope[j]
    return value, derivative


@njit(cache=True, nogil=True, error_model="numpy")
def _newton_scalar(t, clipped, poly, slope, centre, scale_c, tolerance):  # pragma: no cover
    """Up to three more Newton steps of one sample whose first step was above the limit."""
    step = np.inf
    limit = tolerance
    for _ in range(3):
        value, derivative = _value_and_slope(poly, slope, (t - centre) / scale_c)
        step = (value - clipped) / (derivative / scale_c)
        t -= step
        if not abs(step) > limit:
            break
    return t, step, limit


@njit(cache=True, nogil=True, error_model="numpy")
def _bracketed_scalar(fi, grid_t, grid_f, poly, slope, centre, scale_c,
                      tolerance):  # pragma: no cover - compiled
    """Safeguarded Newton of one sample in its cell of the dense table (the slow path).

    ``Thermometer._bracketed_newton`` for one sample: linear interpolation in the cell,
    then Newton steps kept inside the shrinking bracket until one moves less than
    ``tolerance``.
    """
    size = grid_f.size
    index = np.searchsorted(grid_f, fi)
    index = 1 if index < 1 else index
    index = size - 1 if index > size - 1 else index
    f0, f1 = grid_f[index - 1], grid_f[index]
    t0, t1 = grid_t[index - 1], grid_t[index]
    t = t0 + (fi - f0) * (t1 - t0) / (f1 - f0)
    lower = min(t0, t1)
    upper = max(t0, t1)
    t = 0.5 * (t0 + t1) if np.isnan(t) else t
    t = lower if t < lower else t
    t = upper if t > upper else t
    increasing = grid_t[size - 1] > grid_t[0]
    for _ in range(NEWTON_MAX_ITER):
        value, derivative = _value_and_slope(poly, slope, (t - centre) / scale_c)
        residual = value - fi
        candidate = t - residual / (derivative / scale_c)
        if (residual > 0) == increasing:
            upper = min(upper, t)
        else:
            lower = max(lower, t)
        if not ((candidate >= lower) & (candidate <= upper)):
            candidate = 0.5 * (lower + upper)
        change = abs(candidate - t)
        t = candidate
        if not change > tolerance:
            break
    return t
