"""The noise model of a gyro: σ²(τ) = Σ C_k τ^k fitted to the Allan variance, with intervals.

The Allan variance of a sum of independent power-law noises is the sum of theirs
(IEEE Std 952-1997 Annex C; IEEE Std 1554-2005). For a rate in °/h and τ in s:

==================  ===  ===============  ==================================  ==========
term                k    σ²(τ)            the term from C_k                   unit
==================  ===  ===============  ==================================  ==========
quantization        −2   3 Q² / τ²        Q = √(C/3)                          arcsec
angle random walk   −1   N² / τ           N = √C / 60                         °/√h
bias instability     0   (2 ln 2/π) B²    B = √(C π / (2 ln 2)) = √C / 0.664  °/h
rate random walk    +1   K² τ / 3         K = 60 √(3 C)                       °/h/√h
rate ramp           +2   R² τ² / 2        R = 3600 √(2 C)                     °/h/h
==================  ===  ===============  ==================================  ==========

(docs/noise-model.md derives each factor.) The fit, :func:`fit_noise_model`:

1. **Pilot.** Non-negative least squares (:func:`scipy.optimize.nnls`) of the relative
   residuals, each τ weighted by its equivalent degrees of freedom, over the τ with at
   least ``min_blocks`` whole τ-blocks.
2. **Covariance.** The points of an overlapping Allan variance share their data: their
   errors are correlated, and χ² weights of single points say nothing of how the terms vary
   together. ``bootstrap`` records of the recording's length (its segments cut apart as in
   :mod:`hrgtc.evaluation.allan_segments`: gap-aware) are drawn from the pilot model, each
   term an independent power-law noise (white angle, white rate, Kasdin-Walter flicker rate
   [1], random-walk rate, a ramp of random sign), and the covariance of their relative Allan
   variances is the weight of a generalised least squares (GLS) fit with C_k ≥ 0.
3. **Terms.** Unless the caller names them, the terms are those of the subset with the
   smallest GLS χ² + 2·(terms) (Akaike's criterion): a term the data cannot tell apart from
   its neighbours (a rate ramp against a rate random walk over a short record) is left out
   instead of sharing the other's variance.
4. **Intervals.** A parametric bootstrap: records drawn from the *fitted* model, each fitted
   the same way (the term selection included); with q the quantiles of the refitted terms
   θ* at (1 ∓ confidence)/2, the interval is (θ̂²/q_high, θ̂²/q_low): the ratio θ̂/θ as the
   pivot (:func:`_ratio_interval`; ∞ above where the refits leave the term out too often).

Coverage over 200 seeds of allantools' Kasdin noise, and what is not claimed (terms chosen by
AIC on a short record): docs/noise-model.md.

[1] N. J. Kasdin, T. Walter, "Discrete simulation of power law noise", Proc. 1992 IEEE
    Frequency Control Symposium, 274-283. doi:10.1109/FREQ.1992.270003
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.summary import Figure, Summary
from hrgtc.evaluation.allan import AllanResult

__all__ = ["TERMS", "NoiseModel", "fit_noise_model", "pooled_avar", "unit_noises"]

_FLICKER = 2.0 * math.log(2.0) / math.pi  # σ² of flicker rate noise per B² (0.664²)

#: term -> (power k of τ, unit, C_k -> term, definition). IEEE Std 952-1997 Annex C.
TERMS: dict[str, tuple[int, str, Callable[[float], float], str]] = {
    "quantization": (-2, "arcsec", lambda c: math.sqrt(c / 3.0),
                     "Angle quantization Q: σ²(τ) = 3 Q²/τ² (C_-2 = 3 Q²)."),
    "angle_random_walk": (-1, "°/√h", lambda c: math.sqrt(c) / 60.0,
                          "Angle random walk N: σ²(τ) = N²/τ, σ(1 h)·√h; white rate noise of "
                          "two-sided PSD N²."),
    "bias_instability": (0, "°/h", lambda c: math.sqrt(c / _FLICKER),
                         "Bias instability B: the flat of σ(τ) is 0.664 B "
                         "(σ² = (2 ln 2/π) B²); flicker rate noise of PSD B²/(2π f)."),
    "rate_random_walk": (1, "°/h/√h", lambda c: 60.0 * math.sqrt(3.0 * c),
                         "Rate random walk K: σ²(τ) = K² τ/3; a rate whose PSD is "
                         "K²/(2π f)²."),
    "rate_ramp": (2, "°/h/h", lambda c: 3600.0 * math.sqrt(2.0 * c),
                  "Rate ramp R: σ²(τ) = R² τ²/2; a rate changing at R."),
}
_NAMES = tuple(TERMS)


@dataclass(frozen=True)
class NoiseModel:
    """The fitted noise model (:func:`fit_noise_model`).

    Attributes
    ----------
    coefficients
        C_k of each of the five terms, 0 for a term not fitted. [(°/h)² s^-k]
    terms
        Each term in its unit (:data:`TERMS`).
    intervals
        Each fitted term's bootstrap interval at ``confidence`` in its unit (None: not
        fitted, or no bootstrap).
    fitted
        The terms in the model (named by the caller or selected).
    confidence, bootstrap
        Level of the intervals and the number of bootstrap records.
    taus_s
        The τ fitted. [s]
    chi2
        The GLS χ² of the fit over ``taus_s``.
    segment_lengths
        Rate samples of each contiguous segment of the recording.
    sample_rate_hz
        Sample rate of the recording. [Hz]
    bootstrap_terms
        The terms refitted to each bootstrap record, ``(bootstrap, 5)`` in the order of
        :data:`TERMS` (0: left out of that refit).
    notes
        Lines the figures cannot say.
    """

    coefficients: dict[str, float]
    terms: dict[str, float]
    intervals: dict[str, tuple[float, float] | None]
    fitted: tuple[str, ...]
    confidence: float
    bootstrap: int
    taus_s: np.ndarray
    chi2: float
    segment_lengths: tuple[int, ...]
    sample_rate_hz: float
    bootstrap_terms: np.ndarray
    notes: tuple[str, ...] = field(default=())

    def allan_variance(self, taus_s: Sequence[float] | np.ndarray) -> np.ndarray:
        """The model's Allan variance at ``taus_s``. [(°/h)²]"""
        tau = np.asarray(taus_s, dtype=np.float64)
        return _design(tau, _NAMES) @ np.array([self.coefficients[n] for n in _NAMES])

    def summary(self) -> Summary:
        """Each fitted term with its unit, bootstrap interval and definition."""
        figures = tuple(
            Figure(f"noise_model.{name}", name.replace("_", " "), self.terms[name],
                   TERMS[name][1], self.intervals[name],
                   f"{self.confidence:.0%} bootstrap" if self.intervals[name] else "",
                   digits=4, definition=TERMS[name][3] + " Fitted to the Allan variance by "
                   "non-negative generalised least squares (IEEE Std 952-1997 Annex C).")
            for name in self.fitted)
        left_out = [n.replace("_", " ") for n in _NAMES if n not in self.fitted]
        notes = self.notes + ((f"not in the model: {', '.join(left_out)}",) if left_out else ())
        return Summary(f"noise model over τ {self.taus_s[0]:g}-{self.taus_s[-1]:g} s",
                       (("noise model", figures),), notes)


