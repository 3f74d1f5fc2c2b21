"""The scale-factor error of a held-out rate-table run, each axis, before and after.

A rate-table run holds known input rates at several temperatures. At each temperature
(the run's holds grouped as in the fit, :func:`hrgtc.drift.scale_factor.group_segments`),
the least-squares slope of rate − Ω against Ω over the holds (IEEE Std 1431: the bias,
common to all holds of a group, drops out) is the scale-factor error, of the gyro's output
and of the compensated output (:func:`check_scale_factor`). ``hrgtc evaluate`` of a
rate-table run and ``hrgtc calibrate --validate-rate-table`` report it.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.compensate import Compensator
from hrgtc.core import records
from hrgtc.core.records import Count, Positive, Record, Statistic
from hrgtc.drift import find_rate_segments, fit_group, group_segments
from hrgtc.drift.scale_factor import TOLERANCE_SHARE
from hrgtc.model import AxisModel, Model
from hrgtc.recording import ReadOptions, Recording

__all__ = ["STEADY_CHANGE_C", "ScaleFactorCheck", "ScaleFactorCheckRecord",
           "check_scale_factor", "steady_segments"]

PathLike = str | os.PathLike[str]

#: Largest change of the resonator temperature within a rate-table hold used for the
#: scale factor (the rest, e.g. the table at rest while the chamber slews, is left out). [°C]
STEADY_CHANGE_C = 0.2


class ScaleFactorCheckRecord(Record):
    """The record of :class:`~hrgtc.evaluation.scale_check.ScaleFactorCheck`: at each
    temperature of a held-out rate-table run, the scale-factor error raw and compensated,
    and the largest of each. [Hz, -, ppm]"""

    file: str
    axis: str
    freq_hz: list[Positive]
    holds: list[Count]
    raw_ppm: list[Statistic]
    compensated_ppm: list[Statistic]
    raw_max_ppm: Statistic
    compensated_max_ppm: Statistic


@dataclass(frozen=True)
class ScaleFactorCheck(records.Dumped):
    """Scale-factor error of a held-out rate-table run, one axis, before and after.

    At each temperature (the run's holds grouped as in the fit), the least-squares slope
    of rate − Ω against Ω over the holds (IEEE Std 1431: the bias, common to all holds
    of a group, drops out): ``raw_ppm`` of the gyro's output, ``compensated_ppm`` of the
    compensated output (bias and scale factor removed).
    """

    written_by = ScaleFactorCheckRecord  # the calibrate --json document's part

    file: str
    axis: str
    freq_hz: tuple[float, ...]
    holds: tuple[int, ...]
    raw_ppm: tuple[float, ...]
    compensated_ppm: tuple[float, ...]

    @property
    def raw_max_ppm(self) -> float:
        """Largest |raw| error over the temperatures. [ppm]"""
        return float(np.max(np.abs(self.raw_ppm))) if self.raw_ppm else float("nan")

    @property
    def compensated_max_ppm(self) -> float:
        """Largest |compensated| error over the temperatures. [ppm]"""
        return (float(np.max(np.abs(self.compensated_ppm))) if self.compensated_ppm
                else float("nan"))


def steady_segments(run: Recording, segments: Sequence[Any], model: AxisModel,
                    max_change_c: float = STEADY_CHANGE_C) -> list[Any]:
    """The holds of ``run`` at a steady temperature: the resonator temperature (from the
    thermometer) of the first and last tenth of the hold differ by at most
    ``max_change_c``. A hold while the chamber slews has another bias at its start than
    at its end, which the temperature group's one bias cannot represent."""
    kept = []
    for segment in segments:
        first, rows = segment.first_row, segment.rows
        tenth = max(1, rows // 10)
        freq = run.freq_hz
        start = float(np.mean(freq[first:first + tenth]))
        end = float(np.mean(freq[first + rows - tenth:first + rows]))
        change = model.thermometer.temperature(np.array([start, end]), warn=False)
        if abs(float(change[1] - change[0])) <= max_change_c:
            kept.append(segment)
    return kept


def check_scale_factor(path: PathLike, model: Model, options: ReadOptions,
                       table: Any = None) -> tuple[ScaleFactorCheck, ...]:
    """Scale-factor error of a held-out rate-table run, each axis with a scale factor,
    before and after (``table``: the segments of a run without an input-rate column,
    :func:`hrgtc.drift.read_segment_table`)."""
    checks = []
    compensated = Compensator(model).transform(options.read(path))
    for axis, unit_model in model.axes.items():
        sf = unit_model.scale_factor
        if sf is None:
            continue
        view = compensated if not axis else _view(compensated, axis)
        segments = steady_segments(view, find_rate_segments(view, table), unit_model)
        scale = float(unit_model.drift.settings.scales.get("f", 0.0)) or 1.0
        groups = group_segments(segments, TOLERANCE_SHARE * scale)
        freq, holds, raw, after = [], [], [], []
        comp = view["rate_comp_dph"]
        for number, group in enumerate(groups, start=1):
            if len({s.input_rate_dph for s in group}) < 2:
                continue  # one rate at this temperature: no slope to check
            freq.append(float(np.mean([s.freq_hz for s in group])))
            holds.append(len(group))
            raw.append(fit_group(group, number).k_ppm)
            done = [dataclasses.replace(s, rate_dph=float(np.mean(
                comp[s.first_row:s.first_row + s.rows]))) for s in group]
            after.append(fit_group(done, number).k_ppm)
        checks.append(ScaleFactorCheck(str(path), axis, tuple(freq), tuple(holds),
                                       tuple(raw), tuple(after)))
    return tuple(checks)


def _view(recording: Recording, axis: str) -> Recording:
    """The single-axis view of a compensated multi-axis recording (outputs included)."""
    from hrgtc.recording import axis_view

    return axis_view(recording, axis).with_columns(
        **{name: recording[f"{name}_{axis}"] for name in ("rate_comp_dph", "bias_model_dph")})
