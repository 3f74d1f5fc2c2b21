"""Sums of squared stencil terms of the overlapping statistics: which kernel computes them.

Private to :mod:`hrgtc.evaluation.allan` and :mod:`hrgtc.evaluation.allan_segments`.

- The overlapping Allan sums at power-of-two averaging factors (``taus="octave"``, the
  common case) come from the compiled module ``_allan_octave`` (``_allan_octave.c``,
  pairwise doubling, no phase array); numba is not imported.
- Every other statistic or factor list goes to the numba kernels (``_allan_kernels``),
  imported on first use.

The compiled module is built by ``pip install -e .`` (``make .venv/.installed``); when it
is missing, the octave path raises ``ImportError`` saying so rather than falling back to
numba unnoticed (docs/architecture.md, "The native Allan module").
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from hrgtc.core.native import native_module


def octave_levels(factors: np.ndarray) -> int | None:
    """Number of octave levels (m = 1, 2, ..., 2^(levels-1)) that cover ``factors``,
    or None if one of them is not a power of two."""
    factors = np.asarray(factors, dtype=np.int64)
    if factors.size == 0 or np.any(factors < 1) or np.any(factors & (factors - 1)):
        return None
    return int(factors.max()).bit_length()


def octave_sums(y: np.ndarray, factors: np.ndarray, levels: int) -> np.ndarray:
    """Σ_i (X[i+2m] − 2X[i+m] + X[i])² at each factor m (powers of two) of ``factors``."""
    _allan_octave = native_module("hrgtc.evaluation._allan_octave", "Allan sums")
    mean = float(np.mean(y))  # pairwise, as allantools' frequency2phase and the kernels
    every = np.array(_allan_octave.octave_sums(y, mean, levels))
    return every[np.log2(factors).astype(np.int64)]


def sums_of_squares(y: np.ndarray, kind: str, factors: np.ndarray,
                    progress: Callable[[float, float], None] | None = None) -> np.ndarray:
    """Sum of squared stencil terms of ``kind`` at each averaging factor (see
    ``_allan_kernels.sums_of_squares``, same arguments and result)."""
    y = np.ascontiguousarray(y, dtype=np.float64)
    factors = np.asarray(factors, dtype=np.int64)
    levels = octave_levels(factors) if kind == "allan" else None
    if levels is None:
        from hrgtc.evaluation import _allan_kernels  # numba is imported on first use only

        return _allan_kernels.sums_of_squares(y, kind, factors, progress)
    sums = octave_sums(y, factors, levels)
    if progress is not None:
        for done in range(1, factors.size + 1):
            progress(float(done), float(factors.size))
    return sums
