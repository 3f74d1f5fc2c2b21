"""Allan deviation of gyro rate data and the noise terms read off it.

- :func:`allan_deviation`: overlapping or normal Allan deviation of rate
  (frequency-type) data, numerically equal to ``allantools.oadev`` /
  ``allantools.adev`` with ``data_type="freq"`` [3], in O(N) per τ; with
  ``kind=`` also the modified Allan, overlapping Hadamard and time deviations
  (``allantools.mdev`` / ``ohdev`` / ``tdev``), and with ``confidence=`` the
  chi-squared confidence interval of SP 1065 Section 5.3 [3].
- :func:`equivalent_degrees_of_freedom`, :func:`greenhall_edf`,
  :func:`deviation_edf`, :func:`confidence_interval`: the simple edf of SP 1065
  Table 5 (Allan), Greenhall's edf of Section 5.3.3 (modified, time, Hadamard)
  and the chi-squared interval of Eq. (45).
- The noise terms read off the deviation (ARW, bias instability, RRW) are in
  :mod:`hrgtc.evaluation.noise`.

The statistics of :func:`allan_deviation`'s ``kind``, on the phase ``x`` of the rate
(N samples, averaging factor m): ``"allan"`` (Eq. 6-7 and 11), ``"modified"`` (mod σ,
Eq. 14: the m second differences from j to j+m−1 summed before squaring, divided by
2·n·m⁴, n = N+2−3m), ``"hadamard"`` (Eq. 20: third differences x[i+3m] − 3x[i+2m] +
3x[i+m] − x[i], divided by 6·n·m², n = N+1−3m) and ``"time"`` (Eq. 15: τ·mod σ/√3).

The overlapping Allan deviation at octave τ (``taus="octave"``, or any power-of-two
factors) runs in a small C module (``_allan_octave.c``: pairwise block sums, no phase,
one work array the size of the input, no numba import; docs/architecture.md, "The native
Allan module"). The other overlapping statistics and factor lists run in fused numba
kernels (``_allan_kernels``) that never store the phase: extra memory is ~1/32 of the
input. Both are accurate to ~1e-14 relative (the tests hold them to rational and
extended-precision sums; ``allantools`` drifts to ~1e-12 at 10^8 samples) and identical
bit for bit from run to run; the numba kernels are
5× and more faster than allantools with ``taus="all"`` on records of 10^4 to 4·10^4
samples. The first call of a numba statistic in a fresh environment compiles its
kernels (~10 s, and ~6 s more for the many-τ kernel; cached in ``__pycache__``
afterwards).

References
----------
[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
[2] IEEE Std 952-1997, "IEEE Standard Specification Format Guide and Test
    Procedure for Single-Axis Interferometric Fiber Optic Gyros", Annex C
    (Allan variance method of fiber optic gyro data reduction).
[3] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
    Publication 1065, 2008, Eq. (6)-(11); allantools, https://github.com/aewallin/allantools
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.core.records import Count, Positive, Statistic
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.evaluation._allan_edf import (
    NOISE_ALPHAS,
    ONE_SIGMA,
    confidence_interval,
    deviation_edf,
    equivalent_degrees_of_freedom,
    greenhall_edf,
)

__all__ = [
    "KINDS", "NOISE_ALPHAS", "ONE_SIGMA", "AllanResult", "allan_deviation",
    "confidence_interval", "deviation_edf", "equivalent_degrees_of_freedom", "greenhall_edf",
]

#: σ_min = 0.664·B at the flat minimum of a flicker (bias instability) floor;
#: 0.664 ≈ sqrt(2·ln 2 / π), IEEE Std 952-1997 Annex C [2].
FLICKER_FLOOR_FACTOR = 0.664
#: Seconds per hour: τ = 1 h is where ARW is read, τ = 3 h where RRW is read.
SECONDS_PER_HOUR = 3600.0
#: Default averaging times of the bias-stability table (DESIGN.md, "Metrics"). [s]
#: Named τ spacings accepted by :func:`allan_deviation` (those of allantools).
TAU_SPACINGS = ("octave", "decade", "all")
#: Deviations of :func:`allan_deviation`'s ``kind``: SP 1065 Eq. (11), (14), (20), (15) [3].
KINDS = ("allan", "modified", "hadamard", "time")

_CHUNK = 8192  # samples per block of the second-difference loop (stays in L2 cache)


# --------------------------------------------------------------------------- input checks
def _as_rate(values: Any, name: str, minimum: int = 2) -> np.ndarray:
    """``values`` as a finite 1-D float64 array of at least ``minimum`` samples."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim != 1:
        raise InputError(
            f"{name} must be 1-D (one value per sample), got shape {array.shape}; "
            "pass a single column"
        )
    if array.size < minimum:
        raise InputError(f"{name} has {array.size} samples; at least {minimum} are needed")
    if math.isfinite(float(np.sum(array))):  # a finite sum has no inf or nan
        return array
    finite = np.isfinite(array)
    if not finite.all():
        bad = np.flatnonzero(~finite)
        raise InputError(
            f"{name} has {bad.size} non-finite values (first at index {bad[0]}: "
            f"{array[bad[0]]}); remove or interpolate them first"
        )
    return array


