"""The records of a logged run: the :class:`~hrgtc.simulate.logger.Logger` and its sidecar.

:class:`LoggerRecord` gives ``Logger.to_dict``/``from_dict``; :class:`LoggedRunRecord` is the
sidecar (``<stem>.truth.json``, :attr:`~hrgtc.simulate.logger.LoggedRun.info`), which
:func:`~hrgtc.simulate.logger.log_run` writes through it: field order, types and the JSON
Schema from one definition (docs/architecture.md, "One result contract"). The bounds are
the logger's own checks that a type can say.
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

import msgspec
from msgspec import Meta

from hrgtc.core import records
from hrgtc.simulate.handling import HandlingRecord
from hrgtc.simulate.profiles import ProfileRecord
from hrgtc.simulate.reflog import ReferenceLogRecord, TemperatureChannelRecord

__all__ = ["LoggedRunRecord", "LoggerRecord"]


class LoggerRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """A :class:`~hrgtc.simulate.logger.Logger` in a logged run's sidecar."""

    kind: Literal["continuous", "burst"]
    sample_rate_hz: records.Positive
    burst_s: float
    period_s: float
    time_unit: str
    counter_bits: Annotated[int, Meta(ge=8, le=63)] | None
    clock_start_s: float
    jitter_s: records.NonNegative
    start: str
    timezone: str | None
    restarts_s: tuple[float, ...]
    restart_off_s: float
    run_offset_dph: float
    warmup_dph: float
    warmup_tau_s: float
    rate_unit: str
    rate_digits: Annotated[int, Meta(ge=1, le=17)] | None
    frequency: bool
    temperature: TemperatureChannelRecord | None
    reference_log: ReferenceLogRecord | None
    duplicates: int
    spikes: int
    spike_dph: float
    handling: HandlingRecord | None
    accelerometer: bool
    accel_unit: Literal["g", "mps2"]
    columns: dict[str, str]
    extra_columns: dict[str, tuple[float, float]]


class SegmentRowsRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """The rows of one segment of the program in the file, and its run."""

    first_row: records.Count
    last_row: records.Count
    run: records.Count
    start_s: float
    end_s: float


class RestartRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """A power cycle: the first row after it and the new run's turn-on offset."""

    row: records.Count
    time_s: float
    run_offset_dph: float


class SpikeRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """A single-sample spike written into a rate column."""

    row: records.Count
    axis: str | None
    column: str
    size_dph: float
    size_written: float


class ReferenceLogInfoRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """The hand log beside the file: how to read it and its true readings."""

    probe_column: str
    start: str
    lag_s: float
    recording_clock_zero: str
    hrgtc_options: list[str]
    readings: list[dict[str, Any]]


class TemperatureInfoRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """The logged temperature channel: its column, source, count map and range."""

    column: str
    source: Literal["die", "housing"]
    map: dict[str, Any]
    rate_hz: records.Positive | None
    range_c: records.Range
    reference_log: ReferenceLogInfoRecord | None = None

    omit_when_default = ("reference_log",)


class SpreadRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """Range and 1st/99th percentiles of a rate of change while the unit is still."""

    min: float
    max: float
    p01: float
    p99: float


class OrientationRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """An orientation visited: gravity in the body frame and each axis's offset change."""

    index: records.Count
    gravity_body_g: tuple[float, float, float]
    offset_dph: dict[str, float]


class HandlingWindowRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """A handling window between two orientations."""

    start_s: float
    end_s: float
    peak_dps: float
    from_: records.Count = msgspec.field(name="from")
    to: records.Count


class LoggedRunRecord(records.Record, kw_only=True, forbid_unknown_fields=True):
    """A logged run's sidecar (``<stem>.truth.json``)."""

    simulated: bool
    seed: int
    unit: str
    profile: str
    chamber_program: ProfileRecord
    logger: LoggerRecord
    rows: records.Count
    simulated_rows: records.Count
    duration_s: float
    columns: dict[str, str]
    rate_unit: str
    time_unit: str
    segments: list[SegmentRowsRecord]
    restarts: list[RestartRecord]
    spikes: list[SpikeRecord]
    temperature: TemperatureInfoRecord | None
    dfdt_still: dict[str, dict[str, SpreadRecord]]
    motion_rows: records.Count
    motion_peak_dps: records.NonNegative
    orientations: list[OrientationRecord]
    handling_windows: list[HandlingWindowRecord]
    duplicates: list[int]
    hrgtc_options: list[str]
