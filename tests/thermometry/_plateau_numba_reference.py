"""The soak plateaus' block statistics as numba compiled them before they were written in C
(``src/hrgtc/thermometry/_plateau_native.c``): the reference ``test_plateau_native.py``
compares the C kernel with, bit for bit. Imported by the tests only (it imports numba).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: A quotient this close to an integer (relative) takes numpy's own floor division.
_NEAR = 1e-9


@njit(cache=True, nogil=True, fastmath=False, error_model="numpy")
def _floor_divide(a: float, b: float) -> float:
    """``numpy.floor_divide(a, b)`` for a finite ``a`` and ``b != 0``: numpy's
    ``npy_divmod`` (the exact ``fmod``, then the quotient rounded to its integer)."""
    mod = np.fmod(a, b)
    div = (a - mod) / b
    if mod != 0.0 and (b < 0.0) != (mod < 0.0):
        div -= 1.0
    if div != 0.0:
        whole = np.floor(div)
        if div - whole > 0.5:
            whole += 1.0
        return whole
    return math.copysign(0.0, a / b)


@njit(cache=True, nogil=True, fastmath=False, error_model="numpy")
def block_index(time_s: np.ndarray, block_s: float) -> np.ndarray:
    """``numpy.floor_divide(time_s - time_s[0], block_s).astype(numpy.intp)`` of finite,
    increasing times and a positive ``block_s``, without numpy's ``fmod`` per sample (64 ms
    for a 3.6 M-sample soak, 27 ms here): ``floor(d / block_s)`` where the rounded quotient
    is not within :data:`_NEAR` of an integer (rounding is monotonic and integers are
    representable, so there both are the exact quotient's floor), numpy's own arithmetic
    where it is (``floor_divide(1.0, 0.1)`` is 9, ``floor(1.0 / 0.1)`` 10)."""
    out = np.empty(time_s.size, dtype=np.intp)
    if not time_s.size:
        return out
    origin = time_s[0]
    for i in range(time_s.size):
        a = time_s[i] - origin
        quotient = a / block_s
        whole = np.floor(quotient)
        guard = _NEAR * (1.0 + abs(quotient))
        if quotient - whole > guard and whole + 1.0 - quotient > guard:
            out[i] = int(whole)
        else:
            out[i] = int(_floor_divide(a, block_s))
    return out


@njit(cache=True, nogil=True, fastmath=False)
def block_sums(block: np.ndarray, time_s: np.ndarray, freq_hz: np.ndarray, ref_hz: float,
               chamber_c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                               np.ndarray, np.ndarray]:
    """Per block index of ``block`` (non-negative, ``block.max() + 1`` bins): the count
    and the sums of ``time_s``, ``freq_hz − ref_hz``, its square and ``chamber_c``."""
    bins = block.max() + 1 if block.size else 0
    count = np.zeros(bins, dtype=np.int64)
    time_sum = np.zeros(bins)
    dev_sum = np.zeros(bins)
    dev_sq_sum = np.zeros(bins)
    chamber_sum = np.zeros(bins)
    for i in range(block.size):
        k = block[i]
        dev = freq_hz[i] - ref_hz
        count[k] += 1
        time_sum[k] += time_s[i]
        dev_sum[k] += dev
        dev_sq_sum[k] += dev * dev
        chamber_sum[k] += chamber_c[i]
    return count, time_sum, dev_sum, dev_sq_sum, chamber_sum