def _check_sample_rate(sample_rate_hz: float) -> float:
    rate = float(sample_rate_hz)
    if not (math.isfinite(rate) and rate > 0.0):
        raise InputError(f"sample_rate_hz must be a positive number, got {sample_rate_hz!r}")
    return rate


def _block_length(tau_s: float, sample_rate_hz: float) -> int:
    """Samples per τ-block: τ·fs rounded to an integer (as allantools rounds τ)."""
    tau = float(tau_s)
    if not (math.isfinite(tau) and tau > 0.0):
        raise InputError(f"tau_s must be a positive number of seconds, got {tau_s!r}")
    m = round(tau * sample_rate_hz)
    if m < 1:
        raise InputError(
            f"tau_s={tau:g} s is shorter than one sample at {sample_rate_hz:g} Hz; "
            f"use tau_s >= {1.0 / sample_rate_hz:g} s"
        )
    return m


# --------------------------------------------------------------------------- Allan deviation
@dataclass(frozen=True, eq=False)
class AllanResult(records.Written):
    """Allan deviation of a rate record.

    Attributes
    ----------
    taus_s
        Averaging times, integer multiples of the sample period. [s]
    deviation
        Allan deviation at each τ, in the unit of the rate (°/h for ``rate_dph``).
    counts
        Number of second-difference terms averaged at each τ (allantools' ``ns``).
    overlapping
        True for the overlapping estimator (SP 1065 Eq. 11), False for the
        normal, non-overlapping one (Eq. 6-7).
    sample_rate_hz
        Sample rate of the data. [Hz]
    n_samples
        Number of rate samples.
    kind
        ``"allan"``, ``"modified"``, ``"hadamard"`` or ``"time"`` (see :data:`KINDS`).
        The time deviation is in the unit of the rate times seconds.
    lower, upper
        Confidence interval of the deviation at each τ, or None. [unit of deviation]
    confidence
        Confidence level of ``lower`` / ``upper`` (e.g. 0.683), or None.
    segments
        Contiguous segments the deviation was pooled over (1: one record; see
        :mod:`hrgtc.evaluation.allan_segments`). No difference reaches across a gap and
        ``counts`` is the sum of the segments' terms.
    edf
        Equivalent degrees of freedom of each τ behind ``lower`` / ``upper``, or None.
    """

    taus_s: records.Array[float]
    deviation: records.Array[Statistic]
    counts: records.Array[Count]
    overlapping: bool
    sample_rate_hz: Positive
    n_samples: Count
    kind: str = "allan"
    lower: records.Array[Statistic] | None = None
    upper: records.Array[Statistic] | None = None
    confidence: float | None = None
    segments: int = 1
    edf: records.Array[Statistic] | None = None

    def __post_init__(self) -> None:
        for name, dtype in (
            ("taus_s", np.float64), ("deviation", np.float64), ("counts", int),
            ("lower", np.float64), ("upper", np.float64), ("edf", np.float64),
        ):
            if getattr(self, name) is None:
                continue
            array = np.array(getattr(self, name), dtype=dtype)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    @property
    def blocks(self) -> np.ndarray:
        """Number of whole, non-overlapping τ-blocks in the record at each τ."""
        m = np.rint(self.taus_s * self.sample_rate_hz).astype(np.int64)
        return self.n_samples // np.maximum(m, 1)

    def summary(self) -> Summary:
        """The curve as a table: τ, deviation, the terms averaged and (if any) the
        confidence interval of each point (its text: the aligned table)."""
        spacing = "overlapping" if self.overlapping else "normal (non-overlapping)"
        name = {"allan": "Allan", "modified": "modified Allan", "hadamard": "Hadamard",
                "time": "time"}.get(self.kind, self.kind)
        ci = self.lower is not None and self.upper is not None
        header = f"{'tau [s]':>12}  {'deviation':>12}  {'terms':>10}"
        if ci:
            header += f"  {'lower':>12}  {'upper':>12}   ({self.confidence:.3g} confidence)"
        title = (f"{name} deviation, {spacing}; {self.n_samples} samples at "
                 f"{self.sample_rate_hz:g} Hz"
                 + (f", pooled within {self.segments} segments" if self.segments > 1 else ""))
        unit = "°/h·s" if self.kind == "time" else "°/h"
        cells: list[Figure] = []
        layout = [escape(title), escape(header)]
        for k, (t, d, c) in enumerate(zip(self.taus_s, self.deviation, self.counts, strict=True)):
            interval = (float(self.lower[k]), float(self.upper[k])) if ci else None
            cells += [Figure(f"taus_s[{k}]", f"τ {k + 1}", float(t), "s", row=str(k),
                             column="tau"),
                      Figure(f"deviation[{k}]", f"deviation at τ {float(t):g} s", float(d),
                             unit, interval,
                             f"{self.confidence:.3g} CI" if ci else "", row=str(k),
                             column="deviation", definition=f"{name} deviation of the rate "
                             f"at τ = {float(t):g} s."),
                      Figure(f"counts[{k}]", f"terms at τ {float(t):g} s", int(c), row=str(k),
                             column="terms", definition="Terms averaged into the point.")]
            line = f"{{taus_s[{k}]:12.6g}}  {{deviation[{k}]:12.6g}}  {{counts[{k}]:10d}}"
            if ci:
                cells += [Figure(f"lower[{k}]", f"lower at τ {float(t):g} s", interval[0],
                                 unit, row=str(k), column="lower"),
                          Figure(f"upper[{k}]", f"upper at τ {float(t):g} s", interval[1],
                                 unit, row=str(k), column="upper")]
                line += f"  {{lower[{k}]:12.6g}}  {{upper[{k}]:12.6g}}"
            layout.append(line)
        return Summary(title, (("curve", tuple(cells)),), layout=tuple(layout))



