"""Equivalent degrees of freedom and confidence intervals of the Allan-type deviations.

Private helper of :mod:`hrgtc.evaluation.allan`, which re-exports its names.
The overlapping Allan deviation uses the simple edf of SP 1065 Table 5 [3]; the
modified, time and overlapping Hadamard deviations use Greenhall's edf
(SP 1065 Section 5.3.3 [3], computed as in [4]), the same numbers as
``allantools.edf_greenhall``.

References
----------
[3] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
    Publication 1065, 2008, Section 5.3 (Table 5, Eq. 45).
[4] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based
    on finite differences", Proc. 35th PTTI Meeting, 2003, Eq. (7)-(13), Tables 1-3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.settings.compensation import ONE_SIGMA  # erf(1/√2), written once

#: Power-law noise exponents α of S_y(f) ∝ f^α with a simple edf, SP 1065 Table 5 [3].
NOISE_ALPHAS = {
    2: "white PM", 1: "flicker PM", 0: "white FM", -1: "flicker FM", -2: "random walk FM",
}
#: Finite-difference order d and modified (True) of each deviation kind in Greenhall's edf [4].
GREENHALL_KINDS = {"allan": (2, False), "modified": (2, True), "time": (2, True),
                   "hadamard": (3, False)}
#: Largest number of terms of Greenhall's basic sum before his asymptotic tables take over [4].
GREENHALL_J_MAX = 100


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


def _sw(t: float, alpha: int) -> float:
    """Greenhall's sw(t), Eq. (7) of [4]."""
    if alpha in (1, -1, -3):  # t^(3 - α)·ln|t|
        return 0.0 if t == 0.0 else t ** (3 - alpha) * math.log(abs(t))
    if alpha == 2:
        return -abs(t)
    return abs(t) ** (3 - alpha)  # α = 0, -2, -4


def _sx(t: float, f: float, alpha: int) -> float:
    """Greenhall's sx(t), Eq. (8) of [4]; f = ∞ is the limit sw(t, α + 2)."""
    if math.isinf(f):
        return _sw(t, alpha + 2)
    return f * f * (2.0 * _sw(t, alpha) - _sw(t - 1.0 / f, alpha) - _sw(t + 1.0 / f, alpha))


#: Binomial weights of the d-th difference, Eq. (9) of [4].
_SZ_WEIGHTS = {1: (2.0, -1.0), 2: (6.0, -4.0, 1.0), 3: (20.0, -15.0, 6.0, -1.0)}


def _sz(t: float, f: float, alpha: int, d: int) -> float:
    """Greenhall's sz(t), Eq. (9) of [4]."""
    weights = _SZ_WEIGHTS[d]
    total = weights[0] * _sx(t, f, alpha)
    for k, w in enumerate(weights[1:], start=1):
        total += w * (_sx(t - k, f, alpha) + _sx(t + k, f, alpha))
    return total


def _basic_sum(j: float, m_terms: float, s: float, f: float, alpha: int, d: int) -> float:
    """Greenhall's basic sum, Eq. (10) of [4]."""
    total = _sz(0.0, f, alpha, d) ** 2 + (1.0 - j / m_terms) * _sz(j / s, f, alpha, d) ** 2
    for k in range(1, int(j)):
        total += 2.0 * (1.0 - k / m_terms) * _sz(k / s, f, alpha, d) ** 2
    return total


# Tables 1 and 2 of [4]: (a0, a1) by α = 2 .. -4 (rows) and d = 1, 2, 3 (columns); None where
# α + 2d <= 1. Table 3: (b0, b1) for α = 1 by d.
_TABLE1 = (((2 / 3, 1 / 3), (7 / 9, 1 / 2), (22 / 25, 2 / 3)),
           ((0.840, 0.345), (0.997, 0.616), (1.141, 0.843)),
           ((1.079, 0.368), (1.033, 0.607), (1.184, 0.848)),
           (None, (1.048, 0.534), (1.180, 0.816)),
           (None, (1.302, 0.535), (1.175, 0.777)),
           (None, None, (1.194, 0.703)),
           (None, None, (1.489, 0.702)))
