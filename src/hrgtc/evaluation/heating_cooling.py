"""Heating and cooling apart: a run's bias stability and model residual by direction.

HRG drift differs between heating and cooling (Li et al., Sci. Rep. 13:6019, 2023:
−63 % heating, −48 % cooling after compensation), and a model trained on a
cool-down may hold on cooling and fall short on heating. :class:`DirectionSplit`
takes a run chunk by chunk, as :func:`~hrgtc.evaluation.run_pass.run_pass` does,
keeps the means of its 10 s blocks (raw and compensated output, model minus true
bias where the run is simulated, and df/dt from the model's causal filter) and at
the end splits the blocks by the sign of the resonator temperature's rate.

The blocks lie on the time axis (:mod:`hrgtc.core.timeline`), as the bias stability's:
a block never spans a gap or a logger restart, and the partial block a gap cuts short
is kept from half a block less one sample (:func:`~hrgtc.core.timeline.min_partial_rows`),
so a burst logger (5 s bursts every 300 s) gives one block mean per burst instead of
blocks that join two bursts 300 s apart. When no block is possible the result says why
once (:attr:`DirectionStats.reason`). The split:

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
from typing import Any, Self

import numpy as np

from hrgtc.core import records
from hrgtc.core.records import Count, Positive, Record, Statistic
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.core.timeline import (
    RESTARTS_KEY,
    is_gap,
    min_partial_rows,
    restart_rows,
    settle_threshold_s,
)
from hrgtc.drift.cross_validation import RATE_DEADBAND, heating_mask
from hrgtc.drift.features import FeatureStream
from hrgtc.model import Model

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
    partial_blocks
        Blocks (of either direction or neither) closed short at a gap and kept.
    reason
        Why neither direction has a block (None when one has).
    """

    block_s: float
    blocks: dict[str, int]
    raw_dph: dict[str, float]
    compensated_dph: dict[str, float]
    residual_rms_dph: dict[str, float] | None = None
    partial_blocks: int = 0
    reason: str | None = None

    def improvement(self, direction: str) -> float:
        """raw / compensated bias stability of one direction (NaN when either is missing)."""
        comp = self.compensated_dph[direction]
        return self.raw_dph[direction] / comp if comp > 0 else math.nan

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (:class:`DirectionStatsRecord`): one entry per direction."""
        return records.dump(self, DirectionStatsRecord, **{d: {
            "blocks": self.blocks[d], "raw_dph": self.raw_dph[d],
            "compensated_dph": self.compensated_dph[d], "improvement": self.improvement(d),
            "residual_rms_dph": None if self.residual_rms_dph is None
            else self.residual_rms_dph[d]} for d in DIRECTIONS})

    def summary(self, sensor: bool = False) -> Summary:
        """Each direction's blocks, raw and compensated bias stability, improvement and
        (a simulated run) residual against the true bias (its text: one line per
        direction; ``sensor``: the thermometer is a temperature sensor)."""
        what = "temperature" if sensor else "resonator temperature"
        title = f"heating and cooling apart (sign of the {what} rate)"
        if self.reason is not None:
            return Summary(title, (), (self.reason,), (escape(
                f"{title}: no {self.block_s:g} s block ({self.reason})"),))
        sections, layout = [], [escape(title) + ":"]
        for d in DIRECTIONS:
            block = f"{self.block_s:g} s"
            figures = [Figure(f"{d}.blocks", "blocks", self.blocks[d],
                              definition=f"{block} blocks of the run while {d}.")]
            if not self.blocks[d]:
                total = sum(self.blocks.values())
                layout.append(f"  {d}: none of the {total} blocks of {block}")
                sections.append((d, tuple(figures)))
                continue
            figures += [Figure(f"{d}.raw_dph", "raw", self.raw_dph[d], "°/h", digits=4,
                               definition=f"1σ of the {block} means of the raw rate while {d}."),
                        Figure(f"{d}.compensated_dph", "compensated", self.compensated_dph[d],
                               "°/h", digits=4, definition=f"1σ of the {block} means of the "
                               f"compensated rate while {d}."),
                        Figure(f"{d}.improvement", "improvement", self.improvement(d),
                               spec=".2f", definition="raw / compensated.")]
            line = (f"  {d}: {{{d}.blocks}} blocks, {block} bias stability raw "
                    f"{{{d}.raw_dph:.4g}} -> compensated {{{d}.compensated_dph:.4g}} °/h "
                    f"({{{d}.improvement:.2f}}×)")
            if self.residual_rms_dph is not None:
                figures.append(Figure(f"{d}.residual_rms_dph", "RMS model - true bias",
                                      self.residual_rms_dph[d], "°/h", digits=4,
                                      definition=f"RMS of the {block} means of model minus "
                                      "true bias."))
                line += f", RMS model - true bias {{{d}.residual_rms_dph:.4g}} °/h"
            layout.append(line)
            sections.append((d, tuple(figures)))
        if self.partial_blocks:
            sections.append(("gaps", (Figure("partial_blocks", "blocks cut short by a gap",
                                             self.partial_blocks),)))
            layout.append("  ({partial_blocks} blocks cut short by a gap, kept from half "
                          "a block)")
        return Summary(title, tuple(sections), layout=tuple(layout))


class DirectionRecord(Record):
    """One direction of :class:`DirectionStatsRecord`. [°/h]"""

    blocks: Count
    raw_dph: Statistic
    compensated_dph: Statistic
    improvement: Statistic
    #: null on a recorded run without ``bias_dph``
    residual_rms_dph: Statistic


class DirectionStatsRecord(Record):
    """The record of :class:`DirectionStats` (its ``to_dict``)."""

    heating: DirectionRecord
    cooling: DirectionRecord
    block_s: Positive
    partial_blocks: Count
    reason: str | None = None


class DirectionSplit:
    """Streamed block means of one run, split into heating and cooling at the end.

    Parameters
    ----------
    model
        The unit's model (its df/dt filter and the thermometer's slope sign).
    sample_rate_hz
        The run's sample rate: its period is the gap test's (:func:`~hrgtc.core.timeline.is_gap`).
        [Hz]
    """

    def __init__(self, model: Model, sample_rate_hz: float) -> None:
        settings = model.drift.settings
        self.rows = max(round(BLOCK_S * sample_rate_hz), 1)
        self.block_s = self.rows / sample_rate_hz
        self.min_rows = min(self.rows, min_partial_rows(self.rows))
        self._period_s = 1.0 / float(sample_rate_hz)
        self._warmup_s = float(settings.warmup_s)
        self._origin_s: float | None = None  # the run's first sample: the warm-up counts from it
        self._stream = FeatureStream(settings, ("df",))
        slope = float(model.thermometer.slope_hz_per_c(settings.reference_c))
        self.slope_sign = 1.0 if slope >= 0 else -1.0
        self._carry: np.ndarray | None = None  # the open block's rows (within a segment)
        self._last_s: float | None = None  # time of the last settled row
        self._means: list[np.ndarray] = []
        self._truth: bool | None = None
        self.segments = 0  # contiguous segments of settled rows
        self.partial = 0  # blocks closed short at a gap and kept
        self.dropped_rows = 0  # rows of partial blocks shorter than half a block
        self.settled_rows = 0
        self._segment_rows = 0
        self.longest_segment_rows = 0

    def partial_fit(self, freq_chunk: Any, raw_dph: np.ndarray, compensated_dph: np.ndarray,
             residual_dph: np.ndarray | None = None) -> Self:
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
        if not time.size:
            return self
        if self._origin_s is None:
            self._origin_s = float(time[0])
        # the df/dt filter's settling, in seconds on the time axis
        origin = np.full(time.size, self._origin_s)
        restarts = restart_rows(time, freq_chunk.metadata.extra.get(RESTARTS_KEY))
        if restarts.size:  # a logger restart: the filter settles again, and a block ends
            lengths = np.diff(np.append(restarts, time.size))
            origin[restarts[0]:] = np.repeat(time[restarts], lengths)
            self._origin_s = float(time[restarts[-1]])
        settled = time - origin >= settle_threshold_s(self._warmup_s)
        starts = np.zeros(time.size, dtype=bool)  # rows that start a segment
        starts[restarts] = True
        kept_time, block, starts = time[settled], block[settled], starts[settled]
        if not kept_time.size:
            return self
        self.settled_rows += kept_time.size
        starts[1:] |= is_gap(np.diff(kept_time), self._period_s)
        if self._last_s is None:
            starts[0] = True
        else:
            starts[0] |= bool(is_gap(kept_time[0] - self._last_s, self._period_s))
        self._last_s = float(kept_time[-1])
        edges = [*np.flatnonzero(starts).tolist(), kept_time.size]
        if edges[0] != 0:
            edges.insert(0, 0)
        for k in range(len(edges) - 1):
            if starts[edges[k]]:
                self._close_segment()
            self._push(block[edges[k]:edges[k + 1]])
        return self

    def _push(self, rows: np.ndarray) -> None:
        """Rows of the open segment: full blocks become means, the rest is carried."""
        self._segment_rows += rows.shape[0]
        if self._carry is not None and self._carry.shape[0]:
            rows = np.concatenate([self._carry, rows])
        complete = rows.shape[0] // self.rows
        self._carry = rows[complete * self.rows:].copy()
        if complete:
            used = rows[: complete * self.rows]
            self._means.append(used.reshape(complete, self.rows, rows.shape[1]).mean(axis=1))

    def _close_segment(self) -> None:
        """A gap (or the run's end in a segmented run): the partial block is kept from half a
        block less one sample, else dropped; a new segment starts."""
        if self._segment_rows:
            self.longest_segment_rows = max(self.longest_segment_rows, self._segment_rows)
        if self._carry is not None and self._carry.shape[0]:
            if self._carry.shape[0] >= self.min_rows:
                self._means.append(self._carry.mean(axis=0, keepdims=True))
                self.partial += 1
            else:
                self.dropped_rows += self._carry.shape[0]
        self._carry = None
        self._segment_rows = 0
        self.segments += 1

    def finish(self) -> DirectionStats:
        """The split of the blocks so far (call once, after the last chunk)."""
        if self.segments > 1:  # a segmented run: its last burst's partial block counts too
            self._close_segment()
        else:
            self.longest_segment_rows = max(self.longest_segment_rows, self._segment_rows)
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
        return DirectionStats(self.block_s, blocks, raw, comp, resid if self._truth else None,
                              partial_blocks=self.partial,
                              reason=None if any(blocks.values()) else self._reason(means))

    def _reason(self, means: np.ndarray) -> str:
        """Why no block is heating or cooling."""
        half = self.min_rows * self._period_s
        if not self.settled_rows:
            return (f"no sample is past the df/dt filter's {self._warmup_s:g} s settling "
                    "time")
        if not means.shape[0]:
            longest = self.longest_segment_rows * self._period_s
            what = (f"bursts of at most {longest:.3g} s are" if self.segments > 1
                    else f"the settled run ({longest:.3g} s) is")
            return f"{what} shorter than half the {self.block_s:g} s block ({half:.3g} s)"
        return (f"the temperature rate of all {means.shape[0]} blocks is within the dead band "
                f"({RATE_DEADBAND:.0%} of its largest magnitude): neither heating nor cooling")


def _std(values: np.ndarray) -> float:
    return float(np.std(values, ddof=1)) if values.size > 2 else math.nan
