"""The soak plateaus' block statistics (:mod:`hrgtc.thermometry.plateaus`), in C.

One pass over a soak gives, per block, what five ``numpy.bincount`` calls gave (one array
pass each, and a temporary per product): the samples, and the sums of the time, of the
frequency less a reference, of its square and of the chamber temperature. ``bincount``
adds its weights to their bins in the order of the samples, as this loop does, so the sums
are the same bit for bit; ``tests/thermometry/test_plateaus.py`` compares the two.

The loops are the compiled module ``_plateau_native`` (``_plateau_native.c``, built by
``pip install -e .``); they were numba kernels, kept as the reference of
``tests/thermometry/test_plateau_native.py``, which checks the two agree bit for bit.
numba is not imported: its import and start cost a command more than these passes
(docs/architecture.md, "The native kernels"). When the module is missing this raises
``ImportError`` saying how to build it.
"""

from __future__ import annotations

import numpy as np

from hrgtc.core.native import native_module

_native = native_module("hrgtc.thermometry._plateau_native", "plateau statistics")

#: A quotient this close to an integer (relative) takes numpy's own floor division.
_NEAR = 1e-9


def _floor_divide(a: float, b: float) -> float:
    """``numpy.floor_divide(a, b)`` for a finite ``a`` and ``b != 0``: numpy's
    ``npy_divmod`` (the exact ``fmod``, then the quotient rounded to its integer)."""
    return _native.floor_divide(a, b)


def block_index(time_s: np.ndarray, block_s: float) -> np.ndarray:
    """``numpy.floor_divide(time_s - time_s[0], block_s).astype(numpy.intp)`` of finite,
    increasing times (contiguous float64) and a positive ``block_s``, without numpy's
    ``fmod`` per sample: ``floor(d / block_s)`` where the rounded quotient is not within
    :data:`_NEAR` of an integer (rounding is monotonic and integers are representable, so
    there both are the exact quotient's floor), numpy's own arithmetic where it is
    (``floor_divide(1.0, 0.1)`` is 9, ``floor(1.0 / 0.1)`` 10)."""
    out = np.empty(time_s.size, dtype=np.intp)
    _native.block_index(time_s, block_s, out)
    return out


def block_sums(block: np.ndarray, time_s: np.ndarray, freq_hz: np.ndarray, ref_hz: float,
               chamber_c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                               np.ndarray, np.ndarray]:
    """Per block index of ``block`` (intp, non-negative, ``block.max() + 1`` bins): the
    count and the sums of ``time_s``, ``freq_hz − ref_hz``, its square and ``chamber_c``
    (contiguous float64 of ``block``'s length)."""
    bins = int(block.max()) + 1 if block.size else 0
    count = np.zeros(bins, dtype=np.int64)
    sums = [np.zeros(bins) for _ in range(4)]
    _native.block_sums(block, time_s, freq_hz, ref_hz, chamber_c, count, *sums)
    return count, *sums