def _averaging_factors(taus: str | Sequence[float] | np.ndarray, n: int, fs: float) -> np.ndarray:
    """Integer averaging factors m (τ = m / fs) the way ``allantools.tau_generator`` makes them.

    ``n`` is the number of phase points (rate samples + 1).
    """
    if isinstance(taus, str):
        if taus == "octave":
            factors = 2.0 ** np.arange(math.floor(math.log2(n)) + 1)
        elif taus == "decade":
            decades = 10.0 ** np.arange(math.floor(math.log10(n)) + 1)
            factors = np.outer(decades, [1.0, 2.0, 4.0]).ravel()
        elif taus == "all":
            factors = np.arange(1.0, n + 1.0)
        else:
            raise InputError(
                f"taus={taus!r} is not a known spacing; use one of {TAU_SPACINGS} "
                "or an array of averaging times in seconds"
            )
    else:
        taus_s = np.asarray(taus, dtype=np.float64).ravel()
        if taus_s.size == 0 or not np.all(np.isfinite(taus_s)):
            raise InputError(f"taus must be finite averaging times in seconds, got {taus!r}")
        factors = np.round(taus_s * fs)
    factors = factors[(factors > 0) & (factors < n)]
    return np.unique(factors).astype(np.int64)


def _sum_squared_second_differences(phase: np.ndarray, m: int, buffer: np.ndarray) -> float:
    """Σ (x[i+2m] − 2x[i+m] + x[i])² over all i, block-wise so temporaries stay in cache."""
    count = phase.size - 2 * m
    total = 0.0
    for start in range(0, count, buffer.size):
        stop = min(start + buffer.size, count)
        work = buffer[: stop - start]
        np.subtract(phase[start + 2 * m : stop + 2 * m], phase[start + m : stop + m], out=work)
        work -= phase[start + m : stop + m]
        work += phase[start:stop]
        total += float(np.einsum("i,i->", work, work))  # no BLAS: no thread start-up
    return total


#: Terms of each overlapping statistic: phase points N+1 minus its span, SP 1065 [3].
_TERMS = {"allan": (1, 2), "hadamard": (1, 3), "modified": (2, 3), "time": (2, 3)}


