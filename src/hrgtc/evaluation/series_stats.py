"""Bias stability and Allan deviation of a series fed chunk by chunk, in bounded memory.

:func:`~hrgtc.evaluation.run_pass.run_pass` measures runs of any length; holding
every sample of three series (raw, compensated, housing) would take 2.4 GB for
50 M rows. :class:`SeriesStatistics` keeps instead:

* for each τ of the bias-stability table, the count, mean and sum of squared
  deviations of the τ-block means (the statistic needs nothing else), merged chunk
  by chunk with the pairwise update of Chan, Golub and LeVeque [4]; the block means
  are those of :func:`~hrgtc.evaluation.metrics.bias_stability` (the same rows
  averaged in the same order) and the result agrees with it to ~1e-14;
* for the Allan deviation, the samples themselves up to :data:`FULL_SAMPLES`
  (then the result is that of :func:`~hrgtc.evaluation.allan.allan_deviation` on
  the whole series, exactly); beyond, means of blocks of ``D`` samples (``D`` a
  power of two, doubled whenever the kept means exceed :data:`FULL_SAMPLES`),
  plus running sums of squared second differences for every octave factor
  ``m < D`` (exact, carried across chunks with a tail of ``2 m`` samples; started
  over the held samples when the cap is passed, and planned from the expected
  length when it is known). For
  ``m >= D`` the overlapping estimator runs over the block means, i.e. over the
  starting samples that are multiples of ``D`` — the same statistic with fewer
  (still overlapping) terms; at the τ that carry noise terms (≥ 1000 D samples
  per τ-block) it differs from the all-samples estimate by far less than its
  confidence interval (SP 1065 [3] Section 5.3).

Memory: at most :data:`FULL_SAMPLES` floats for the Allan deviation plus
``N / m`` block means per τ of the table, whatever ``N``.

[3] W. J. Riley, NIST SP 1065, 2008.
[4] T. F. Chan, G. H. Golub, R. J. LeVeque, "Algorithms for computing the sample
    variance", The American Statistician 37(3), 242-247, 1983.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import Self

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.timeline import min_partial_rows
from hrgtc.evaluation.allan import (
    AllanResult,
    _block_length,
    allan_deviation,
    confidence_interval,
)
from hrgtc.evaluation.allan_segments import pooled_deviation, pooled_edf
from hrgtc.evaluation.burst_allan import BurstAllanResult, burst_mean_allan

#: Samples kept at full resolution for the Allan deviation (32 MiB per series).
FULL_SAMPLES = 1 << 22
#: Largest averaging factor of the exact running sums (covers D up to 2 of these).
EXACT_MAX_FACTOR = 1 << 12


class _BlockMeans:
    """Means of consecutive blocks of ``rows`` samples, as ``reshape(-1, rows).mean(1)``.

    With ``keep=False`` only their count, mean and sum of squared deviations are kept.
    """

    def __init__(self, rows: int, keep: bool = True) -> None:
        self.rows = int(rows)
        self.keep = keep
        self._carry = np.empty(0)
        self._means: list[np.ndarray] = []
        self.count = 0
        self.partial = 0  # blocks closed short at a gap (kept from half a block)
        self.mean = 0.0
        self.m2 = 0.0

    def partial_fit(self, values: np.ndarray) -> Self:
        data = np.concatenate([self._carry, values]) if self._carry.size else values
        blocks = data.size // self.rows
        if blocks:
            self._add(data[: blocks * self.rows].reshape(blocks, self.rows).mean(axis=1))
        self._carry = np.array(data[blocks * self.rows:])
        return self

    def finish(self) -> np.ndarray:
        """The means of the complete blocks (the open one is not a block yet)."""
        return self.means()

    def close_segment(self, min_rows: int) -> None:
        """A gap follows: the partial block is kept as one mean when it holds at least
        ``min_rows`` samples (the rule of the training windows), else dropped."""
        if self._carry.size >= max(1, min_rows):
            self._add(np.array([float(np.mean(self._carry))]))
            self.partial += 1
        self._carry = np.empty(0)

    def _add(self, means: np.ndarray) -> None:
        blocks = means.size
        if self.keep:
            self._means.append(means)
        else:  # Chan et al. [4]: merge (count, mean, M2) of this batch into the total
            mean = float(np.mean(means))
            m2 = float(np.sum((means - mean) ** 2))
            total = self.count + blocks
            delta = mean - self.mean
            self.m2 += m2 + delta * delta * self.count * blocks / total
            self.mean += delta * blocks / total
        self.count += blocks

    def std(self) -> float:
        """Sample standard deviation (ddof=1) of the block means, NaN below two blocks."""
        if self.count < 2:
            return math.nan
        if self.keep:
            return float(np.std(self.means(), ddof=1))
        return math.sqrt(self.m2 / (self.count - 1))

    def means(self) -> np.ndarray:
        if len(self._means) > 1:
            self._means = [np.concatenate(self._means)]
        return self._means[0] if self._means else np.empty(0)

    def halve(self) -> None:
        """Double the block length: pairs of means averaged (the carry is kept as samples)."""
        means = self.means()
        pairs = means.size // 2
        merged = 0.5 * (means[0: 2 * pairs: 2] + means[1: 2 * pairs: 2])
        self._means = [merged]
        self.count = pairs
        if means.size % 2:  # a lone block: back to its samples' share, kept as one mean
            self._carry = np.concatenate([np.full(self.rows, means[-1]), self._carry])
        self.rows *= 2


class _SecondDifferenceSums:
    """Σ (x[i+2m] − 2x[i+m] + x[i])² over all i for octave m ≤ ``largest``, streamed."""

    def __init__(self, largest: int) -> None:
        self.factors = 2 ** np.arange(int(math.log2(max(largest, 1))) + 1)
        self.sums = np.zeros(self.factors.size)
        self.counts = np.zeros(self.factors.size, dtype=np.int64)  # terms summed per factor
        self._tail = np.empty(0)

    def break_segment(self) -> None:
        """A gap: no second difference reaches across it."""
        self._tail = np.empty(0)

    def partial_fit(self, values: np.ndarray) -> Self:
        data = np.concatenate([self._tail, values]) if self._tail.size else values
        old = self._tail.size
        centred = data - np.mean(data)  # a constant offset leaves second differences unchanged
        phase = np.empty(data.size + 1)
        phase[0] = 0.0
        np.cumsum(centred, out=phase[1:])
        for k, m in enumerate(self.factors.tolist()):
            start = max(old - 2 * m + 1, 0)  # terms that end in the new samples
            stop = data.size - 2 * m + 1
            if stop <= start:
                continue
            term = phase[start + 2 * m: stop + 2 * m] - 2.0 * phase[start + m: stop + m]
            term += phase[start:stop]
            self.sums[k] += float(np.dot(term, term))
            self.counts[k] += stop - start
        keep = 2 * int(self.factors[-1])
        self._tail = np.array(data[-keep:])
        return self

    def finish(self) -> tuple[np.ndarray, np.ndarray]:
        """The sums of squared second differences per octave factor and their counts."""
        return self.sums, self.counts


class SeriesStatistics:
    """Bias stability at ``taus_s`` and the octave Allan deviation of one series, streamed.

    Parameters
    ----------
    sample_rate_hz
        Sample rate. [Hz]
    taus_s
        Averaging times of the bias stability. [s]
    allan
        Also keep what the Allan deviation needs.
    full_samples
        Samples kept at full resolution (see the module docstring).
    expected_samples
        Length of the series if known (0: unknown); fixes how many exact running sums
        a long series needs (fewer is faster).
    """

    def __init__(self, sample_rate_hz: float, taus_s: Sequence[float], allan: bool = True,
                 full_samples: int = FULL_SAMPLES, expected_samples: int = 0) -> None:
        self.sample_rate_hz = float(sample_rate_hz)
        self.taus_s = tuple(float(t) for t in taus_s)
        self.n = 0
        self._sum = 0.0
        self._sum_squares = 0.0
        self._stability = {t: _BlockMeans(_block_length(t, self.sample_rate_hz), keep=False)
                           for t in self.taus_s}
        self.allan = allan
        self._full_samples = int(full_samples)
        self._full: list[np.ndarray] | None = [] if allan else None
        self._decimated: _BlockMeans | None = None
        self._exact: _SecondDifferenceSums | None = None
        largest = EXACT_MAX_FACTOR
        if expected_samples > 0:
            block = 2
            while expected_samples / block > self._full_samples // 2 and block < 2 * largest:
                block *= 2
            largest = block // 2
        self._largest_exact = largest
        self.segments = 1  # contiguous segments pushed (break_segment adds one)
        self._segment_samples = 0
        self._longest = 0
        self._full_breaks: list[int] = []  # sample indices where a segment starts
        self._coarse_crosses_gaps = False
        # per segment: [time of its first sample (NaN if not given), samples, sum]
        self._segments: list[list[float]] = []

    def partial_fit(self, values: np.ndarray, breaks: Sequence[int] = (),
                    time_s: np.ndarray | None = None) -> Self:
        """Add the next samples; ``breaks``: indices in ``values`` where a segment starts
        after a gap (no τ-block and no Allan difference reaches across it); ``time_s``:
        their times [s] (for the burst means beyond a segment)."""
        values = np.asarray(values, dtype=np.float64)
        cuts = sorted({int(b) for b in breaks if 0 <= b < values.size})
        if not cuts:
            self._push(values, time_s)
            return self
        edges = [0, *[c for c in cuts if c > 0], values.size]
        for k in range(len(edges) - 1):
            if k > 0 or cuts[0] == 0:
                self.break_segment()
            self._push(values[edges[k]:edges[k + 1]],
                       None if time_s is None else time_s[edges[k]:edges[k + 1]])
        return self

    def finish(self) -> Self:
        """The statistics (read with :meth:`bias_stability`, :meth:`allan_deviation`, ...)."""
        return self

    def break_segment(self) -> None:
        """A gap before the next sample: the partial τ-blocks are dropped (a block never
        spans a gap) and the Allan differences restart."""
        if self.n == 0:
            return
        self.segments += 1
        self._longest = max(self._longest, self._segment_samples)
        self._segment_samples = 0
        for means in self._stability.values():
            means.close_segment(min_partial_rows(means.rows))
        if not self.allan:
            return
        if self._full is not None:
            self._full_breaks.append(self.n)
        else:
            self._exact.break_segment()
            self._decimated._carry = np.empty(0)
            self._coarse_crosses_gaps = True

    @property
    def longest_segment_s(self) -> float:
        """Duration of the longest contiguous segment pushed. [s]"""
        return max(self._longest, self._segment_samples) / self.sample_rate_hz

    def _push(self, values: np.ndarray, time_s: np.ndarray | None = None) -> None:
        if not values.size:
            return
        if self._segment_samples == 0:
            self._segments.append([math.nan if time_s is None else float(time_s[0]), 0, 0.0])
        self._segments[-1][1] += values.size
        self._segments[-1][2] += float(np.sum(values))
        self.n += values.size
        self._sum += float(np.sum(values))
        self._sum_squares += float(np.dot(values, values))
        self._segment_samples += values.size
        for means in self._stability.values():
            means.partial_fit(values)
        if not self.allan:
            return
        if self._full is not None:
            self._full.append(np.array(values))
            if self.n > self._full_samples:  # switch to block means and exact running sums
                held = np.concatenate(self._full)
                self._full = None
                self._exact = _SecondDifferenceSums(self._largest_exact)
                self._decimated = _BlockMeans(2)
                edges = [0, *self._full_breaks, held.size]
                for k in range(len(edges) - 1):
                    if k:
                        self._exact.break_segment()
                        self._decimated._carry = np.empty(0)
                        self._coarse_crosses_gaps = True
                    self._exact.partial_fit(held[edges[k]:edges[k + 1]])
                    self._decimated.partial_fit(held[edges[k]:edges[k + 1]])
                self._shrink()
            return
        self._exact.partial_fit(values)
        self._decimated.partial_fit(values)
        self._shrink()

    def _shrink(self) -> None:
        while self._decimated.count > self._full_samples // 2:
            if self._decimated.rows >= 2 * self._largest_exact:
                break  # beyond the exact sums' reach: keep the resolution, and the memory
            self._decimated.halve()

    def mean(self) -> float:
        """Mean of the series (NaN when empty): the offset a bias stability does not show."""
        return self._sum / self.n if self.n else math.nan

    def rms(self) -> float:
        """Root mean square of the series (NaN when empty): offset and spread together."""
        return math.sqrt(self._sum_squares / self.n) if self.n else math.nan

    def bias_stability(self) -> dict[float, float]:
        """``{tau_s: 1σ of the τ-block means}``, NaN where fewer than two blocks fit. [°/h]

        A τ-block never spans a gap; in a recording of segments (bursts) the partial
        block at each segment's end is kept as one mean when it covers at least half τ,
        the rule of the training windows, so 5 s bursts give τ = 10 s figures from their
        burst means (:meth:`partial_blocks` counts them) instead of none.
        """
        if self.segments > 1:
            for means in self._stability.values():
                means.close_segment(min_partial_rows(means.rows))
        return {tau: means.std() for tau, means in self._stability.items()}

    def blocks(self) -> dict[float, int]:
        """``{tau_s: τ-blocks behind the bias stability}`` (partial ones at gaps included):
        the N of each figure, whose interval has N − 1 degrees of freedom."""
        self.bias_stability()  # closes the partial blocks of a segmented series
        return {tau: means.count for tau, means in self._stability.items()}

    def partial_blocks(self) -> dict[float, int]:
        """``{tau_s: τ-blocks closed short at a gap}`` (kept from half τ)."""
        return {tau: means.partial for tau, means in self._stability.items()}

    def segment_lengths(self) -> list[int]:
        """Samples of each contiguous segment pushed."""
        return [int(seg[1]) for seg in self._segments]

    def segment_starts(self) -> list[int]:
        """Indices (in the samples pushed) where a segment starts after a gap."""
        return np.cumsum(self.segment_lengths())[:-1].tolist()

    def allan_deviation(self, confidence: float | None = None) -> AllanResult:
        """Overlapping Allan deviation at octave τ (see the module docstring), pooled within
        segments; with ``confidence`` its chi-squared interval from the pooled edf
        (:func:`~hrgtc.evaluation.allan_segments.pooled_edf`: the segments' own edfs, not
        one of the whole sample count)."""
        if not self.allan:
            raise InputError("the Allan deviation was not kept (allan=False)")
        fs = self.sample_rate_hz
        if self._full is not None:
            values = np.concatenate(self._full) if self._full else np.empty(0)
            if self._full_breaks:
                return pooled_deviation(values, fs, self._full_breaks, "octave",
                                        confidence=confidence)
            return allan_deviation(values, fs, taus="octave", confidence=confidence)
        block = self._decimated.rows
        coarse = allan_deviation(self._decimated.means(), fs / block, taus="octave")
        if self._coarse_crosses_gaps:  # block means across gaps: those τ are not estimable
            coarse = AllanResult(taus_s=np.empty(0), deviation=np.empty(0),
                                 counts=np.empty(0, dtype=np.int64), overlapping=True,
                                 sample_rate_hz=fs, n_samples=self.n)
        small = self._exact.factors < block
        counts = self._exact.counts[small]
        usable = counts > 1
        m = self._exact.factors[small][usable].astype(np.float64)
        fine = np.sqrt(self._exact.sums[small][usable] / (2.0 * counts[usable])) / m
        result = AllanResult(
            taus_s=np.concatenate([m / fs, coarse.taus_s]),
            deviation=np.concatenate([fine, coarse.deviation]),
            counts=np.concatenate([counts[usable], coarse.counts]),
            overlapping=True, sample_rate_hz=fs, n_samples=self.n,
            segments=len(self._segments))
        if confidence is None:
            return result
        lengths = self.segment_lengths()
        edf = np.array([pooled_edf("allan", lengths, int(k)) for k in
                        np.rint(result.taus_s * fs).astype(np.int64)])
        lower, upper = confidence_interval(result.deviation, edf, confidence)
        return replace(result, lower=lower, upper=upper, confidence=float(confidence), edf=edf)

    def burst_allan(self, confidence: float) -> BurstAllanResult:
        """Allan deviation beyond a segment from the segments' means, with the dead-time
        ratio and its bias (:func:`~hrgtc.evaluation.burst_allan.burst_mean_allan`).

        Raises
        ------
        InputError
            Not estimable: one segment, no times pushed, or no regular period.
        """
        if len(self._segments) < 2:
            raise InputError("one contiguous segment: the pooled deviation covers every τ")
        table = np.array(self._segments, dtype=np.float64)
        starts, samples, sums = table[:, 0], table[:, 1], table[:, 2]
        if not np.all(np.isfinite(starts)):
            raise InputError("the segments' start times were not given")
        return burst_mean_allan(sums / samples, samples / self.sample_rate_hz, starts,
                                confidence=confidence)