_TABLE2 = (((3 / 2, 1 / 2), (35 / 18, 1.0), (231 / 100, 3 / 2)),
           ((78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)),
           ((2 / 3, 1 / 6), (2 / 3, 1 / 3), (7 / 9, 1 / 2)),
           (None, (0.852, 0.375), (0.997, 0.617)),
           (None, (1.079, 0.368), (1.033, 0.607)),
           (None, None, (1.053, 0.553)),
           (None, None, (1.302, 0.535)))
_TABLE3 = ((6.0, 4.0), (15.23, 12.0), (47.8, 40.0))


def _table(table: tuple, alpha: int, d: int) -> tuple[float, float]:
    entry = table[2 - alpha][d - 1]
    assert entry is not None  # excluded by α + 2d > 1
    return entry


def greenhall_edf(n_phase: int, m: int, noise_alpha: int = 0, d: int = 2, *,
                  overlapping: bool = True, modified: bool = False) -> float:
    """Greenhall's equivalent degrees of freedom of a finite-difference variance [4].

    The algorithm of SP 1065 Section 5.3.3 [3] (Greenhall and Riley [4], Eq. 7-13
    and Tables 1-3), as ``allantools.edf_greenhall``: the Allan (d = 2), Hadamard
    (d = 3) and their modified forms (the time variance shares the modified Allan's).

    Parameters
    ----------
    n_phase
        Number of phase points, N + 1 for N rate samples.
    m
        Averaging factor, τ = m·τ0.
    noise_alpha
        Exponent α of the dominant power-law noise S_y(f) ∝ f^α, one of :data:`NOISE_ALPHAS`.
    d
        Order of the phase difference: 1, 2 (Allan) or 3 (Hadamard).
    overlapping
        Overlapping estimator (stride τ0) rather than the non-overlapping one (stride τ).
    modified
        Modified variance (mdev, tdev: phase averaged over τ before differencing).

    Returns
    -------
    float
        Equivalent degrees of freedom; NaN for the one case [4] leaves open (white PM,
        unmodified, fewer than d + 1 independent terms: the longest τ of a short record).

    Raises
    ------
    InputError
        For an α outside :data:`NOISE_ALPHAS`, d outside 1..3, α + 2d <= 1 (the
        variance does not converge) or an m the record cannot hold.
    """
    alpha = _checked_alpha(noise_alpha, d)
    n, m = float(n_phase), int(m)
    f = 1.0 if modified else float(m)  # filter factor
    s = float(m) if overlapping else 1.0  # stride factor
    length = m / f + m * d  # length of the filter applied to the phase
    if m < 1 or n < length + 1:
        raise InputError(f"m={m} needs at least {length + 1:g} phase points, got {n_phase}")
    m_terms = 1.0 + math.floor(s * (n - length) / m)
    terms = _Terms(m=m, m_terms=m_terms, s=s, j=min(m_terms, (d + 1) * s), r=m_terms / s,
                   alpha=alpha, d=d)
    if modified:  # case 1
        inverse = _inverse_modified(terms)
    elif alpha <= 0:  # case 2
        inverse = _inverse_phase_like(terms)
    elif alpha == 1:  # case 3
        inverse = _inverse_flicker_pm(terms)
    else:  # case 4, α = 2 unmodified
        if math.ceil(terms.r) <= d:
            return math.nan
        a0 = math.comb(4 * d, 2 * d) / math.comb(2 * d, d) ** 2
        inverse = (a0 - d / (2.0 * terms.r)) / m_terms
    return 1.0 / inverse


def _checked_alpha(noise_alpha: int, d: int) -> int:
    """``noise_alpha`` as an int, once it and ``d`` are known to give a convergent edf."""
    if noise_alpha not in NOISE_ALPHAS:
        raise InputError(
            f"noise_alpha={noise_alpha!r} has no edf here; use one of {sorted(NOISE_ALPHAS)}")
    if d not in _SZ_WEIGHTS:
        raise InputError(f"d={d!r} must be 1, 2 (Allan) or 3 (Hadamard)")
    alpha = int(noise_alpha)
    if alpha + 2 * d <= 1:
        raise InputError(f"noise_alpha={alpha} with d={d}: the variance does not converge "
                         "(alpha + 2d must exceed 1); use a higher-order deviation")
    return alpha


