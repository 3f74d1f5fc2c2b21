"""Equivalent degrees of freedom and confidence intervals of the Allan deviation.

Private helper of :mod:`hrgtc.evaluation.allan`, which re-exports its names.

References
----------
[3] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
    Publication 1065, 2008, Section 5.3 (Table 5, Eq. 45).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from hrgtc.errors import InputError

#: Power-law noise exponents α of S_y(f) ∝ f^α with a simple edf, SP 1065 Table 5 [3].
NOISE_ALPHAS = {
    2: "white PM", 1: "flicker PM", 0: "white FM", -1: "flicker FM", -2: "random walk FM",
}
#: One-sigma confidence, erf(1/√2).
ONE_SIGMA = 0.6826894921370859


def equivalent_degrees_of_freedom(n_phase: int, m: int, noise_alpha: int = 0) -> float:
    """Simple equivalent degrees of freedom of the overlapping Allan variance, SP 1065 Table 5 [3].

    The approximations of Table 5 (after Howe, Allan and Barnes), the same as
    ``allantools.edf_simple``; Greenhall's exact edf (SP 1065 Section 5.3.3)
    differs by a few per cent.

    Parameters
    ----------
    n_phase
        Number of phase points, N + 1 for N rate samples.
    m
        Averaging factor, τ = m·τ0.
    noise_alpha
        Exponent α of the dominant power-law noise S_y(f) ∝ f^α, one of :data:`NOISE_ALPHAS`.

    Returns
    -------
    float
        Equivalent degrees of freedom.

    Raises
    ------
    InputError
        For an α outside :data:`NOISE_ALPHAS` or m outside 1 ≤ m ≤ (n_phase − 1)/2.
    """
    if noise_alpha not in NOISE_ALPHAS:
        raise InputError(
            f"noise_alpha={noise_alpha!r} has no simple edf; use one of {sorted(NOISE_ALPHAS)} "
            f"({', '.join(f'{a}: {name}' for a, name in NOISE_ALPHAS.items())})"
        )
    N, m = float(n_phase), float(m)  # SP 1065's symbols
    if not 1.0 <= m <= (N - 1.0) / 2.0:
        raise InputError(f"m={m:g} must be between 1 and (n_phase - 1)/2 = {(N - 1) / 2:g}")
    if noise_alpha == 2:
        return (N + 1.0) * (N - 2.0 * m) / (2.0 * (N - m))
    if noise_alpha == 1:
        return math.exp(math.sqrt(math.log((N - 1.0) / (2.0 * m))
                                  * math.log((2.0 * m + 1.0) * (N - 1.0) / 4.0)))
    if noise_alpha == 0:
        return (3.0 * (N - 1.0) / (2.0 * m) - 2.0 * (N - 2.0) / N) * (4.0 * m * m
                                                                   / (4.0 * m * m + 5.0))
    if noise_alpha == -1:
        if m == 1.0:
            return 2.0 * (N - 2.0) / (2.3 * N - 4.9)
        return 5.0 * N * N / (4.0 * m * (N + 3.0 * m))
    return (N - 2.0) / (m * (N - 3.0) ** 2) * ((N - 1.0) ** 2 - 3.0 * m * (N - 1.0) + 4.0 * m * m)


def confidence_interval(
    deviation: Any, edf: Any, confidence: float = ONE_SIGMA
) -> tuple[np.ndarray, np.ndarray]:
    """Chi-squared confidence interval of a deviation, SP 1065 Eq. (45) [3].

    ``σ²·edf/χ²(1 − p/2, edf) ≤ σ_true² ≤ σ²·edf/χ²(p/2, edf)`` with
    p = 1 − confidence, as ``allantools.confidence_interval``.

    Parameters
    ----------
    deviation
        Estimated deviations. [any unit]
    edf
        Equivalent degrees of freedom of each.
    confidence
        Two-sided confidence level in (0, 1), e.g. :data:`ONE_SIGMA` or 0.95.

    Returns
    -------
    lower, upper : numpy.ndarray
        Bounds of the deviation. [unit of deviation]
    """
    from scipy.stats import chi2  # scipy.stats is slow to import; only when asked

    level = float(confidence)
    if not 0.0 < level < 1.0:
        raise InputError(f"confidence must be in (0, 1), e.g. 0.683 or 0.95; got {confidence!r}")
    tail = (1.0 - level) / 2.0
    dev = np.asarray(deviation, dtype=np.float64)
    dof = np.asarray(edf, dtype=np.float64)
    lower = dev * np.sqrt(dof / chi2.ppf(1.0 - tail, dof))
    upper = dev * np.sqrt(dof / chi2.ppf(tail, dof))
    return lower, upper
