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
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Self

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError

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
class TrainingStatistics(records.Written):
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

    sample_rate_hz: records.Positive
    rate_noise_dph: records.NonNegative
    rate_level_dph: float
    samples: records.Count
    runs: records.Count

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

    def noise_ratio(self, rate_dph: Any, sample_rate_hz: float) -> float:
        """The recording's rate noise over the training data's, at the training rate (NaN
        when either is 0 or unknown: a quantised or constant rate)."""
        noise = rate_noise_dph(rate_dph)
        if not (noise > 0.0 and self.rate_noise_dph > 0.0 and sample_rate_hz > 0.0):
            return math.nan
        return noise * math.sqrt(self.sample_rate_hz / sample_rate_hz) / self.rate_noise_dph


#: The record of :class:`TrainingStatistics` (nested in other records).
TrainingStatisticsRecord = records.record_of(TrainingStatistics)


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


# -- without a model: the sensor class (calibrate) ------------------------------------------
#: Angle random walk of 0.25 °/√h (15 °/h/√Hz): beyond any HRG (navigation and tactical
#: HRGs have 0.0002-0.05 °/√h), typical of a MEMS gyro; an HRG's rate read ×57.3 (rad/s
#: declared) has it from 0.005 °/√h on (issue 27). [°/h/√Hz]
HRG_MAX_NOISE_DENSITY = 15.0
#: A bias of 1 °/s at rest: beyond any HRG (a few °/h at most), common in MEMS gyros. [°/h]
HRG_MAX_BIAS_DPH = 3600.0
#: Noise densities of any gyro, from the best HRG/FOG (ARW 1e-4 °/√h = 0.006 °/h/√Hz) to the
#: noisiest MEMS (1 °/s/√Hz). [°/h/√Hz]
ANY_GYRO_NOISE_DENSITY = (1e-3, 3600.0)
#: MAD of the differences of white noise of σ = 1: 0.6745·√2.
_MAD_PER_SIGMA = 0.6744897501960817 * math.sqrt(2.0)


def noise_density(rate_dph: Any, sample_rate_hz: float) -> float:
    """White-noise density of a rate from the MAD of its differences. [°/h/√Hz]

    σ per sample = MAD / (0.6745·√2); density = σ / √fs (= ARW × 60 in °/√h).
    """
    return rate_noise_dph(rate_dph) / _MAD_PER_SIGMA / math.sqrt(sample_rate_hz)


def _likely_unit(density: float, bias_dph: float) -> str:
    """The unit factor that brings an HRG-implausible rate closest to a typical HRG."""
    best = None
    for factor, larger, _ in UNIT_FACTORS:
        scaled = density / factor
        if scaled <= HRG_MAX_NOISE_DENSITY and abs(bias_dph) / factor <= HRG_MAX_BIAS_DPH:
            distance = abs(math.log(max(scaled, 1e-12) / 0.3))  # a typical HRG: 0.3 °/h/√Hz
            if best is None or distance < best[0]:
                best = (distance, factor, larger)
    if best is None:
        return "a rate in another unit or another gyro's column"
    return f"{best[2]} (values × {best[1]:.6g})"


#: Why a unit is an HRG, and the way out when it is not: the resonator thermometer.
RESONATOR_THERMOMETER = ("this unit is calibrated with its resonator as thermometer (an HRG)",
                         "for a MEMS gyro use --thermometer sensor")