@dataclass(frozen=True)
class _Terms:
    """What Greenhall's cases read (SP 1065 Section 5.3.3 [3]).

    ``m`` the averaging factor, ``m_terms`` the number of summands M, ``s`` the stride
    factor S, ``j = min(M, (d + 1) S)``, ``r = M / S``, ``alpha`` and ``d`` as in
    :func:`greenhall_edf`.
    """

    m: int
    m_terms: float
    s: float
    j: float
    r: float
    alpha: int
    d: int


def _inverse_modified(t: _Terms) -> float:
    """1 / edf of a modified variance, case 1 of [4] (Table 1 beyond J_max)."""
    alpha, d, r = t.alpha, t.d, t.r
    j_max = float(GREENHALL_J_MAX)
    if t.j <= j_max:
        return _basic_sum(t.j, t.m_terms, t.s, 1.0, alpha, d) / (_sz(0.0, 1.0, alpha, d) ** 2
                                                                 * t.m_terms)
    if r > d + 1:
        a0, a1 = _table(_TABLE1, alpha, d)
        return (a0 - a1 / r) / r
    return _basic_sum(j_max, j_max, j_max / r, 1.0, alpha, d) / (
        _sz(0.0, 1.0, alpha, d) ** 2 * j_max)


def _inverse_phase_like(t: _Terms) -> float:
    """1 / edf of an unmodified variance for α <= 0, case 2 of [4] (Table 2 beyond J_max)."""
    alpha, d, r, m = t.alpha, t.d, t.r, t.m
    j_max = float(GREENHALL_J_MAX)
    if t.j <= j_max:
        f_eff = float(m) if m * (d + 1) <= j_max else math.inf
        return _basic_sum(t.j, t.m_terms, t.s, f_eff, alpha, d) / (
            _sz(0.0, f_eff, alpha, d) ** 2 * t.m_terms)
    if r > d + 1:
        a0, a1 = _table(_TABLE2, alpha, d)
        return (a0 - a1 / r) / r
    return _basic_sum(j_max, j_max, j_max / r, math.inf, alpha, d) / (
        _sz(0.0, math.inf, alpha, d) ** 2 * j_max)


def _inverse_flicker_pm(t: _Terms) -> float:
    """1 / edf of an unmodified variance for α = 1, case 3 of [4] (Tables 2 and 3)."""
    d, r, m = t.d, t.r, t.m
    j_max = float(GREENHALL_J_MAX)
    if t.j <= j_max:
        return _basic_sum(t.j, t.m_terms, t.s, float(m), 1, d) / (_sz(0.0, float(m), 1, d) ** 2
                                                                  * t.m_terms)
    b0, b1 = _TABLE3[d - 1]
    if r > d + 1:
        a0, a1 = _table(_TABLE2, 1, d)
        return (a0 - a1 / r) / ((b0 + b1 * math.log(m)) ** 2 * r)
    return _basic_sum(j_max, j_max, j_max / r, j_max / r, 1, d) / (
        (b0 + b1 * math.log(m)) ** 2 * j_max)


def deviation_edf(kind: str, n_phase: int, m: int, noise_alpha: int = 0) -> float:
    """Equivalent degrees of freedom of an overlapping deviation of :data:`GREENHALL_KINDS`.

    ``"allan"``: the simple edf of SP 1065 Table 5 (:func:`equivalent_degrees_of_freedom`);
    ``"modified"`` and ``"time"``: Greenhall's edf with d = 2, modified;
    ``"hadamard"`` (overlapping): Greenhall's edf with d = 3 [3, 4].
    """
    if kind not in GREENHALL_KINDS:
        raise InputError(f"kind={kind!r} has no edf here; use one of {tuple(GREENHALL_KINDS)}")
    if kind == "allan":
        return equivalent_degrees_of_freedom(n_phase, m, noise_alpha)
    d, modified = GREENHALL_KINDS[kind]
    return greenhall_edf(n_phase, m, noise_alpha, d, overlapping=True, modified=modified)


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
