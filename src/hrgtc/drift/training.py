"""Statistics of a model's training data, and the plausibility of a recording against them.

A wrong rate unit that makes values larger (``--rate-unit dps`` on °/h data: × 3600) or
smaller passes every check of a recording on its own: a rate-table run, a field
recording and a MEMS gyro with a 4 °/s offset legitimately have any level. What a unit
mistake cannot hide is the *noise*: the same gyro at the same sample rate has the same
white noise, and a unit factor multiplies it. The model file keeps, per axis, the
noise of its training data as the MAD (median absolute deviation) of sample-to-sample
differences of ``rate_dph`` at its sample rate (robust to the slow thermal drift and
to a few spikes), with the rate level; a recording compensated with the model is
compared by its noise only: a ratio near 3600, 57.3, 1000, 206265 or their inverses
is refused, naming the likely mistake.

White noise of standard deviation σ per sample has sample-to-sample differences of
standard deviation σ√2, and σ = N·√fs for a noise density N (angle random walk): the
MAD of differences scales with √fs, so a recording at another rate is scaled to the
model's before the comparison.

The statistics are taken on the first rows of every training run (the heads the
calibration reads anyway); the training ranges of every model variable are the drift
model's ``ranges``. Old model files have no statistics: the check is skipped (the CLI
says so once).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.errors import InputError

#: Unit factors a recording's noise ratio to the training data's is tested against: the
#: factor, what it would mean when the recording is that much *larger*, and smaller.
UNIT_FACTORS: tuple[tuple[float, str, str], ...] = (
    (3600.0,
     "°/h data read as °/s (--rate-unit dps on a rate in °/h)",
     "°/s data read as °/h (pass --rate-unit dps)"),
    (180.0 / math.pi,
     "degree data read as radians (--rate-unit rad/s on a rate in °/s)",
     "rad/s data read as °/s (pass --rate-unit rad/s)"),
    (1000.0,
     "a milli-unit read as the unit (e.g. mdps data read as dps)",
     "a unit read as a milli-unit, or the gyro's counts scaled by 1000"),
    (3600.0 * 180.0 / math.pi,
     "°/h data read as rad/s (--rate-unit rad/s on a rate in °/h)",
     "rad/s data read as °/h (pass --rate-unit rad/s)"),
)
#: A ratio within this factor of a unit factor is taken for that unit mistake. The noise of
#: one gyro varies far less between runs; unit factors are 57.3 and more.
FACTOR_TOLERANCE = 2.5


def rate_noise_dph(rate_dph: Any) -> float:
    """MAD of the sample-to-sample differences of a rate. [°/h]

    Returns NaN for fewer than 3 finite samples; 0 for a quantised rate whose steps are
    mostly 0.
    """
    rate = np.asarray(rate_dph, dtype=np.float64)
    rate = rate[np.isfinite(rate)]
    if rate.size < 3:
        return math.nan
    steps = np.diff(rate)
    return float(np.median(np.abs(steps - np.median(steps))))


@dataclass(frozen=True)
class TrainingStatistics:
    """What the model's training data looked like, per axis (plain JSON in the model file).

    Attributes
    ----------
    sample_rate_hz
        Sample rate of the training runs. [Hz]
    rate_noise_dph
        MAD of sample-to-sample differences of ``rate_dph`` (median over the runs). [°/h]
    rate_level_dph
        Median ``rate_dph`` (for the record: a recording's level is not compared). [°/h]
    samples
        Rows the statistics were taken on.
    runs
        Training runs they were taken on.
    """

    sample_rate_hz: float
    rate_noise_dph: float
    rate_level_dph: float
    samples: int
    runs: int

    @classmethod
    def from_runs(cls, heads: Sequence[Any]) -> TrainingStatistics | None:
        """From the first rows of each training run (:class:`Recording` objects); None
        when no run has three samples."""
        noises, levels, n, rate = [], [], 0, math.nan
        for head in heads:
            noise = rate_noise_dph(head.rate_dph)
            if math.isfinite(noise):
                noises.append(noise)
                levels.append(float(np.median(head.rate_dph)))
                n += len(head)
                rate = head.metadata.sample_rate_hz if math.isnan(rate) else rate
        if not noises:
            return None
        return cls(float(rate), float(np.median(noises)), float(np.median(levels)), n,
                   len(noises))

    def to_dict(self) -> dict[str, Any]:
        return {"sample_rate_hz": self.sample_rate_hz, "rate_noise_dph": self.rate_noise_dph,
                "rate_level_dph": self.rate_level_dph, "samples": self.samples,
                "runs": self.runs}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> TrainingStatistics:
        try:
            return cls(float(data["sample_rate_hz"]), float(data["rate_noise_dph"]),
                       float(data["rate_level_dph"]), int(data["samples"]), int(data["runs"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"not a valid training-statistics record: {exc!r}") from exc

    def noise_ratio(self, rate_dph: Any, sample_rate_hz: float) -> float:
        """The recording's rate noise over the training data's, at the training rate (NaN
        when either is 0 or unknown: a quantised or constant rate)."""
        noise = rate_noise_dph(rate_dph)
        if not (noise > 0.0 and self.rate_noise_dph > 0.0 and sample_rate_hz > 0.0):
            return math.nan
        return noise * math.sqrt(self.sample_rate_hz / sample_rate_hz) / self.rate_noise_dph


def unit_mistake(ratio: float) -> tuple[float, str] | None:
    """(signed factor, likely mistake) when ``ratio`` is near a unit factor, else None."""
    if not (math.isfinite(ratio) and ratio > 0.0):
        return None
    for factor, larger, smaller in UNIT_FACTORS:
        if factor / FACTOR_TOLERANCE <= ratio <= factor * FACTOR_TOLERANCE:
            return factor, larger
        if factor / FACTOR_TOLERANCE <= 1.0 / ratio <= factor * FACTOR_TOLERANCE:
            return 1.0 / factor, smaller
    return None


def check_noise(statistics: TrainingStatistics | None, rate_dph: Any, sample_rate_hz: float,
                source: str = "", column: str = "rate_dph") -> float:
    """Refuse a recording whose rate noise differs from the training data's by a unit factor.

    Returns the ratio (NaN when not compared: no statistics, or a quantised rate).

    Raises
    ------
    InputError
        Names the file, the column, the ratio and the likely unit mistake.
    """
    if statistics is None:
        return math.nan
    ratio = statistics.noise_ratio(rate_dph, sample_rate_hz)
    found = unit_mistake(ratio)
    if found is None:
        return ratio
    factor, mistake = found
    where = f"{source}: " if source else ""
    noise = rate_noise_dph(rate_dph)
    raise InputError(
        f"{where}column {column!r}: its noise (MAD of sample-to-sample differences "
        f"{noise:.4g} °/h at {sample_rate_hz:g} Hz) is {ratio:.4g}× the model's training data "
        f"({statistics.rate_noise_dph:.4g} °/h at {statistics.sample_rate_hz:g} Hz), near the "
        f"unit factor {factor:.6g}: likely {mistake}; check --rate-unit (the level of a "
        "rate-table or biased run may differ, its noise may not)")