def check_resonator_gyro(rate_dph: Any, sample_rate_hz: float, input_rate_dph: float = 0.0,
                         source: str = "", column: str = "rate_dph",
                         hrg: tuple[str, str] = RESONATOR_THERMOMETER,
                         levels: bool = True) -> None:
    """Refuse the training data of an HRG (resonator thermometer) whose noise or bias only a
    MEMS gyro could have: a unit mistake that makes values larger (``--rate-unit dps`` on
    °/h data makes the bias stability 4208 instead of 1.2 °/h).

    ``hrg``: why the unit is an HRG and what to do if it is not (its resonator is the
    thermometer, or the file logs a resonator frequency beside a temperature sensor);
    ``levels`` False: the noise only (the level of a biased run may differ, its noise
    may not).

    Raises
    ------
    InputError
        Names the file, the column, the figures and the likely unit.
    """
    rate = np.asarray(rate_dph, dtype=np.float64)
    density = noise_density(rate, sample_rate_hz)
    finite = rate[np.isfinite(rate)]
    bias = float(np.median(finite)) - input_rate_dph if finite.size else math.nan
    noisy = density > HRG_MAX_NOISE_DENSITY
    biased = levels and abs(bias) > HRG_MAX_BIAS_DPH
    if not (noisy or biased):
        return
    where = f"{source}: " if source else ""
    what = " and ".join(
        [f"a noise density of {density:.4g} °/h/√Hz (angle random walk {density / 60.0:.3g} "
         f"°/√h; an HRG has at most {HRG_MAX_NOISE_DENSITY / 60.0:g})"] * noisy
        + [f"a bias of {bias:.4g} °/h at rest (an HRG has at most {HRG_MAX_BIAS_DPH:g})"]
        * biased)
    raise InputError(
        f"{where}column {column!r}: {what}: only a MEMS gyro could have that, and {hrg[0]}. "
        f"Likely {_likely_unit(density, bias)}: check --rate-unit; {hrg[1]}")


def implausible_for_any_gyro(rate_dph: Any, sample_rate_hz: float) -> str | None:
    """A warning when a rate's noise density is outside what any gyro has (None: inside).

    With a temperature sensor as thermometer (a MEMS gyro, most often) a unit that only
    makes values larger cannot always be told from a noisier gyro: only densities beyond
    every gyro are flagged.
    """
    density = noise_density(rate_dph, sample_rate_hz)
    low, high = ANY_GYRO_NOISE_DENSITY
    if not math.isfinite(density) or low <= density <= high or density == 0.0:
        return None
    side = "above the noisiest" if density > high else "below the quietest"
    return (f"the rate's noise density {density:.4g} °/h/√Hz is {side} gyro's ({low:g} to "
            f"{high:g} °/h/√Hz): check --rate-unit (°/h, °/s, rad/s)")


# -- calibrate --thermometer sensor: is the thermometer a temperature? ------------------------
#: A temperature whose sample-to-sample noise is this share of its span is no temperature
#: (a thermal mass changes smoothly: 0.002 on a real MEMS recording, 4e-5 on the
#: simulator); a rate at rest is mostly noise (white noise alone: 0.205).
ROUGH_TEMPERATURE = 0.02
#: ... and it must be this many times rougher than the rate column.
SWAP_CONTRAST = 10.0


class ChannelShape:
    """How smooth a column is, over a whole run read in chunks: the median of the chunks'
    MAD of sample-to-sample differences over the span between the 1st and 99th
    percentiles (the lowest and highest of the chunks')."""

    def __init__(self) -> None:
        self._noises: list[float] = []
        self._low, self._high = math.inf, -math.inf

    def partial_fit(self, values: Any) -> Self:
        """One chunk of the column's values."""
        finite = np.asarray(values, dtype=np.float64)
        finite = finite[np.isfinite(finite)]
        noise = rate_noise_dph(finite)
        if not math.isfinite(noise):
            return self
        self._noises.append(noise)
        low, high = np.percentile(finite, [1.0, 99.0])
        self._low, self._high = min(self._low, float(low)), max(self._high, float(high))
        return self

    def finish(self) -> Self:
        """The shape of every chunk taken (read with :attr:`smoothness`)."""
        return self

    @property
    def noise(self) -> float:
        """Median over the chunks of the MAD of sample-to-sample differences (NaN: none)."""
        return float(np.median(self._noises)) if self._noises else math.nan

    @property
    def span(self) -> float:
        """Span between the 1st and 99th percentiles (NaN: no chunk)."""
        return self._high - self._low if self._noises else math.nan

    @property
    def smoothness(self) -> float:
        """noise / span: small for a temperature, about 0.2 for a rate at rest (NaN when
        the column is constant)."""
        return self.noise / self.span if self.span > 0.0 else math.nan


