"""Heating and cooling apart: a run's bias stability and model residual by direction.

HRG drift differs between heating and cooling (Li et al., Sci. Rep. 13:6019, 2023:
−63 % heating, −48 % cooling after compensation), and a model trained on a
cool-down may hold on cooling and fall short on heating. :class:`DirectionSplit`
takes a run chunk by chunk, as :func:`~hrgtc.evaluation.run_pass.run_pass` does,
keeps the means of its 10 s blocks (raw and compensated output, model minus true
bias where the run is simulated, and df/dt from the model's causal filter) and at
the end splits the blocks by the sign of the resonator temperature's rate:

* heating where df/dt · sign(df/dT) > 0, cooling where < 0, with the same dead band
  (5 % of the run's largest |df/dt|, :data:`hrgtc.drift.cross_validation.RATE_DEADBAND`)
  as the cross-validation's split, so blocks at constant temperature are neither.
  For a resonator whose frequency falls as it warms (df/dT < 0, fused silica and
  the paper's unit) heating is df/dt < 0.

Per direction it gives the bias stability (1σ of the block means about their mean,
as :func:`~hrgtc.evaluation.metrics.bias_stability` for the whole run) raw and
compensated, their ratio, and the RMS of model minus true bias. The first
``warmup_s`` of the run, which training and the evaluation leave out, are left out
here too. Memory: three or four floats per 10 s block.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core.timeline import RESTARTS_KEY, restart_rows, settle_threshold_s
from hrgtc.drift.cross_validation import heating_mask
from hrgtc.drift.features import FeatureStream
from hrgtc.model import UnitModel

#: The block length of the split. [s]
BLOCK_S = 10.0
DIRECTIONS = ("heating", "cooling")


@dataclass(frozen=True)
class DirectionStats:
    """Bias stability and residual of one run's heating and cooling blocks.

    Attributes
    ----------
    block_s
        Block length. [s]
    blocks
        Direction -> number of blocks.
    raw_dph, compensated_dph
        Direction -> 1σ of the block means of the raw / compensated output (NaN with
        fewer than three blocks). [°/h]
    residual_rms_dph
        Direction -> RMS of the block means of model minus true bias (None on a
        recorded run without ``bias_dph``). [°/h]
    """

    block_s: float
    blocks: dict[str, int]
    raw_dph: dict[str, float]
    compensated_dph: dict[str, float]
    residual_rms_dph: dict[str, float] | None = None

    def improvement(self, direction: str) -> float:
        """raw / compensated bias stability of one direction (NaN when either is missing)."""
        comp = self.compensated_dph[direction]
        return self.raw_dph[direction] / comp if comp > 0 else math.nan

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types: one entry per direction."""
        def clean(v: float) -> float | None:
            return float(v) if math.isfinite(v) else None

        return {d: {"blocks": self.blocks[d], "raw_dph": clean(self.raw_dph[d]),
                    "compensated_dph": clean(self.compensated_dph[d]),
                    "improvement": clean(self.improvement(d)),
                    "residual_rms_dph": None if self.residual_rms_dph is None
                    else clean(self.residual_rms_dph[d])}
                for d in DIRECTIONS} | {"block_s": self.block_s}

    def summary(self, sensor: bool = False) -> str:
        """One line per direction (``sensor``: the thermometer is a temperature sensor)."""
        lines = []
        for d in DIRECTIONS:
            if not self.blocks[d]:
                lines.append(f"  {d}: no {self.block_s:g} s block")
                continue
            line = (f"  {d}: {self.blocks[d]} blocks, {self.block_s:g} s bias stability raw "
                    f"{self.raw_dph[d]:.4g} -> compensated {self.compensated_dph[d]:.4g} °/h "
                    f"({self.improvement(d):.2f}×)")
            if self.residual_rms_dph is not None:
                line += f", RMS model - true bias {self.residual_rms_dph[d]:.4g} °/h"
            lines.append(line)
        what = "temperature" if sensor else "resonator temperature"
        return f"heating and cooling apart (sign of the {what} rate):\n" + "\n".join(lines)


class DirectionSplit:
    """Streamed block means of one run, split into heating and cooling at the end.

    Parameters
    ----------
    model
        The unit's model (its df/dt filter and the thermometer's slope sign).
    sample_rate_hz
        The run's sample rate. [Hz]
    """

    def __init__(self, model: UnitModel, sample_rate_hz: float) -> None:
        settings = model.drift.settings
        self.rows = max(round(BLOCK_S * sample_rate_hz), 1)
        self.block_s = self.rows / sample_rate_hz
        self._warmup_s = float(settings.warmup_s)
        self._origin_s: float | None = None  # the run's first sample: the warm-up counts from it
        self._stream = FeatureStream(settings, ("df",))
        slope = float(model.thermometer.slope_hz_per_c(settings.reference_c))
        self.slope_sign = 1.0 if slope >= 0 else -1.0
        self._carry: np.ndarray | None = None
        self._means: list[np.ndarray] = []
        self._truth: bool | None = None

    def partial_fit(self, freq_chunk: Any, raw_dph: np.ndarray, compensated_dph: np.ndarray,
             residual_dph: np.ndarray | None = None) -> None:
        """The next chunk: the recording (for df/dt), raw and compensated output [°/h] and,
        on a simulated run, model minus true bias [°/h]."""
        df = self._stream.transform(freq_chunk)["df"]
        if self._truth is None:
            self._truth = residual_dph is not None
        columns = [df, raw_dph, compensated_dph]
        if self._truth:
            columns.append(residual_dph if residual_dph is not None else np.full(df.size, np.nan))
        block = np.column_stack(columns)
        time = np.asarray(freq_chunk.time_s, dtype=np.float64)
        if time.size and self._origin_s is None:
            self._origin_s = float(time[0])
        if time.size:  # the df/dt filter's settling, in seconds on the time axis
            origin = np.full(time.size, self._origin_s)
            restarts = restart_rows(time, freq_chunk.metadata.extra.get(RESTARTS_KEY))
            if restarts.size:  # a logger restart: the filter settles again
                lengths = np.diff(np.append(restarts, time.size))
                origin[restarts[0]:] = np.repeat(time[restarts], lengths)
                self._origin_s = float(time[restarts[-1]])
            block = block[time - origin >= settle_threshold_s(self._warmup_s)]
        if self._carry is not None and self._carry.shape[0]:
            block = np.concatenate([self._carry, block])
        complete = block.shape[0] // self.rows
        self._carry = block[complete * self.rows:].copy()
        if complete:
            used = block[: complete * self.rows]
            self._means.append(used.reshape(complete, self.rows, block.shape[1]).mean(axis=1))

    def result(self) -> DirectionStats:
        """The split of the blocks so far."""
        width = 4 if self._truth else 3
        means = np.concatenate(self._means) if self._means else np.empty((0, width))
        heating, cooling = heating_mask(means[:, 0], self.slope_sign)
        blocks, raw, comp, resid = {}, {}, {}, {}
        for direction, mask in zip(DIRECTIONS, (heating, cooling), strict=True):
            blocks[direction] = int(np.count_nonzero(mask))
            raw[direction] = _std(means[mask, 1])
            comp[direction] = _std(means[mask, 2])
            if self._truth:
                values = means[mask, 3]
                resid[direction] = float(np.sqrt(np.mean(values ** 2))) if values.size \
                    else math.nan
        return DirectionStats(self.block_s, blocks, raw, comp, resid if self._truth else None)


def _std(values: np.ndarray) -> float:
    return float(np.std(values, ddof=1)) if values.size > 2 else math.nan
