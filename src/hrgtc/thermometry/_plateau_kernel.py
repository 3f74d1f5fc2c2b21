"""Compiled loop of the soak plateaus' block statistics (:mod:`hrgtc.thermometry.plateaus`).

One pass over a soak gives, per block, what five ``numpy.bincount`` calls gave (one array
pass each, and a temporary per product): the samples, and the sums of the time, of the
frequency less a reference, of its square and of the chamber temperature. ``bincount``
adds its weights to their bins in the order of the samples, as this loop does, so the sums
are the same bit for bit (``fastmath`` off: no product is fused into an add);
``tests/thermometry/test_plateaus.py`` compares the two.
"""

from __future__ import annotations

import numpy as np
from numba import njit


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