def check_sensor_swap(temperature: ChannelShape, rate: ChannelShape, source: str = "",
                      temperature_column: str = "temperature_c",
                      rate_column: str = "rate_dph") -> None:
    """Refuse a sensor thermometer that is as rough as a rate while the rate column is as
    smooth as a temperature: swapped headers (issue 21's audit found them reported as "a
    run that spans only 0.7 °C").

    Raises
    ------
    InputError
        Names the file, both columns, their noise and span, and the fix.
    """
    rough, smooth = temperature.smoothness, rate.smoothness
    if not (rough > ROUGH_TEMPERATURE and rough > SWAP_CONTRAST * smooth):
        return
    where = f"{source}: " if source else ""
    raise InputError(
        f"{where}the headers {rate_column} and {temperature_column} look swapped: the "
        f"thermometer column {temperature_column!r} changes by {temperature.noise:.3g} from "
        f"sample to sample over a span of {temperature.span:.3g} (a rate's noise; a "
        f"temperature changes smoothly) and {rate_column!r} by {rate.noise:.3g} over "
        f"{rate.span:.3g} (a temperature's); fix the header line of the file, or map the "
        f"columns with --col {rate_column}={temperature_column} "
        f"--col {temperature_column}={rate_column}")


# -- calibrate --thermometer sensor: a chamber set-point taken for the thermometer -------------
#: Share of the moving samples of a column whose second difference is 0 (to 1e-9 of its
#: span) for it to be a noise-free ramp: a set-point, computed, never measured.
SETPOINT_SHARE = 0.99


def is_setpoint_ramp(values: Any) -> bool:
    """True for a column that moves (half its steps or more) as noise-free straight ramps:
    a chamber's set-point. A measured temperature has noise, or steps of its resolution
    between equal samples (a second difference at each step)."""
    finite = np.asarray(values, dtype=np.float64)
    finite = finite[np.isfinite(finite)]
    span = float(np.ptp(finite)) if finite.size else 0.0
    if finite.size < 100 or span <= 0.0:
        return False
    steps = np.diff(finite)
    moving = steps != 0.0
    if np.count_nonzero(moving) < 0.5 * steps.size:
        return False
    both = moving[1:] & moving[:-1]
    flat = np.abs(np.diff(steps)[both]) <= 1e-9 * span
    return bool(flat.size) and float(np.mean(flat)) >= SETPOINT_SHARE


def check_setpoint_thermometer(temperature: Any, chamber: Any, source: str = "",
                               temperature_column: str = "temperature_c",
                               chamber_column: str = "chamber_c") -> None:
    """Refuse a sensor thermometer that is a noise-free ramp beside a ``chamber_c`` that
    is not: the set-point and the sensor's headers swapped (issue 27's audit: fitted
    without a word, the gyro's drift against a temperature running ahead of it).

    Raises
    ------
    InputError
        Names the file, both columns and the fix.
    """
    if chamber is None or not is_setpoint_ramp(temperature) or is_setpoint_ramp(chamber):
        return
    where = f"{source}: " if source else ""
    raise InputError(
        f"{where}the headers {chamber_column} and {temperature_column} look swapped: the "
        f"thermometer column {temperature_column!r} moves as noise-free straight ramps (a "
        f"chamber's set-point; no sensor reads without noise) while {chamber_column!r} has a "
        f"measurement's noise; fix the header line of the file, or map the columns with "
        f"--col {temperature_column}={chamber_column} --col {chamber_column}={temperature_column}")