def _overlapping_deviation(
    values: np.ndarray, kind: str, factors: np.ndarray, fs: float,
    progress: Progress | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Kept factors, deviations and term counts of an overlapping statistic."""
    from hrgtc.evaluation import _allan_sums

    extra, span = _TERMS[kind]
    counts = values.size + extra - span * factors
    total = factors.size
    kept = factors[counts > 1]  # allantools drops τ with fewer than two terms
    skipped = total - kept.size

    def report(done: float, _total: float) -> None:
        if progress is not None:
            progress(done + skipped, float(total))

    if progress is not None:
        for done in range(1, skipped + 1):
            progress(float(done), float(total))
    sums = _allan_sums.sums_of_squares(values, "modified" if kind == "time" else kind, kept,
                                       report)
    counts = counts[counts > 1]
    return kept, deviation_from_sums(kind, sums, counts, kept, fs), counts


def deviation_from_sums(kind: str, sums: np.ndarray, counts: np.ndarray, factors: np.ndarray,
                        fs: float) -> np.ndarray:
    """The deviation of ``kind`` from its sums of squared stencil terms and their counts.

    ``sums`` are those of :func:`_allan_sums.sums_of_squares` (of ``"modified"`` for
    the time deviation); a pooled sum over segments divided by its pooled count gives the
    pooled deviation.
    """
    m = np.asarray(factors, dtype=np.float64)
    counts = np.asarray(counts, dtype=np.float64)
    if kind == "allan":  # SP 1065 Eq. (11) (and Eq. 6-7: the same on every m-th point)
        return np.sqrt(sums / (2.0 * counts)) / m
    if kind == "hadamard":  # Eq. (20)
        return np.sqrt(sums / (6.0 * counts)) / m
    deviation = np.sqrt(sums / (2.0 * counts)) / (m * m)  # Eq. (14)
    if kind == "time":  # Eq. (15): τ·mod σ/√3
        deviation = deviation * (m / fs) / math.sqrt(3.0)
    return deviation


def _normal_allan(
    values: np.ndarray, factors: np.ndarray,
    progress: Progress | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Non-overlapping Allan deviation, SP 1065 Eq. (6)-(7), on the float64 phase."""
    n = values.size
    phase = np.empty(n + 1, dtype=np.float64)
    phase[0] = 0.0
    np.subtract(values, values.mean(), out=phase[1:])
    np.cumsum(phase[1:], out=phase[1:])
    buffer = np.empty(_CHUNK, dtype=np.float64)
    kept_m: list[int] = []
    deviations: list[float] = []
    counts: list[int] = []
    for done, m in enumerate(factors.tolist(), start=1):
        sub = np.ascontiguousarray(phase[::m])
        count = sub.size - 2
        if count > 1:
            total = _sum_squared_second_differences(sub, 1, buffer)
            kept_m.append(m)
            counts.append(count)
            deviations.append(math.sqrt(total / (2.0 * count)) / m)
        if progress is not None:
            progress(float(done), float(factors.size))
    return np.asarray(kept_m, dtype=np.int64), np.asarray(deviations), np.asarray(counts)


def allan_deviation(rate: Any, sample_rate_hz: float,
                    taus: str | Sequence[float] | np.ndarray = "octave", overlapping: bool = True,
                    *, kind: str = "allan", confidence: float | None = None,
                    noise_alpha: int = 0, progress: Progress | None = None) -> AllanResult:
    """Allan deviation of rate (frequency-type) data, NIST SP 1065 Eq. (6)-(11) [3].

    The rate, mean removed, is summed into an angle ("phase") series
    ``x[0] = 0, x[k] = Σ_{i<k} (rate[i] − mean)`` (``allantools.frequency2phase``);
    then for each averaging factor m

        σ²(m·τ0) = Σ_i (x[i+2m] − 2x[i+m] + x[i])² / (2·n·m²),

    with i running over every sample (``overlapping=True``, Eq. 11, n = N+1−2m
    terms) or every m-th (``overlapping=False``, Eq. 6-7, n = floor(N/m)−1
    terms). As in allantools, τ with fewer than two terms are dropped.

    ``kind`` selects another overlapping statistic of the same phase (the formulas, and
    the speed, memory and accuracy of the kernels: module docstring).

    Parameters
    ----------
    rate
        Rate samples, e.g. gyro output. [°/h] (any unit; the deviation has the same)
    sample_rate_hz
        Sample rate. [Hz]
    taus
        ``"octave"`` (m = 1, 2, 4, ...), ``"decade"`` (m = 1, 2, 4, 10, 20, 40, ...),
        ``"all"`` (every m; O(N²), for short records only) or an array of
        averaging times, rounded to integer multiples of the sample period and
        de-duplicated as allantools does. [s]
    overlapping
        Overlapping (default) or normal Allan deviation; only ``kind="allan"``
        has a normal form here.
    kind
        One of :data:`KINDS`.
    confidence
        If given (e.g. :data:`ONE_SIGMA`), the result carries the chi-squared
        confidence interval of each τ (:func:`confidence_interval`), with the edf of
        :func:`deviation_edf` (SP 1065 Table 5 for Allan, Greenhall's for the others);
        for the normal deviation, that of the ``n // m`` τ-means at m = 1.
    noise_alpha
        Power-law exponent α of the dominant noise for the edf, one of
        :data:`NOISE_ALPHAS`; 0 (white FM) is white rate noise, i.e. angle random walk.
    progress
        Optional callback ``progress(done, total)`` called after each τ.

    Returns
    -------
    AllanResult
        Averaging times, deviations, term counts and optional confidence interval.

    Raises
    ------
    InputError
        Non-finite or non-1-D input, fewer than 3 samples, an unknown spacing or
        kind, a normal (non-overlapping) deviation other than Allan's, a
        confidence outside (0, 1), or no τ in ``taus`` that the record can resolve.

    Examples
    --------
    >>> result = allan_deviation([1.0, 2.0, 1.0, 2.0, 1.0, 2.0, 1.0], sample_rate_hz=1.0)
    >>> [round(float(d), 6) for d in result.deviation]  # 1/sqrt(2) at 1 s, 0 at 2 s
    [0.707107, 0.0]
    """
    fs = _check_sample_rate(sample_rate_hz)
    _check_kind(kind, overlapping)
    values = _as_rate(rate, "rate", minimum=3)
    n = values.size
    factors = _averaging_factors(taus, n + 1, fs)
    kept, deviation, counts = (_overlapping_deviation(values, kind, factors, fs, progress)
                               if overlapping else _normal_allan(values, factors, progress))
    if kept.size == 0:
        raise _no_tau_fits(taus, n, fs)
    edf = None if confidence is None else _edf(kind, overlapping, n, kept, noise_alpha)
    lower, upper = (None, None) if edf is None else confidence_interval(deviation, edf,
                                                                        confidence)
    return AllanResult(taus_s=kept.astype(np.float64) / fs, deviation=deviation, counts=counts,
                       overlapping=overlapping, sample_rate_hz=fs, n_samples=n, kind=kind,
                       lower=lower, upper=upper, edf=edf,
                       confidence=None if confidence is None else float(confidence))


def _no_tau_fits(taus: Any, n: int, fs: float) -> InputError:
    """The error of ``taus`` of which none fits ``n`` samples at ``fs`` Hz with 2 terms."""
    return InputError(
        f"no averaging time in taus={taus!r} fits a record of {n} samples at {fs:g} Hz "
        f"with at least 2 terms; use taus between {1.0 / fs:g} s and {(n - 1) / (2 * fs):g} s"
    )


def _check_kind(kind: str, overlapping: bool) -> None:
    """Refuse an unknown ``kind`` and a normal (non-overlapping) form other than Allan's."""
    if kind not in KINDS:
        raise InputError(f"kind={kind!r} is not a known deviation; use one of {KINDS}")
    if not overlapping and kind != "allan":
        raise InputError(
            f"kind={kind!r} is computed in its overlapping form only; pass overlapping=True"
        )


def _edf(kind: str, overlapping: bool, n: int, kept: np.ndarray, noise_alpha: int,
         ) -> np.ndarray:
    """Equivalent degrees of freedom at each kept averaging factor of ``n`` rate samples.

    Non-overlapping: the τ-means form a record of n // m samples read at m = 1, where the
    overlapping and the normal estimator coincide.
    """
    return np.array([deviation_edf(kind, n + 1, int(m), noise_alpha) if overlapping
                     else equivalent_degrees_of_freedom(n // m + 1, 1, noise_alpha)
                     for m in kept])
