"""Spikes: single samples that no gyro, resonator or thermometer can produce.

IMU logs (PX4 or ArduPilot style) carry the odd garbage sample: a NaN where a
packet was lost, a rate of 10^30, a temperature of -273 °C, a resonator
frequency 20 % away from the rest of the run. A *spike* here is a row with

* a value that is not finite (NaN or infinite) in any column, or
* a value outside the physical bounds of its column (those of the validation:
  :data:`~hrgtc.recording.checks.FREQ_SAMPLE_RANGE_HZ`, ±1000 °/s for rates,
  :data:`~hrgtc.recording.checks.TEMPERATURE_RANGE_C` for temperatures; for the
  sensor thermometer, ``freq_hz`` in the temperature range), or
* a resonator frequency more than :data:`~hrgtc.recording.checks.FREQ_JUMP_FRACTION`
  away from the median of the first rows of its column.

``spikes="error"`` (the default) leaves them to the validation, whose error
names the file, column, row and value; ``spikes="drop"`` removes those rows
(:class:`SpikeFilter`) and says how many went, with the first of them, in a
:class:`~hrgtc.errors.SpikeWarning`.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping

import numpy as np

from hrgtc.errors import InputError, SpikeWarning
from hrgtc.recording.axes import base_name
from hrgtc.recording.checks import _BOUNDS, FREQ_JUMP_FRACTION, TEMPERATURE_RANGE_C

SPIKE_POLICIES: tuple[str, ...] = ("error", "drop")

__all__ = ["SPIKE_POLICIES", "SpikeFilter", "check_spike_policy"]


def check_spike_policy(spikes: str) -> str:
    """Return ``spikes`` if it is one of :data:`SPIKE_POLICIES`, else raise InputError."""
    if spikes not in SPIKE_POLICIES:
        raise InputError(f"spikes must be one of {list(SPIKE_POLICIES)}, got {spikes!r}; "
                         "'drop' removes the rows of implausible samples")
    return spikes


class SpikeFilter:
    """Drop the rows of spikes from consecutive pieces of a recording, counting them.

    Parameters
    ----------
    thermometer
        ``"resonator"`` or ``"sensor"`` (``freq_hz`` then holds a temperature [°C]).
    source
        The file, for the warning.

    Attributes
    ----------
    dropped
        Rows dropped so far.
    first
        ``(column, row, value)`` of the first spike (row in the file's data rows,
        from 0), None without any.
    """

    def __init__(self, thermometer: str = "resonator", source: str | None = None) -> None:
        self.sensor = thermometer == "sensor"
        self.source = source
        self.dropped = 0
        self.first: tuple[str, int, float] | None = None
        self._reference: dict[str, float] = {}

    def _bounds(self, name: str) -> tuple[float, float] | None:
        base = base_name(name)
        if base == "freq_hz" and self.sensor:
            return TEMPERATURE_RANGE_C
        bounds = _BOUNDS.get(base)
        return None if bounds is None else (bounds[0], bounds[1])

    def _bad(self, name: str, values: np.ndarray) -> np.ndarray:
        bad = ~np.isfinite(values)
        bounds = self._bounds(name)
        with np.errstate(invalid="ignore"):
            if bounds is not None:
                bad |= (values < bounds[0]) | (values > bounds[1])
            if base_name(name) == "freq_hz" and not self.sensor:
                if name not in self._reference and (~bad).any():
                    self._reference[name] = float(np.median(values[~bad]))
                reference = self._reference.get(name)
                if reference is not None:
                    bad |= np.abs(values - reference) > FREQ_JUMP_FRACTION * reference
        return bad

    def drop(self, columns: Mapping[str, np.ndarray], row_offset: int) -> dict[str, np.ndarray]:
        """``columns`` without the rows of spikes (the same arrays when there is none).

        Parameters
        ----------
        columns
            Float64 columns in the contract's names and units.
        row_offset
            File row of the first row of ``columns``.
        """
        keep: np.ndarray | None = None
        first: tuple[str, int, float] | None = None
        for name, values in columns.items():
            bad = self._bad(name, values)
            if bad.any():
                i = int(np.argmax(bad))
                if first is None or i < first[1]:
                    first = (name, i, float(values[i]))
                keep = ~bad if keep is None else keep & ~bad
        if keep is None or first is None:
            return dict(columns)
        if self.first is None:
            self.first = (first[0], row_offset + first[1], first[2])
        self.dropped += int(keep.size - np.count_nonzero(keep))
        return {name: values[keep] for name, values in columns.items()}

    def warn(self) -> None:
        """Issue a :class:`~hrgtc.errors.SpikeWarning` saying how many rows were dropped."""
        if not self.dropped or self.first is None:
            return
        name, row, value = self.first
        where = f"{self.source}: " if self.source else ""
        warnings.warn(
            f"{where}dropped {self.dropped} row(s) with spikes (--spikes drop); the first: "
            f"column '{name}', row {row}, value {value:.6g}",
            SpikeWarning, stacklevel=3)
