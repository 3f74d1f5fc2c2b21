"""The recording type: one run of one gyro, its columns and metadata.

The recording contract is that of DESIGN.md: a table with one row per sample
(``time_s``, ``freq_hz``, ``rate_dph`` required; ``chamber_c``, ``housing_c``,
``input_rate_dph`` (known input rate per sample), ``temperature_c`` (a sensor on
the gyro), ``accel_x/y/z`` (accelerometer axes: motion and orientation, see
:mod:`hrgtc.recording.motion`) and ``orientation`` (the user's label) optional;
``resonator_c``, ``bias_dph`` and ``scale_ppm`` ground truth
written only by the simulator) and metadata (``unit``, ``sample_rate_hz``,
``input_rate_dph``, ``profile``, ``schema``). A multi-axis recording has these
columns per axis (``rate_dph_x``, ...; see :mod:`hrgtc.recording.axes`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from hrgtc.core.errors import RecordingError

SCHEMA_VERSION = 1

#: Column name -> (unit, required, meaning). The recording contract of DESIGN.md.
COLUMNS: dict[str, tuple[str, bool, str]] = {
    "time_s": ("s", True, "time since start, strictly increasing"),
    "freq_hz": ("Hz", True, "resonator frequency from the reference-phase loop"),
    "rate_dph": ("deg/h", True, "gyro output (rebalance loop), input rate included"),
    "chamber_c": ("degC", False, "chamber temperature"),
    "housing_c": ("degC", False, "housing thermistor temperature"),
    "resonator_c": ("degC", False, "true resonator temperature (simulator ground truth)"),
    "bias_dph": ("deg/h", False, "true gyro bias (simulator ground truth)"),
    "input_rate_dph": ("deg/h", False, "known input rate per sample (rate-table runs)"),
    "temperature_c": ("degC", False, "temperature sensor on the gyro (no frequency output)"),
    "scale_ppm": ("ppm", False, "true scale-factor error (simulator ground truth)"),
    "accel_x": ("m/s^2", False, "accelerometer x (motion and orientation; any one unit)"),
    "accel_y": ("m/s^2", False, "accelerometer y (motion and orientation; any one unit)"),
    "accel_z": ("m/s^2", False, "accelerometer z (motion and orientation; any one unit)"),
    "orientation": ("label", False, "the user's number for the unit's orientation"),
}
REQUIRED_COLUMNS = tuple(name for name, (_, required, _) in COLUMNS.items() if required)


@dataclass(frozen=True)
class Metadata:
    """Metadata of a recording.

    Parameters
    ----------
    sample_rate_hz
        Nominal sample rate. [Hz]
    unit
        Serial number or name of the gyro.
    input_rate_dph
        Known rate on the sensitive axis during the test (e.g. the Earth-rate
        component); bias = rate - input rate. [°/h]
    profile
        Free text describing the test (e.g. ``"soak -10 C"``).
    schema
        Version of the recording schema.
    extra
        Any further key/value pairs (JSON types), kept on round trips.
    """

    sample_rate_hz: float
    unit: str = "unknown"
    input_rate_dph: float = 0.0
    profile: str = ""
    schema: int = SCHEMA_VERSION
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        rate = self.sample_rate_hz
        try:
            usable = math.isfinite(rate) and rate > 0
        except TypeError:
            usable = False
        if not usable:
            raise RecordingError(
                f"metadata sample_rate_hz must be a positive number of Hz, got {rate!r}; "
                "give the logger's rate (e.g. --rate-hz 200)"
            )
        try:
            usable = math.isfinite(self.input_rate_dph)
        except TypeError:
            usable = False
        if not usable:
            raise RecordingError(
                f"metadata input_rate_dph must be a finite number of °/h, got "
                f"{self.input_rate_dph!r}; give it with --input-rate-dph"
            )

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Metadata:
        """Inverse of :meth:`to_dict`; unknown keys go into ``extra``."""
        known = {"sample_rate_hz", "unit", "input_rate_dph", "profile", "schema", "extra"}
        if not isinstance(data.get("extra") or {}, Mapping):
            raise RecordingError(f"metadata extra is {data.get('extra')!r}, not a JSON object "
                                 "of key/value pairs; fix or remove it")
        extra = dict(data.get("extra") or {})
        extra.update({k: v for k, v in data.items() if k not in known})
        if "sample_rate_hz" not in data:
            raise RecordingError("metadata has no 'sample_rate_hz'; give it (e.g. --rate-hz 200)")
        values: dict[str, Any] = {}
        for key, convert, default, option in (
            ("sample_rate_hz", float, None, "--rate-hz"),
            ("input_rate_dph", float, 0.0, "--input-rate-dph"),
            ("schema", int, SCHEMA_VERSION, None),
        ):
            raw = data.get(key, default)
            try:
                values[key] = convert(raw)
            except (TypeError, ValueError):
                fix = f"; override it with {option}" if option else ""
                raise RecordingError(f"metadata {key} is {raw!r}, not a number{fix}") from None
        return cls(
            sample_rate_hz=values["sample_rate_hz"],
            unit=str(data.get("unit", "unknown")),
            input_rate_dph=values["input_rate_dph"],
            profile=str(data.get("profile", "")),
            schema=values["schema"],
            extra=extra,
        )


class Recording:
    """Named float64 columns of equal length plus :class:`Metadata`.

    Parameters
    ----------
    columns
        Column name -> 1-D array. Converted to contiguous float64.
    metadata
        The recording's metadata.
    source
        Where the recording came from (a path), used in error messages.
    """

    def __init__(
        self,
        columns: Mapping[str, Any],
        metadata: Metadata,
        source: str | None = None,
    ) -> None:
        arrays: dict[str, np.ndarray] = {}
        length = None
        for name, values in columns.items():
            array = np.ascontiguousarray(values, dtype=np.float64)
            if array.ndim != 1:
                raise RecordingError(f"column {name!r} must be 1-D, got shape {array.shape}")
            if length is None:
                length = array.shape[0]
            elif array.shape[0] != length:
                raise RecordingError(
                    f"column {name!r} has {array.shape[0]} rows, the others {length}"
                )
            arrays[name] = array
        self._columns = arrays
        self.metadata = metadata
        self.source = source

    # -- access -----------------------------------------------------------------
    @property
    def names(self) -> tuple[str, ...]:
        """Column names, in order."""
        return tuple(self._columns)

    @property
    def columns(self) -> Mapping[str, np.ndarray]:
        """Read-only view of the column mapping."""
        return dict(self._columns)

    def __len__(self) -> int:
        return 0 if not self._columns else next(iter(self._columns.values())).shape[0]

    def __contains__(self, name: object) -> bool:
        return name in self._columns

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self._columns[name]
        except KeyError:
            where = f" in {self.source}" if self.source else ""
            raise RecordingError(
                f"column {name!r} not found{where}; columns are {list(self._columns)}"
            ) from None

    @property
    def time_s(self) -> np.ndarray:
        """Time since start. [s]"""
        return self["time_s"]

    @property
    def freq_hz(self) -> np.ndarray:
        """Resonator frequency. [Hz]"""
        return self["freq_hz"]

    @property
    def rate_dph(self) -> np.ndarray:
        """Gyro output, input rate included. [°/h]"""
        return self["rate_dph"]

    @property
    def measured_bias_dph(self) -> np.ndarray:
        """Gyro output minus the known input rate. [°/h]

        The ``input_rate_dph`` column (one input rate per sample, rate-table runs)
        when the recording has one, else the metadata's constant ``input_rate_dph``.
        """
        if "input_rate_dph" in self._columns:
            return self["rate_dph"] - self._columns["input_rate_dph"]
        return self["rate_dph"] - self.metadata.input_rate_dph

    @property
    def sample_rate_hz(self) -> float:
        """Nominal sample rate of the metadata. [Hz]"""
        return self.metadata.sample_rate_hz

    @property
    def duration_s(self) -> float:
        """Time from first to last sample plus one sample period. [s]"""
        if len(self) == 0:
            return 0.0
        return float(self.time_s[-1] - self.time_s[0]) + 1.0 / self.sample_rate_hz

    def slice(self, start: int, stop: int) -> Recording:
        """Rows ``start:stop`` as a new recording (views, no copy)."""
        return Recording(
            {k: v[start:stop] for k, v in self._columns.items()}, self.metadata, self.source
        )

    def with_columns(self, **columns: Any) -> Recording:
        """A new recording with columns added or replaced."""
        merged: dict[str, Any] = dict(self._columns)
        merged.update(columns)
        return Recording(merged, self.metadata, self.source)

    def __repr__(self) -> str:
        return (
            f"Recording(rows={len(self)}, columns={list(self._columns)}, "
            f"unit={self.metadata.unit!r}, sample_rate_hz={self.metadata.sample_rate_hz:g})"
        )


def concatenate(recordings: list[Recording]) -> Recording:
    """Join chunks of one recording (same columns and metadata) end to end."""
    if not recordings:
        raise RecordingError("nothing to concatenate")
    first = recordings[0]
    return Recording(
        {name: np.concatenate([r[name] for r in recordings]) for name in first.names},
        first.metadata,
        first.source,
    )
