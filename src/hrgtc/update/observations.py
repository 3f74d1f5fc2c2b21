"""Still blocks: what an in-field update observes in a recording.

A still period (the motion detector's, :meth:`hrgtc.recording.motion.MotionMask.still_periods`,
or an interval given with ``--still``) is cut into blocks of ``block_s``; each block's mean
of the compensated residual (rate - known input - the model's bias) is one observation of
the filter (:mod:`hrgtc.update.kalman`)::

    residual = ΔB0 + Δk_f · f + c_run + noise

with ``f`` the block's mean of the model's variable f, and ``c_run`` the recording's
nuisance constant: its turn-on shift, and, when the input rate is not known, the Earth-rate
projection (up to ±15 °/h on an HRG) and the offset change with it. A block whose
temperature changes faster than ``max_temperature_rate_c_per_h`` is thermally unsettled: its
residual is the model's transient, not ageing, and it is left out.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.settings.update import UpdateSettings

__all__ = ["StillBlock", "index_periods", "still_blocks", "stretches"]

_SECONDS_PER_HOUR = 3600.0


@dataclass(frozen=True)
class StillBlock:
    """One block of a still period: one observation of the update.

    Attributes
    ----------
    run
        Index of the recording among those given (its nuisance constant).
    period
        Index of the still period in the recording.
    start_s, end_s
        The block's first and last sample times. [s]
    residual_dph
        Mean of rate - known input rate - the model's bias. [°/h]
    f
        Mean of the model's variable f (freq_hz - f_ref). [Hz, or °C for a sensor]
    temperature_c
        Mean resonator temperature (the model's thermometer). [°C]
    temperature_rate_c_per_h
        Slope of the temperature over the block. [°C/h]
    white_sigma_dph
        Standard error of the mean from the samples' spread (white noise only). [°/h]
    """

    run: int
    period: int
    start_s: float
    end_s: float
    residual_dph: float
    f: float
    temperature_c: float
    temperature_rate_c_per_h: float
    white_sigma_dph: float

    @property
    def time_h(self) -> float:
        """Mid time of the block. [h]"""
        return 0.5 * (self.start_s + self.end_s) / _SECONDS_PER_HOUR


def index_periods(time_s: np.ndarray, intervals_s: Sequence[tuple[float, float]],
                  source: str) -> list[tuple[int, int]]:
    """Index ranges ``[start, stop)`` of given still intervals (``--still START:END``). [s]

    Raises
    ------
    InputError
        An interval that is reversed or holds no sample of the recording.
    """
    out = []
    for start, end in intervals_s:
        if not (math.isfinite(start) and math.isfinite(end) and start < end):
            raise InputError(f"{source}: still interval {start!r}:{end!r} s is not an ordered "
                             "pair of times (START < END)")
        a, b = np.searchsorted(time_s, [start, end], side="left")
        b = int(np.searchsorted(time_s, end, side="right"))
        if b - int(a) < 2:
            raise InputError(f"{source}: still interval {start:g}:{end:g} s holds no samples "
                             f"(the recording spans {time_s[0]:g} to {time_s[-1]:g} s)")
        out.append((int(a), b))
    return out


def still_blocks(run: int, time_s: np.ndarray, rate_dph: np.ndarray, bias_dph: np.ndarray,
                 f: np.ndarray, temperature_c: np.ndarray, periods: Sequence[tuple[int, int]],
                 settings: UpdateSettings) -> list[StillBlock]:
    """The blocks of ``block_s`` of each still period (a shorter remainder is left out).

    ``rate_dph`` is the gyro's rate minus the known input rate (0 when unknown), ``bias_dph``
    the model's bias on every sample. [°/h]
    """
    residual = np.asarray(rate_dph, dtype=np.float64) - np.asarray(bias_dph, dtype=np.float64)
    blocks = []
    for period, (a, b) in enumerate(periods):
        t = time_s[a:b]
        count = int((t[-1] - t[0]) // settings.block_s) if b - a > 1 else 0
        edges = np.searchsorted(t, t[0] + settings.block_s * np.arange(count + 1))
        for lo, hi in itertools.pairwise(edges):
            lo, hi = a + int(lo), a + int(hi)
            if hi - lo < 3:
                continue
            blocks.append(_block(run, period, time_s[lo:hi], residual[lo:hi], f[lo:hi],
                                 temperature_c[lo:hi]))
    return blocks


def _block(run: int, period: int, t: np.ndarray, residual: np.ndarray, f: np.ndarray,
           temperature: np.ndarray) -> StillBlock:
    centred = t - t.mean()
    good = np.isfinite(temperature)
    rate = (float(np.polyfit(centred[good], temperature[good], 1)[0]) * _SECONDS_PER_HOUR
            if np.count_nonzero(good) > 2 else math.nan)
    return StillBlock(run=run, period=period, start_s=float(t[0]), end_s=float(t[-1]),
                      residual_dph=float(residual.mean()), f=float(f.mean()),
                      temperature_c=float(np.nanmean(temperature)) if good.any() else math.nan,
                      temperature_rate_c_per_h=rate,
                      white_sigma_dph=float(residual.std(ddof=1) / math.sqrt(residual.size)))


def stretches(blocks: Sequence[StillBlock], block_s: float) -> np.ndarray:
    """A number per block, the same for blocks that follow each other in one still period
    (a block left out, a new period or a new run starts another stretch): where a jump is
    looked for (a step between two temperatures may be the model's misfit between them)."""
    out = np.zeros(len(blocks), dtype=np.int64)
    for k in range(1, len(blocks)):
        a, b = blocks[k - 1], blocks[k]
        apart = (a.run, a.period) != (b.run, b.period) or b.start_s - a.start_s > 1.5 * block_s
        out[k] = out[k - 1] + int(apart)
    return out


def block_noise_dph(blocks: Sequence[StillBlock], fallback_dph: float) -> float:
    """1σ of one block's mean beyond white noise, from the data: the robust spread (MAD) of
    successive blocks' residual differences within a run, over √2 (a constant, a slow trend
    and a single jump barely move it). ``fallback_dph`` with fewer than three differences.
    [°/h]"""
    differences = [b2.residual_dph - b1.residual_dph for b1, b2 in itertools.pairwise(blocks)
                   if b1.run == b2.run]
    if len(differences) < 3:
        return fallback_dph
    mad = float(np.median(np.abs(np.asarray(differences) - np.median(differences))))
    return 1.482602218505602 * mad / math.sqrt(2.0)


def describe_blocks(blocks: Sequence[StillBlock]) -> dict[str, Any]:
    """Count, temperature span and largest temperature rate of ``blocks`` (plain types)."""
    if not blocks:
        return {"n_blocks": 0, "span_c": 0.0, "max_rate_c_per_h": 0.0}
    temperatures = [b.temperature_c for b in blocks]
    return {"n_blocks": len(blocks), "span_c": float(np.nanmax(temperatures)
                                                     - np.nanmin(temperatures)),
            "max_rate_c_per_h": float(np.nanmax([abs(b.temperature_rate_c_per_h)
                                                 for b in blocks]))}