def _design(taus_s: np.ndarray, names: Sequence[str]) -> np.ndarray:
    return np.column_stack([taus_s ** TERMS[n][0] for n in names]) if names else \
        np.zeros((taus_s.size, 0))


def _kasdin_flicker(shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    """Rows of flicker noise from unit white noise by Kasdin and Walter's filter
    h_0 = 1, h_j = h_{j−1}(j − ½)/j [1] (FFT, zero-padded: no wrap-around). Its Allan
    variance at fs = 1 is 2 ln 2/π (two-sided PSD 1/(2π f)) for τ ≫ 1 s, and more at
    τ of a few samples (1.44 times at τ = 1/fs, 1.05 times at 4/fs), as allantools'
    ``Noise(b=-3)``; the bootstrap reproduces that excess of a sampled flicker noise."""
    _rows, n = shape
    h = np.ones(n)
    j = np.arange(1, n)
    h[1:] = np.cumprod((j - 0.5) / j)
    size = 2 * n
    white = rng.standard_normal(shape)
    return np.fft.irfft(np.fft.rfft(white, size, axis=1) * np.fft.rfft(h, size), size,
                        axis=1)[:, :n]


def unit_noises(draws: int, n: int, sample_rate_hz: float, rng: np.random.Generator,
                names: Sequence[str] = _NAMES) -> dict[str, np.ndarray]:
    """For each term of ``names``, ``draws`` rate records of ``n`` samples whose Allan
    variance is τ^k (C_k = 1): a model's record is Σ √C_k · unit_k, the terms
    independent. [°/h]"""
    fs = float(sample_rate_hz)
    shape = (draws, n)
    make = {
        "quantization": lambda: np.diff(rng.standard_normal((draws, n + 1)), axis=1)
        * (fs / math.sqrt(3.0)),  # white angle noise of σ² = 1/3, differenced
        "angle_random_walk": lambda: math.sqrt(fs) * rng.standard_normal(shape),
        "bias_instability": lambda: _kasdin_flicker(shape, rng) / math.sqrt(_FLICKER),
        "rate_random_walk": lambda: np.cumsum(math.sqrt(3.0 / fs) * rng.standard_normal(shape),
                                              axis=1),
        "rate_ramp": lambda: np.sign(rng.standard_normal((draws, 1))) * math.sqrt(2.0)
        * np.arange(n) / fs,
    }
    return {name: make[name]() for name in _NAMES if name in names}


def pooled_avar(records: np.ndarray, lengths: Sequence[int], factors: np.ndarray) -> np.ndarray:
    """Overlapping Allan variance of each row of ``records`` at the averaging factors, pooled
    within the segments of ``lengths`` (the formula of
    :func:`~hrgtc.evaluation.allan_segments.pooled_deviation`, vectorised over rows)."""
    rows = records.shape[0]
    sums = np.zeros((rows, factors.size))
    counts = np.zeros(factors.size)
    start = 0
    for length in lengths:
        seg = records[:, start:start + length]
        start += length
        phase = np.zeros((rows, length + 1))
        np.cumsum(seg - seg.mean(axis=1, keepdims=True), axis=1, out=phase[:, 1:])
        for j, m in enumerate(factors):
            if length + 1 - 2 * m < 1:
                continue
            d = phase[:, 2 * m:] - 2.0 * phase[:, m:-m] + phase[:, :-2 * m]
            sums[:, j] += np.einsum("ij,ij->i", d, d)
            counts[j] += d.shape[1]
    return sums / (2.0 * counts * factors.astype(np.float64) ** 2)


def _nnls(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    from scipy.optimize import nnls

    if a.shape[1] == 0:
        return np.zeros(0)
    scale = 1.0 / np.maximum(np.max(np.abs(a), axis=0), 1e-300)
    x, _ = nnls(a * scale, b)
    return x * scale


def _pilot(taus: np.ndarray, avar: np.ndarray, edf: np.ndarray,
           names: Sequence[str]) -> np.ndarray:
    """C_k ≥ 0 minimising Σ (edf/2)(σ² − model)²/model², by reweighting with the model."""
    design = _design(taus, names)
    reference = avar
    coefficients = np.zeros(len(names))
    for _ in range(4):
        weight = np.sqrt(edf / 2.0) / reference
        coefficients = _nnls(design * weight[:, None], avar * weight)
        model = design @ coefficients
        if not np.all(model > 0):
            break
        reference = model
    return coefficients


class _Gls:
    """NNLS in the coordinates whitened by the covariance of the relative Allan variances."""

    def __init__(self, taus: np.ndarray, reference: np.ndarray, relative: np.ndarray) -> None:
        cov = np.cov(relative, rowvar=False)
        # shrink the sample covariance a little towards its diagonal (p τ from B draws)
        cov = 0.9 * cov + 0.1 * np.diag(np.diag(cov))
        # a term without scatter (a ramp alone) leaves the covariance singular: a floor
        cov += np.eye(cov.shape[0]) * (1e-12 + 1e-9 * float(np.max(np.diag(cov))))
        self.whiten = np.linalg.inv(np.linalg.cholesky(cov)) / reference[None, :]
        design = self.whiten @ _design(taus, _NAMES)
        self.scale = 1.0 / np.maximum(np.max(np.abs(design), axis=0), 1e-300)
        self.design = design * self.scale

    def select(self, avar: np.ndarray, candidates: Sequence[tuple[int, ...]],
               ) -> tuple[np.ndarray, float]:
        """C_k of the five terms (0: left out) of the candidate subset (column indices)
        with the smallest χ² + 2·(non-zero terms) (Akaike), and its χ²."""
        from scipy.optimize import nnls

        y = self.whiten @ avar
        best = (math.inf, np.zeros(len(_NAMES)), math.inf)
        for columns in candidates:
            a = self.design[:, columns]
            c, norm = nnls(a, y)
            score = norm * norm + 2.0 * np.count_nonzero(c)
            if score < best[0] - 1e-12:
                full = np.zeros(len(_NAMES))
                full[list(columns)] = c
                best = (score, full * self.scale, norm * norm)
        return best[1], best[2]


def _expand(names: Sequence[str], values: np.ndarray) -> np.ndarray:
    out = np.zeros(len(_NAMES))
    for name, v in zip(names, values, strict=True):
        out[_NAMES.index(name)] = v
    return out


#: Samples simulated at once by the bootstrap (rows × record length): bounds its memory
#: (~0.3 GB with the flicker's FFT) whatever the record's length.
BATCH_SAMPLES = 1 << 22


def _bootstrap_avar(full: np.ndarray, draws: int, lengths: tuple[int, ...],
                    factors: np.ndarray, sample_rate_hz: float,
                    rng: np.random.Generator) -> np.ndarray:
    """The pooled Allan variances of ``draws`` records of the model with the five C_k
    ``full``, simulated :data:`BATCH_SAMPLES` at a time. [(°/h)²]"""
    n = sum(lengths)
    names = [k for k, c in zip(_NAMES, full, strict=True) if c > 0]
    rows = max(1, BATCH_SAMPLES // n)
    out = np.empty((draws, factors.size))
    for start in range(0, draws, rows):
        batch = min(rows, draws - start)
        records = np.zeros((batch, n))
        for name, unit in unit_noises(batch, n, sample_rate_hz, rng, names).items():
            records += math.sqrt(full[_NAMES.index(name)]) * unit
        out[start:start + batch] = pooled_avar(records, lengths, factors)
    return out


def _ratio_interval(value: float, draws: np.ndarray,
                    confidence: float) -> tuple[float, float]:
    """The bootstrap interval of a term taking the ratio estimate/truth as pivot: the
    refits θ* of a model with term θ̂ give the quantiles q of θ*/θ̂, and θ lies in
    (θ̂/q_high, θ̂/q_low). A term more than (1 − confidence)/2 of the refits leave out
    (q_low = 0) has no upper bound at that confidence (∞), nor has a term fitted as 0
    (named by the caller, at the bound): (0, ∞). A bound by test inversion (the largest θ
    whose refits fall to 0 in (1 − confidence)/2 of the records) is not computed."""
    low, high = np.quantile(draws, [(1.0 - confidence) / 2.0, (1.0 + confidence) / 2.0])
    if value <= 0.0:
        return 0.0, math.inf
    lower = value * value / high if high > 0 else 0.0
    upper = value * value / low if low > 0 else math.inf
    return float(lower), float(upper)


def _checked(allan: AllanResult, terms: Sequence[str] | None,
             segment_lengths: Sequence[int] | None, bootstrap: int, confidence: float,
             min_blocks: int) -> tuple[tuple[str, ...], tuple[int, ...], np.ndarray]:
    """The terms to fit, the segments' lengths and the τ to fit (a mask) of
    :func:`fit_noise_model`'s arguments, or the InputError saying what is wrong."""
    if allan.kind != "allan" or not allan.overlapping or allan.edf is None:
        raise InputError("fit_noise_model needs an overlapping Allan deviation with its edf: "
                         "allan_deviation(rate, fs, confidence=0.683)")
    if not 0.0 < confidence < 1.0:
        raise InputError(f"confidence must be in (0, 1), got {confidence!r}")
    if bootstrap < 50:
        raise InputError(f"bootstrap must be at least 50 records, got {bootstrap}")
    unknown = [t for t in (terms or ()) if t not in TERMS]
    if unknown or (terms is not None and not terms):
        raise InputError(f"terms must be a non-empty subset of {list(TERMS)}, got {terms!r}")
    if segment_lengths is None:
        if allan.segments > 1:
            raise InputError(f"the Allan deviation is pooled over {allan.segments} segments: "
                             "pass their segment_lengths")
        segment_lengths = (int(allan.n_samples),)
    lengths = tuple(int(n) for n in segment_lengths)
    if sum(lengths) != allan.n_samples or min(lengths) < 1:
        raise InputError(f"segment_lengths add up to {sum(lengths)}, the Allan deviation has "
                         f"{allan.n_samples} samples")
    names = tuple(n for n in _NAMES if terms is None or n in terms)
    m = np.rint(allan.taus_s * allan.sample_rate_hz).astype(np.int64)
    blocks = np.zeros(m.size, dtype=np.int64)
    for length in lengths:
        blocks += length // m
    keep = (blocks >= min_blocks) & (allan.deviation > 0) & np.isfinite(allan.edf) \
        & (allan.edf > 0)
    if np.count_nonzero(keep) < len(names) + 2:
        raise InputError(f"the Allan deviation has {np.count_nonzero(keep)} τ with at least "
                         f"{min_blocks} τ-blocks; {len(names)} terms need {len(names) + 2}: a "
                         "longer record, fewer terms or a lower min_blocks")
    return names, lengths, keep


def fit_noise_model(allan: AllanResult, *, terms: Sequence[str] | None = None,
                    segment_lengths: Sequence[int] | None = None, bootstrap: int = 200,
                    confidence: float = 0.9, min_blocks: int = 8,
                    seed: int = 0) -> NoiseModel:
    """Fit σ²(τ) = Σ C_k τ^k to an overlapping Allan deviation, intervals by parametric
    bootstrap (module docstring).

    Parameters
    ----------
    allan
        An overlapping Allan deviation of a rate in °/h with its edf
        (:func:`~hrgtc.evaluation.allan.allan_deviation` or
        :func:`~hrgtc.evaluation.allan_segments.pooled_deviation` with ``confidence``).
    terms
        Names of :data:`TERMS` to fit; None: selected by Akaike's criterion.
    segment_lengths
        Rate samples of each contiguous segment the deviation was pooled over; required
        when ``allan.segments > 1``, else one segment of ``allan.n_samples``.
    bootstrap
        Records drawn from the model for the covariance and for the intervals (≥ 50).
    confidence
        Level of each term's interval.
    min_blocks
        Fewest whole τ-blocks for a τ to be fitted.
    seed
        Seed of the bootstrap's generator (the same seed, the same intervals).

    Raises
    ------
    InputError
        Not an overlapping Allan deviation with its edf, unknown terms, segment lengths
        that do not add up, fewer usable τ than terms + 2, or a confidence outside (0, 1).
    """
    names, lengths, keep = _checked(allan, terms, segment_lengths, bootstrap, confidence,
                                    min_blocks)
    m = np.rint(allan.taus_s * allan.sample_rate_hz).astype(np.int64)
    taus, factors = allan.taus_s[keep], m[keep]
    avar = allan.deviation[keep] ** 2
    pilot = _expand(names, _pilot(taus, avar, allan.edf[keep], names))
    rng = np.random.default_rng(seed)
    reference = _design(taus, _NAMES) @ pilot
    pilot_avar = _bootstrap_avar(pilot, bootstrap, lengths, factors, allan.sample_rate_hz, rng)
    gls = _Gls(taus, reference, pilot_avar / reference)
    columns = tuple(_NAMES.index(k) for k in names)
    candidates = [columns] if terms is not None else [
        s for r in range(1, len(columns) + 1) for s in itertools.combinations(columns, r)]
    full, chi2 = gls.select(avar, candidates)
    fitted = names if terms is not None else tuple(
        k for k, c in zip(_NAMES, full, strict=True) if c > 0)
    coefficients = dict(zip(_NAMES, map(float, full), strict=True))
    term_values = {k: float(TERMS[k][2](c)) for k, c in coefficients.items()}
    draws = np.zeros((bootstrap, len(_NAMES)))
    for b, row in enumerate(_bootstrap_avar(full, bootstrap, lengths, factors,
                                            allan.sample_rate_hz, rng)):
        c, _ = gls.select(row, candidates)
        draws[b] = [TERMS[k][2](v) for k, v in zip(_NAMES, c, strict=True)]
    intervals = dict.fromkeys(_NAMES)
    for j, k in enumerate(_NAMES):
        if k in fitted:
            intervals[k] = _ratio_interval(term_values[k], draws[:, j], confidence)
    return NoiseModel(coefficients, term_values, intervals, fitted, float(confidence),
                      int(bootstrap), taus, chi2, lengths, float(allan.sample_rate_hz), draws)
