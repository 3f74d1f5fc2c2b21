"""Gyro and measurement noise: angle random walk, bias instability, rate random walk.

The three classical terms of the Allan deviation of a gyro (IEEE Std 952-1997,
Annex C), generated chunk by chunk with state carried across chunks:

* **angle random walk** N: white rate noise, ``sigma(tau) = N / sqrt(tau)``.
  Specified per root hertz, so the per-sample standard deviation is
  ``N * 60 * sqrt(f_s)`` [°/h] and every average over a given time has the
  same spread whatever the sample rate.
* **bias instability** B: flicker (1/f) rate noise, a flat Allan floor
  ``0.664 B``. Made as a sum of first-order Gauss-Markov processes with
  log-spaced correlation times (two per decade between ``flicker_tau_min_s``
  and ``flicker_tau_max_s``), each of variance ``B^2 ln(r) / pi`` for a spacing
  ratio r, so that their summed spectrum approximates the one-sided PSD
  ``B^2 / (pi f)``; the floor is flat within 1 % from about 10 tau_min to
  tau_max / 10. The processes start stationary.
* **rate random walk** K: integrated white noise, ``sigma(tau) = K sqrt(tau/3)``
  (tau in hours), starting at zero.

The slow parts (Gauss-Markov sum and random walk) are advanced exactly on a
coarse grid (step ``max(flicker_tau_min_s / 10, 1 / f_s)``) and interpolated
linearly to the sample times; the white part is drawn at every sample. Each
part draws from its own :class:`numpy.random.Generator`, in time order, so a
run is the same whatever the chunk size.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Annotated, Any

import numpy as np
from msgspec import Meta
from scipy.signal import lfilter

from hrgtc.core import records
from hrgtc.core.errors import InputError

__all__ = ["BIAS_INSTABILITY_FLOOR", "GyroNoise", "GyroNoiseStream", "WhiteNoiseStream"]

#: Allan-deviation floor of flicker rate noise per unit bias instability, sqrt(2 ln 2 / pi).
BIAS_INSTABILITY_FLOOR = math.sqrt(2.0 * math.log(2.0) / math.pi)

_SECONDS_PER_HOUR = 3600.0


def _gauss_markov_allan_variance(tau_s: np.ndarray, tau_c: float, variance: float) -> np.ndarray:
    """Allan variance of a first-order Gauss-Markov process (continuous time)."""
    x = tau_s / tau_c
    return variance * (2.0 * x - 3.0 + 4.0 * np.exp(-x) - np.exp(-2.0 * x)) / x**2


def _gauss_markov_mean_variance(tau_s: np.ndarray, tau_c: float, variance: float) -> np.ndarray:
    """Variance of the tau-average of a first-order Gauss-Markov process."""
    x = tau_s / tau_c
    return 2.0 * variance * (x - 1.0 + np.exp(-x)) / x**2


@dataclass(frozen=True)
class GyroNoise(records.Written):
    """Noise terms of a gyro's rate output.

    Parameters
    ----------
    arw_deg_per_sqrt_h
        Angle random walk N. [°/√h]
    bias_instability_dph
        Bias instability B (Allan floor / 0.664). [°/h]
    rrw_dph_per_sqrt_h
        Rate random walk K. [°/h/√h]
    flicker_tau_min_s, flicker_tau_max_s
        Shortest and longest correlation time of the flicker processes. [s]
    flicker_per_decade
        Number of Gauss-Markov processes per decade of correlation time.
    """

    forbid_unknown_fields = True  # a misspelt key of a hand-written input is refused

    arw_deg_per_sqrt_h: records.NonNegative
    bias_instability_dph: records.NonNegative
    rrw_dph_per_sqrt_h: records.NonNegative
    flicker_tau_min_s: records.Positive = 1.0
    flicker_tau_max_s: records.Positive = 1.0e5
    flicker_per_decade: Annotated[int, Meta(ge=1)] = 2

    def __post_init__(self) -> None:
        for name in ("arw_deg_per_sqrt_h", "bias_instability_dph", "rrw_dph_per_sqrt_h"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value >= 0.0):
                raise InputError(f"{name} must be finite and >= 0, got {value!r}")
            object.__setattr__(self, name, value)
        lo, hi = float(self.flicker_tau_min_s), float(self.flicker_tau_max_s)
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
            raise InputError(
                f"need 0 < flicker_tau_min_s < flicker_tau_max_s [s], got {lo!r}, {hi!r}"
            )
        if int(self.flicker_per_decade) < 1:
            raise InputError(f"flicker_per_decade must be >= 1, got {self.flicker_per_decade!r}")

    @property
    def correlation_times_s(self) -> np.ndarray:
        """Correlation times of the flicker processes, log-spaced. [s]"""
        decades = math.log10(self.flicker_tau_max_s / self.flicker_tau_min_s)
        count = max(2, round(decades * int(self.flicker_per_decade)) + 1)
        return np.geomspace(self.flicker_tau_min_s, self.flicker_tau_max_s, count)

    @property
    def flicker_variance(self) -> float:
        """Variance of each Gauss-Markov process, ``B^2 ln(r) / pi``. [(°/h)²]"""
        taus = self.correlation_times_s
        ratio = taus[1] / taus[0]
        return self.bias_instability_dph**2 * math.log(ratio) / math.pi

    def allan_deviation(self, tau_s: Any) -> np.ndarray:
        """Allan deviation of the configured noise, closed form (continuous time). [°/h]

        Parameters
        ----------
        tau_s
            Averaging times. [s]
        """
        tau = np.asarray(tau_s, dtype=np.float64)
        avar = (self.arw_deg_per_sqrt_h * 60.0) ** 2 / tau
        for tau_c in self.correlation_times_s:
            avar = avar + _gauss_markov_allan_variance(tau, tau_c, self.flicker_variance)
        avar = avar + self.rrw_dph_per_sqrt_h**2 * (tau / _SECONDS_PER_HOUR) / 3.0
        return np.sqrt(avar)

    def expected_bias_stability(self, tau_s: float, duration_s: float) -> float:
        """Expected 1-sigma spread of the tau-second means over a run, closed form. [°/h]

        The expectation of the (population) variance of ``duration / tau``
        non-overlapping means about their grand mean, for the white,
        Gauss-Markov and random-walk parts; the quantity ``bias stability`` of
        [1] at constant temperature.
        """
        tau, total = float(tau_s), float(duration_s)
        blocks = total / tau
        var = (self.arw_deg_per_sqrt_h * 60.0) ** 2 / tau * (1.0 - 1.0 / blocks)
        for tau_c in self.correlation_times_s:
            var += float(
                _gauss_markov_mean_variance(np.array(tau), tau_c, self.flicker_variance)
                - _gauss_markov_mean_variance(np.array(total), tau_c, self.flicker_variance)
            )
        # Random walk W with E[W(t)^2] = q t: E[var of means about their mean] ~ q T / 6.
        var += self.rrw_dph_per_sqrt_h**2 / _SECONDS_PER_HOUR * total / 6.0
        return math.sqrt(var)

    def stream(
        self, sample_rate_hz: float, white_rng: np.random.Generator, slow_rng: np.random.Generator
    ) -> GyroNoiseStream:
        """A stateful generator of this noise at a sample rate (see :class:`GyroNoiseStream`)."""
        return GyroNoiseStream(self, sample_rate_hz, white_rng, slow_rng)


#: The record of :class:`GyroNoise` (nested in other records).
GyroNoiseRecord = records.record_of(GyroNoise)


class WhiteNoiseStream:
    """White Gaussian noise of a fixed standard deviation per sample, chunk by chunk.

    Parameters
    ----------
    std
        Standard deviation per sample (in the unit of the quantity).
    rng
        Generator used for this stream only.
    """

    def __init__(self, std: float, rng: np.random.Generator) -> None:
        self.std = float(std)
        self._rng = rng

    def next(self, count: int) -> np.ndarray:
        """The next ``count`` samples."""
        if self.std == 0.0:
            return np.zeros(count)
        out = self._rng.standard_normal(count)
        out *= self.std
        return out


class GyroNoiseStream:
    """The noise of :class:`GyroNoise` sample by sample, in chunks, state carried.

    Parameters
    ----------
    noise
        The noise terms.
    sample_rate_hz
        Sample rate of the output. [Hz]
    white_rng, slow_rng
        Generators for the white part and for the slow (flicker and random
        walk) parts, used by this stream only.
    """

    def __init__(
        self,
        noise: GyroNoise,
        sample_rate_hz: float,
        white_rng: np.random.Generator,
        slow_rng: np.random.Generator,
    ) -> None:
        self.noise = noise
        self.sample_rate_hz = float(sample_rate_hz)
        self._white = WhiteNoiseStream(
            noise.arw_deg_per_sqrt_h * 60.0 * math.sqrt(self.sample_rate_hz), white_rng
        )
        self._rng = slow_rng
        self.coarse_step_s = max(noise.flicker_tau_min_s / 10.0, 1.0 / self.sample_rate_hz)
        taus = noise.correlation_times_s
        self._decay = np.exp(-self.coarse_step_s / taus)
        self._drive = math.sqrt(noise.flicker_variance) * np.sqrt(
            -np.expm1(-2.0 * self.coarse_step_s / taus)
        )
        self._walk_step = noise.rrw_dph_per_sqrt_h * math.sqrt(
            self.coarse_step_s / _SECONDS_PER_HOUR
        )
        # Coarse point 0: flicker processes drawn from their stationary law, walk at 0.
        self._processes = self._rng.standard_normal(taus.size) * math.sqrt(noise.flicker_variance)
        self._walk = 0.0
        # The last two coarse points generated (one at the start): first index, values.
        self._tail_index = 0
        self._tail_values = np.array([self._processes.sum()])
        self._next_sample = 0

    def _advance_coarse(self, count: int) -> np.ndarray:
        """Values (flicker sum + walk) at the next ``count`` coarse points."""
        draws = self._rng.standard_normal((count, self._processes.size + 1))
        total = np.zeros(count)
        for k in range(self._processes.size):
            values, _ = lfilter(
                [self._drive[k]],
                [1.0, -self._decay[k]],
                draws[:, k],
                zi=[self._decay[k] * self._processes[k]],
            )
            self._processes[k] = values[-1]
            total += values
        walk, _ = lfilter([self._walk_step], [1.0, -1.0], draws[:, -1], zi=[self._walk])
        self._walk = float(walk[-1])
        total += walk
        return total

    def next(self, count: int) -> np.ndarray:
        """The next ``count`` samples of rate noise. [°/h]"""
        out = self._white.next(count)
        if count == 0:
            return out
        index = np.arange(self._next_sample, self._next_sample + count, dtype=np.float64)
        self._next_sample += count
        time_s = index / self.sample_rate_hz
        last = self._tail_index + self._tail_values.size - 1
        needed = math.floor(time_s[-1] / self.coarse_step_s) + 1
        values = self._tail_values
        if needed > last:
            values = np.concatenate([values, self._advance_coarse(needed - last)])
        grid = np.arange(self._tail_index, self._tail_index + values.size) * self.coarse_step_s
        out += np.interp(time_s, grid, values)
        self._tail_values = values[-2:].copy()
        self._tail_index += values.size - self._tail_values.size
        return out
