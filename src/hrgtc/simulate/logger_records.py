"""The record of a :class:`~hrgtc.simulate.logger.Logger`: its fields in a logged run's sidecar.

One definition gives ``Logger.to_dict``/``from_dict`` and the JSON Schema of the
``logger`` part of the sidecar (``<stem>.truth.json``); see docs/architecture.md
("One result contract"). The bounds are the logger's own checks that a type can say.
"""

from __future__ import annotations

from typing import Annotated, Literal

from msgspec import Meta

from hrgtc.core import records
from hrgtc.simulate.handling import HandlingRecord
from hrgtc.simulate.reflog import ReferenceLogRecord, TemperatureChannelRecord

__all__ = ["LoggerRecord"]


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
