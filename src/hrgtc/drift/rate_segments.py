"""Rate-table segments: stretches of a run at a known, constant input rate.

A scale-factor test (IEEE Std 1431-2004, Sec. 10.3.3) turns the gyro at known
rates, e.g. 0, ±10, ±100, ±300 °/s, held for a while each, at several
temperatures. The input rate comes either as a per-sample column
``input_rate_dph`` of the recording or as a segment table, a CSV file
``start_s,end_s,input_rate_dph`` with one row per hold. Each hold becomes a
:class:`RateSegment`: the means of the output rate and of the resonator
frequency over its rows, after the table has settled (``settle_s``).

:func:`segment_scale_errors` measures the scale-factor error of every segment,
(rate - bias) / input - 1 in ppm, on a raw or a compensated run.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.records import Count
from hrgtc.core.summary import Figure, Summary
from hrgtc.recording import Recording

__all__ = [
    "RateSegment",
    "RateStep",
    "SegmentScaleErrors",
    "find_rate_segments",
    "read_segment_table",
    "segment_scale_errors",
]

#: Columns of a segment table, in this order in the header (others are refused).
TABLE_COLUMNS = ("start_s", "end_s", "input_rate_dph")
#: Default time left out after each change of the input rate. [s]
SETTLE_S = 5.0
#: Default shortest segment kept (after the settling time). [s]
MIN_DURATION_S = 10.0


@dataclass(frozen=True)
class RateStep:
    """One row of a segment table: input rate ``input_rate_dph`` from ``start_s`` to ``end_s``.

    Attributes
    ----------
    start_s, end_s
        Start and end of the hold, in the recording's ``time_s``. [s]
    input_rate_dph
        Known rate on the sensitive axis. [°/h]
    """

    start_s: float
    end_s: float
    input_rate_dph: float


@dataclass(frozen=True)
class RateSegment(records.Written):
    """A stretch of a run at a constant, known input rate, and its means.

    Attributes
    ----------
    start_s, end_s
        Time of the first and of the last row used (both included). [s]
    input_rate_dph
        Known input rate. [°/h]
    rate_dph
        Mean gyro output over the rows. [°/h]
    freq_hz
        Mean resonator frequency over the rows (or temperature, for a sensor thermometer). [Hz]
    rows
        Number of rows used.
    first_row
        Index of the first row used in the recording (rows ``first_row:first_row + rows``).
    """

    start_s: float
    end_s: float
    input_rate_dph: float
    rate_dph: float
    freq_hz: float
    rows: Count
    first_row: Count = 0


def read_segment_table(path: str | Path) -> tuple[RateStep, ...]:
    """Read a segment table, a CSV file with the header ``start_s,end_s,input_rate_dph``.

    Blank lines and lines starting with ``#`` are skipped. Every value must be a
    finite number, ``start_s < end_s``, and the holds must be in time order without
    overlapping; errors name the file, the line and row (data rows from 0) and the column.

    Parameters
    ----------
    path
        The CSV file.

    Returns
    -------
    tuple of RateStep
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read the segment table ({exc})") from exc
    lines = [(n, line) for n, line in enumerate(text.splitlines(), start=1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise InputError(f"{path}: the segment table is empty; write the header "
                         f"{','.join(TABLE_COLUMNS)} and one row per hold")
    header_line, header = lines[0]
    names = [name.strip() for name in next(csv.reader([header]))]
    if names != list(TABLE_COLUMNS):
        raise InputError(f"{path}: line {header_line}: header {names} is not "
                         f"{list(TABLE_COLUMNS)}; write exactly '{','.join(TABLE_COLUMNS)}'")
    steps: list[RateStep] = []
    for row, (line_no, line) in enumerate(lines[1:]):
        where = f"{path}: line {line_no} (row {row})"
        fields = next(csv.reader([line]))
        if len(fields) != len(TABLE_COLUMNS):
            raise InputError(f"{where}: expected {len(TABLE_COLUMNS)} fields, got "
                             f"{len(fields)}; write start_s,end_s,input_rate_dph")
        values = []
        for name, field in zip(TABLE_COLUMNS, fields, strict=True):
            try:
                value = float(field)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise InputError(f"{where}, column '{name}': {field.strip()!r} is not a finite "
                                 "number")
            values.append(value)
        step = RateStep(*values)
        if not step.start_s < step.end_s:
            raise InputError(f"{where}, column 'end_s': end {step.end_s:g} s is not after the "
                             f"start {step.start_s:g} s")
        if steps and step.start_s < steps[-1].end_s:
            raise InputError(f"{where}, column 'start_s': start {step.start_s:g} s lies before "
                             f"the end {steps[-1].end_s:g} s of the row before; list the holds "
                             "in time order without overlaps")
        steps.append(step)
    if not steps:
        raise InputError(f"{path}: the segment table has a header but no rows")
    return tuple(steps)


def _where(recording: Recording) -> str:
    return f"{recording.source}: " if recording.source else ""


def _column_stretches(recording: Recording) -> list[tuple[int, int, float]]:
    """(start, stop, input) of each stretch of constant ``input_rate_dph``."""
    if "input_rate_dph" not in recording:
        raise InputError(f"{_where(recording)}no column 'input_rate_dph'; map the input-rate "
                         "column (--col input_rate_dph=...) or pass a segment table")
    values = recording["input_rate_dph"]
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise InputError(f"{_where(recording)}column 'input_rate_dph', row {int(bad[0])}: "
                         f"{values[bad[0]]} is not finite")
    changes = np.flatnonzero(np.diff(values) != 0.0) + 1
    starts = np.concatenate([[0], changes])
    stops = np.concatenate([changes, [values.size]])
    return [(int(a), int(b), float(values[a])) for a, b in zip(starts, stops, strict=True)]


def find_rate_segments(recording: Recording, table: Sequence[RateStep] | None = None, *,
                       settle_s: float = SETTLE_S,
                       min_duration_s: float = MIN_DURATION_S) -> tuple[RateSegment, ...]:
    """The holds of a rate-table run at constant, known input rates.

    From the ``input_rate_dph`` column (each stretch of one constant value, from
    the first row of the stretch, i.e. after each change) or, when given, from a
    segment table (rows with ``start_s + settle_s <= time_s < end_s``). The first
    ``settle_s`` of each hold (the run's first hold included) are left out (the
    table's acceleration and the rebalance loop settling); stretches shorter than
    ``min_duration_s`` after that are dropped from the column (they are the
    accelerations between holds) and are an error from a table.

    Parameters
    ----------
    recording
        The run, with ``time_s``, ``freq_hz``, ``rate_dph`` (and ``input_rate_dph``
        without a table).
    table
        Optional segment table (:func:`read_segment_table`); it takes precedence
        over the column.
    settle_s
        Time left out at the start of each hold. [s]
    min_duration_s
        Shortest hold kept, counted from its first to one sample past its last used row. [s]

    Returns
    -------
    tuple of RateSegment
        In time order.
    """
    if not (math.isfinite(settle_s) and settle_s >= 0):
        raise InputError(f"settle_s must be a finite number >= 0, got {settle_s!r}")
    if not (math.isfinite(min_duration_s) and min_duration_s >= 0):
        raise InputError(f"min_duration_s must be a finite number >= 0, got {min_duration_s!r}")
    time = recording.time_s
    period = 1.0 / recording.sample_rate_hz
    slack = 1e-6 * period  # a row exactly settle_s after the change counts as settled
    segments: list[RateSegment] = []
    if table is None:
        spans = []
        for start, stop, rate in _column_stretches(recording):
            first = start + int(np.searchsorted(time[start:stop], time[start] + settle_s - slack))
            spans.append((first, stop, rate, None))
    else:
        spans = []
        for row, step in enumerate(table):
            first = int(np.searchsorted(time, step.start_s + settle_s - slack))
            stop = int(np.searchsorted(time, step.end_s - slack))
            spans.append((first, stop, step.input_rate_dph, row))
    for first, stop, rate, row in spans:
        duration = float(time[stop - 1] - time[first]) + period if stop > first else 0.0
        if duration < min_duration_s - slack:
            if row is None:
                continue
            raise InputError(
                f"{_where(recording)}segment table row {row} ({table[row].start_s:g} to "
                f"{table[row].end_s:g} s) holds {duration:g} s of the recording after "
                f"settle_s = {settle_s:g} s, less than min_duration_s = {min_duration_s:g} s; "
                "check the table's times against time_s or lower min_duration_s")
        segments.append(RateSegment(
            start_s=float(time[first]), end_s=float(time[stop - 1]), input_rate_dph=rate,
            rate_dph=float(np.mean(recording.rate_dph[first:stop])),
            freq_hz=float(np.mean(recording.freq_hz[first:stop])),
            rows=stop - first, first_row=first))
    return tuple(segments)


@dataclass(frozen=True, eq=False)
class SegmentScaleErrors(records.Written):
    """Scale-factor error of each segment with a non-zero input rate.

    Attributes
    ----------
    segments
        The segments measured (means of ``rate_dph`` minus the bias).
    error_ppm
        (rate - bias) / input - 1 of each segment. [ppm]
    """

    segments: tuple[RateSegment, ...]
    error_ppm: records.Array[records.Statistic]

    @property
    def rms_ppm(self) -> float:
        """Root mean square of the errors. [ppm]"""
        return float(np.sqrt(np.mean(self.error_ppm ** 2))) if self.error_ppm.size else math.nan

    @property
    def max_abs_ppm(self) -> float:
        """Largest error magnitude. [ppm]"""
        return float(np.max(np.abs(self.error_ppm))) if self.error_ppm.size else math.nan

    def summary(self) -> Summary:
        """Each segment (start, input rate, frequency, scale-factor error) as a table, and
        the RMS and largest error (its text: the table and one line of totals)."""
        cells: list[Figure] = []
        rows = []
        for k, (seg, err) in enumerate(zip(self.segments, self.error_ppm, strict=True)):
            key = f"segments[{k}]"
            cells += [Figure(f"{key}.start_s", f"segment {k + 1} start", seg.start_s, "s",
                             row=str(k), column="start"),
                      Figure(f"{key}.input_rate_dps", f"segment {k + 1} input rate",
                             seg.input_rate_dph / 3600.0, "°/s", row=str(k),
                             column="input rate"),
                      Figure(f"{key}.freq_hz", f"segment {k + 1} frequency", seg.freq_hz, "Hz",
                             digits=8, row=str(k), column="frequency"),
                      Figure(f"error_ppm[{k}]", f"segment {k + 1} error", float(err), "ppm",
                             digits=4, row=str(k), column="error", definition="Scale-factor "
                             "error of the segment: (mean rate − bias − Ω) / Ω.")]
            rows.append(f"{{{key}.start_s:>10.6g}}{{{key}.input_rate_dps:>12.6g}}"
                        f"{{{key}.freq_hz:>14.8g}}{{error_ppm[{k}]:>12.4g}}")
        totals = (Figure("segments", "segments", len(self.segments)),
                  Figure("rms_ppm", "RMS error", self.rms_ppm, "ppm", digits=4,
                         definition="Root mean square of the segments' scale-factor errors."),
                  Figure("max_abs_ppm", "largest |error|", self.max_abs_ppm, "ppm", digits=4,
                         definition="Largest absolute scale-factor error of a segment."))
        layout = (f"{'start_s':>10}{'input °/s':>12}{'freq_hz':>14}{'error ppm':>12}", *rows,
                  "{segments} segments: rms {rms_ppm:.4g} ppm, max |error| {max_abs_ppm:.4g} ppm")
        return Summary("scale-factor error per rate segment",
                       (("segments", tuple(cells)), ("totals", totals)), layout=layout)


def segment_scale_errors(recording: Recording, bias_dph: Any = None, *,
                         segments: Sequence[RateSegment] | None = None,
                         table: Sequence[RateStep] | None = None,
                         settle_s: float = SETTLE_S,
                         min_duration_s: float = MIN_DURATION_S) -> SegmentScaleErrors:
    """Scale-factor error (rate - bias)/input - 1 of each segment, before or after compensation.

    Parameters
    ----------
    recording
        A raw rate-table run, or its compensated output (``rate_dph`` compensated).
    bias_dph
        Bias to subtract: one value per row, a constant, or None for none (a
        compensated run, whose bias is already removed). For a raw run pass the
        drift model's bias (or the simulator's truth ``bias_dph``). [°/h]
    segments
        The segments (e.g. found on the raw run, for the compensated one); default
        :func:`find_rate_segments` of ``recording`` with ``table``, ``settle_s`` and
        ``min_duration_s``.

    Returns
    -------
    SegmentScaleErrors
        Segments with zero input rate are left out.
    """
    if segments is None:
        segments = find_rate_segments(recording, table, settle_s=settle_s,
                                      min_duration_s=min_duration_s)
    rate = recording.rate_dph
    if bias_dph is not None:
        bias = np.asarray(bias_dph, dtype=np.float64)
        if bias.ndim > 1 or (bias.ndim == 1 and bias.size != rate.size):
            raise InputError(f"bias_dph has shape {bias.shape}; give one value per row "
                             f"({rate.size}) or a single value")
        rate = rate - bias
    kept, errors = [], []
    for seg in segments:
        if seg.input_rate_dph == 0.0:
            continue
        if seg.first_row + seg.rows > rate.size:
            raise InputError(f"{_where(recording)}segment at {seg.start_s:g} s ends at row "
                             f"{seg.first_row + seg.rows}, past the {rate.size} rows of the run")
        mean = float(np.mean(rate[seg.first_row:seg.first_row + seg.rows]))
        kept.append(seg)
        errors.append((mean / seg.input_rate_dph - 1.0) * 1e6)
    return SegmentScaleErrors(tuple(kept), np.array(errors, dtype=np.float64))
