"""Deviations of a recording of contiguous segments, pooled within segments, never across a gap.

A logger that pauses (bursts, dropouts, restarts) gives a rate record of contiguous
segments (:mod:`hrgtc.core.timeline`). A second difference that reaches across a gap
differences two samples that are not τ apart, and a step of the offset between two
segments (a restart, a new orientation) would read as a huge deviation at every τ
that spans it. :func:`pooled_deviation` sums each statistic's squared stencil terms
(SP 1065 Eq. 6-20 [3]) inside every segment long enough for them and divides by the
total number of terms:

    σ²_pooled(τ) = Σ_k S_k(τ) / (c·Σ_k n_k(τ)),

with S_k the sum of squared terms of segment k, n_k their number and c the
statistic's normalisation (2m² for the Allan variance, ...). This is the variance
of every term the segments hold, each weighted alike, the way allantools' ``oadev``
weights the terms of one record; a τ whose terms fit in no segment is left out.

Its equivalent degrees of freedom (:func:`pooled_edf`) combine the segments' own
edfs (SP 1065 Table 5 or Greenhall's, as for one record) by Satterthwaite's
approximation for a weighted sum of independent scaled χ² variables [5]:

    edf = (Σ_k n_k)² / Σ_k (n_k² / edf_k),

exact in distribution when every segment sees the same noise and the segments are
independent (white noise; for flicker and random-walk noise the segments of one run
are correlated and the edf is an upper bound). One segment gives its own edf; k equal
segments k times it. A segment holding a single term contributes one degree of
freedom (one Gaussian term is χ² with one).

[3] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special Publication
    1065, 2008, Sections 5.2-5.3.
[5] F. E. Satterthwaite, "An approximate distribution of estimates of variance
    components", Biometrics Bulletin 2(6), 110-114, 1946.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.evaluation._allan_edf import (
    NOISE_ALPHAS,
    confidence_interval,
    deviation_edf,
    equivalent_degrees_of_freedom,
)
from hrgtc.evaluation.allan import (
    _CHUNK,
    AllanResult,
    _as_rate,
    _averaging_factors,
    _check_kind,
    _check_sample_rate,
    _sum_squared_second_differences,
    allan_deviation,
    deviation_from_sums,
)

__all__ = ["pooled_deviation", "pooled_edf", "segment_edges", "segment_terms"]

#: Segments shorter than this are summed in numpy (a numba kernel's thread start-up costs
#: ~10 ms a call, a burst file has thousands of segments); rounding stays below ~1e-11.
SMALL_SEGMENT = 4096


def segment_terms(kind: str, overlapping: bool, length: Any, m: Any) -> np.ndarray:
    """Number of stencil terms of ``kind`` in a segment of ``length`` rate samples at factor m.

    Overlapping Allan N + 1 − 2m, Hadamard N + 1 − 3m, modified (and time) N + 2 − 3m,
    normal (non-overlapping) Allan floor(N/m) − 1 (SP 1065 [3]); never below zero.
    """
    n = np.asarray(length, dtype=np.int64)
    m = np.asarray(m, dtype=np.int64)
    if not overlapping:
        terms = n // np.maximum(m, 1) - 1
    elif kind == "allan":
        terms = n + 1 - 2 * m
    elif kind == "hadamard":
        terms = n + 1 - 3 * m
    else:
        terms = n + 2 - 3 * m
    return np.maximum(terms, 0)


def segment_edges(breaks: Sequence[int], n: int) -> list[int]:
    """``[0, *breaks, n]``: the edges of the segments of a record of ``n`` samples.

    ``breaks`` are the indices where a segment starts after a gap; 0, ``n`` and
    repeats are ignored.

    Raises
    ------
    InputError
        A break outside 0..n or not an integer.
    """
    cuts: set[int] = set()
    for b in breaks:
        if int(b) != b or not 0 <= b <= n:
            raise InputError(f"breaks must be sample indices in 0..{n}, got {b!r}")
        if 0 < b < n:
            cuts.add(int(b))
    return [0, *sorted(cuts), int(n)]


@functools.lru_cache(maxsize=8192)
def _segment_edf(kind: str, overlapping: bool, length: int, m: int, noise_alpha: int) -> float:
    """The edf of one segment's terms (SP 1065 Table 5 or Greenhall), 1 for a single term."""
    terms = int(segment_terms(kind, overlapping, length, m))
    if terms <= 1:
        return float(terms)  # one Gaussian term: χ² with one degree of freedom
    try:
        if overlapping:
            edf = deviation_edf(kind, length + 1, m, noise_alpha)
        else:  # the τ-means read at m = 1, as allan_deviation does
            edf = equivalent_degrees_of_freedom(length // m + 1, 1, noise_alpha)
    except InputError:  # a segment too short for the formula: its terms as a lower bound
        return 1.0
    return edf if math.isfinite(edf) and edf > 0.0 else 1.0


def pooled_edf(kind: str, lengths: Sequence[int], m: int, noise_alpha: int = 0,
               overlapping: bool = True) -> float:
    """Equivalent degrees of freedom of a deviation pooled within segments (module docstring).

    Parameters
    ----------
    kind
        One of :data:`~hrgtc.evaluation.allan.KINDS`.
    lengths
        Rate samples of each segment.
    m
        Averaging factor, τ = m·τ0.
    noise_alpha
        Exponent α of the dominant power-law noise, one of :data:`NOISE_ALPHAS`.
    overlapping
        The overlapping estimator (False: the normal Allan deviation).

    Returns
    -------
    float
        ``(Σ n_k)² / Σ (n_k² / edf_k)`` over the segments with terms; NaN when none has.
    """
    if noise_alpha not in NOISE_ALPHAS:
        raise InputError(f"noise_alpha={noise_alpha!r} has no edf; use one of "
                         f"{sorted(NOISE_ALPHAS)}")
    sizes, repeats = np.unique(np.asarray(lengths, dtype=np.int64), return_counts=True)
    total = 0.0
    spread = 0.0
    for length, count in zip(sizes.tolist(), repeats.tolist(), strict=True):
        terms = float(segment_terms(kind, overlapping, length, m))
        if terms < 1.0:
            continue
        total += count * terms
        spread += count * terms * terms / _segment_edf(kind, overlapping, length, int(m),
                                                      int(noise_alpha))
    return total * total / spread if spread > 0.0 else math.nan


def _segment_sums(values: np.ndarray, kind: str, overlapping: bool,
                  factors: np.ndarray) -> np.ndarray:
    """Sums of squared stencil terms of one segment at each factor (each with a term)."""
    if overlapping and values.size < SMALL_SEGMENT:  # numpy: no kernel start-up per burst
        phase = np.zeros(values.size + 1)
        np.cumsum(values - values.mean(), out=phase[1:])
        if kind in ("modified", "time"):  # m second differences summed: the phase's sum
            phase = np.concatenate([[0.0], np.cumsum(phase)])
        out = np.empty(factors.size)
        for k, m in enumerate(factors.tolist()):
            if kind == "allan":
                term = phase[2 * m:] - 2.0 * phase[m:phase.size - m] + phase[:phase.size - 2 * m]
            else:  # third difference: Hadamard of the phase, modified of its sum
                term = (phase[3 * m:] - 3.0 * phase[2 * m:phase.size - m]
                        + 3.0 * phase[m:phase.size - 2 * m] - phase[:phase.size - 3 * m])
            out[k] = float(np.dot(term, term))
        return out
    if overlapping:
        from hrgtc.evaluation import _allan_sums

        return _allan_sums.sums_of_squares(values, "modified" if kind == "time" else kind,
                                           factors)
    phase = np.empty(values.size + 1)
    phase[0] = 0.0
    np.cumsum(values - values.mean(), out=phase[1:])
    buffer = np.empty(_CHUNK)
    return np.array([_sum_squared_second_differences(np.ascontiguousarray(phase[::m]), 1,
                                                     buffer) for m in factors.tolist()])


def _pooled_sums(values: np.ndarray, edges: Sequence[int], kind: str, overlapping: bool,
                 factors: np.ndarray, progress: Progress | None,
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The sums of squared stencil terms at each factor, and their numbers, over the
    segments ``values[edges[i]:edges[i + 1]]``; ``progress`` after each segment."""
    sums = np.zeros(factors.size)
    counts = np.zeros(factors.size, dtype=np.int64)
    pieces = len(edges) - 1
    for done, (a, b) in enumerate(itertools.pairwise(edges), start=1):
        terms = segment_terms(kind, overlapping, b - a, factors)
        has = terms >= 1
        if has.any():
            sums[has] += _segment_sums(values[a:b], kind, overlapping, factors[has])
            counts[has] += terms[has]
        if progress is not None:
            progress(float(done), float(pieces))
    return sums, counts


def pooled_deviation(
    rate: Any,
    sample_rate_hz: float,
    breaks: Sequence[int] = (),
    taus: str | Sequence[float] | np.ndarray = "octave",
    overlapping: bool = True,
    *,
    kind: str = "allan",
    confidence: float | None = None,
    noise_alpha: int = 0,
    progress: Progress | None = None,
) -> AllanResult:
    """A deviation of :func:`~hrgtc.evaluation.allan.allan_deviation` pooled within segments.

    No stencil term reaches across a gap (module docstring); without ``breaks`` the
    result is :func:`~hrgtc.evaluation.allan.allan_deviation`'s (to rounding).

    Parameters
    ----------
    rate
        Rate samples of every segment, in order. [°/h] (any unit)
    sample_rate_hz
        Sample rate inside the segments. [Hz]
    breaks
        Indices in ``rate`` where a segment starts after a gap.
    taus, overlapping, kind, noise_alpha, progress
        As for :func:`~hrgtc.evaluation.allan.allan_deviation`; ``taus`` are read
        against the longest segment.
    confidence
        If given, the chi-squared interval of each τ with :func:`pooled_edf`.

    Returns
    -------
    AllanResult
        ``counts`` the terms summed over the segments, ``segments`` their number and
        ``edf`` the pooled edf behind the interval.

    Raises
    ------
    InputError
        As :func:`~hrgtc.evaluation.allan.allan_deviation`, or when no τ has two terms
        in the segments.

    Examples
    --------
    >>> import numpy as np
    >>> rate = np.r_[[1.0, 2.0] * 4, [101.0, 102.0] * 4]  # a step of 100 at the gap
    >>> [float(d) for d in pooled_deviation(rate, 1.0, breaks=[8], taus=[1.0]).deviation]
    [0.7071067811865476]
    """
    fs = _check_sample_rate(sample_rate_hz)
    _check_kind(kind, overlapping)
    values = _as_rate(rate, "rate", minimum=3)
    edges = segment_edges(breaks, values.size)
    if len(edges) == 2 and values.size >= SMALL_SEGMENT:
        return allan_deviation(values, fs, taus, overlapping, kind=kind, confidence=confidence,
                               noise_alpha=noise_alpha, progress=progress)
    lengths = np.diff(edges)
    factors = _averaging_factors(taus, int(lengths.max()) + 1, fs)
    sums, counts = _pooled_sums(values, edges, kind, overlapping, factors, progress)
    pieces = len(edges) - 1
    keep = counts > 1
    if not keep.any():
        raise InputError(
            f"no averaging time in taus={taus!r} has two terms in the {pieces} segments "
            f"(the longest holds {int(lengths.max())} samples at {fs:g} Hz); no difference "
            "is taken across a gap")
    factors, counts = factors[keep], counts[keep]
    deviation = deviation_from_sums(kind, sums[keep], counts, factors, fs)
    lower = upper = edf = None
    if confidence is not None:
        edf = np.array([pooled_edf(kind, lengths.tolist(), int(m), noise_alpha, overlapping)
                        for m in factors])
        lower, upper = confidence_interval(deviation, edf, confidence)
    return AllanResult(
        taus_s=factors.astype(np.float64) / fs, deviation=deviation, counts=counts,
        overlapping=overlapping, sample_rate_hz=fs, n_samples=int(values.size), kind=kind,
        lower=lower, upper=upper, confidence=None if confidence is None else float(confidence),
        segments=int(np.count_nonzero(lengths)), edf=edf)
