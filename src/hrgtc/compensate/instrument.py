"""Compensation of a whole instrument: every axis of a multi-axis recording in one pass.

Each axis has its own :class:`~hrgtc.compensate.compensator.Compensator` (its own
thermometer, drift model, df/dt filter state and scale factor); a chunk of a
multi-axis recording is split into single-axis views
(:func:`hrgtc.recording.axis_view`, no copies), each axis compensated, and the
outputs added under the axis's suffix (``rate_comp_dph_x``, ``in_range_x``, ...).
A single-axis model is the one-axis case: the plain single-axis columns, unchanged.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from hrgtc import recording as rec_io
from hrgtc.compensate.compensator import (
    CompensationSummary,
    Compensator,
    check_thermometer_kind,
    compensate_file,
    output_columns,
    plausible_frequency_band,
)
from hrgtc.compensate.ranges import RangeReport
from hrgtc.errors import RecordingError
from hrgtc.model import InstrumentModel, UnitModel, axis_suffix
from hrgtc.recording import Recording, axis_names, axis_view

__all__ = ["InstrumentCompensator", "compensate_instrument_file",
           "instrument_output_columns"]


def instrument_output_columns(model: InstrumentModel) -> tuple[str, ...]:
    """Columns compensation adds for ``model``: each axis's outputs under its suffix."""
    return tuple(f"{name}{axis_suffix(axis)}" for axis, unit in model.axes.items()
                 for name in output_columns(unit))


class InstrumentCompensator:
    """Streaming compensation of every axis of an instrument, chunk by chunk.

    Parameters
    ----------
    model
        The instrument's model (:class:`~hrgtc.model.InstrumentModel`; a
        :class:`~hrgtc.model.UnitModel` is the one-axis case).
    drift, engine, gaps
        As :class:`~hrgtc.compensate.compensator.Compensator`, for every axis.
    bands_hz
        Axis -> plausible frequency band (see
        :func:`~hrgtc.compensate.compensator.plausible_frequency_band`): a sample
        outside is an error naming its column and row, as the reader does for a
        single-axis file. None: not checked here.
    """

    def __init__(self, model: InstrumentModel | UnitModel, drift: str = "frequency",
                 engine: str = "fused", gaps: str = "ignore",
                 bands_hz: dict[str, tuple[float, float]] | None = None) -> None:
        if isinstance(model, UnitModel):
            model = InstrumentModel.single(model)
        self.model = model
        self.axes = {axis: Compensator(unit, drift, engine, gaps)
                     for axis, unit in model.axes.items()}
        self.bands_hz = dict(bands_hz or {})
        self.columns = instrument_output_columns(model)
        self._rows = 0

    def process(self, chunk: Recording) -> Recording:
        """The next chunk with every axis's output columns added."""
        if self.model.is_single_axis:
            result = self.axes[""].process(chunk)
            self._rows += len(chunk)
            return result
        found = axis_names(chunk.names)
        missing = [axis for axis in self.axes if axis not in found]
        if missing:
            where = f" of {chunk.source}" if chunk.source else ""
            raise RecordingError(
                f"the recording{where} has no columns of axis {', '.join(missing)} "
                f"(its axes: {', '.join(found) or 'none, a single-axis file'}); the model "
                f"{self.model.unit!r} has axes {', '.join(self.axes)}"
            )
        added: dict[str, np.ndarray] = {}
        for axis, compensator in self.axes.items():
            view = axis_view(chunk, axis)
            self._check_band(axis, view)
            result = compensator.process(view)
            for name in output_columns(compensator.model):
                added[f"{name}_{axis}"] = result[name]
        self._rows += len(chunk)
        return chunk.with_columns(**added)

    def _check_band(self, axis: str, view: Recording) -> None:
        band = self.bands_hz.get(axis)
        if band is None:
            return
        freq = view.freq_hz
        bad = np.flatnonzero(~((freq >= band[0]) & (freq <= band[1])))
        if bad.size:
            row = self._rows + int(bad[0])
            where = f"{view.source}: " if view.source else ""
            raise RecordingError(
                f"{where}column freq_hz_{axis}, row {row}: {freq[bad[0]]!r} Hz is outside the "
                f"band {band[0]:.6g}-{band[1]:.6g} Hz this axis can reach ({bad.size} such rows "
                "in this chunk); is it another unit's file, or the wrong column?"
            )

    # -- what :func:`compensate_file` and the CLI report ----------------------------
    @property
    def samples(self) -> int:
        """Rows compensated so far."""
        return self._rows

    @property
    def out_of_range_fraction(self) -> float:
        """Largest share over the axes of samples beyond the trained temperatures."""
        return max(c.out_of_range_fraction for c in self.axes.values())

    @property
    def rate_out_of_range_fraction(self) -> float:
        """Largest share over the axes of samples beyond the trained df/dt."""
        return max(c.rate_out_of_range_fraction for c in self.axes.values())

    def ranges(self) -> RangeReport:
        """The range report of the axis that went farthest (single axis: its report)."""
        reports = [c.ranges() for c in self.axes.values()]
        return max(reports, key=lambda r: r.temperature_fraction + r.rate_fraction)

    def axis_ranges(self) -> dict[str, RangeReport]:
        """Each axis's range report."""
        return {axis: c.ranges() for axis, c in self.axes.items()}

    def summary(self) -> dict[str, Any]:
        """Per-axis shares beyond the trained ranges (plain JSON)."""
        return {axis or "-": c.ranges().to_dict() for axis, c in self.axes.items()}


def compensate_instrument_file(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str],
    model: InstrumentModel,
    *,
    drift: str = "frequency",
    read_options: rec_io.ReadOptions | None = None,
    **options: Any,
) -> CompensationSummary:
    """Compensate every axis of a recording file into a new file (bounded memory).

    As :func:`~hrgtc.compensate.compensator.compensate_file` (``options`` are its
    keyword arguments); each axis's frequency is checked against that axis's
    plausible band. A single-axis model is compensated exactly as by
    ``compensate_file``. The model's temperature map (a raw count's map to °C from
    ``calibrate --temp-ref``) is applied unless ``read_options`` give their own
    scale and offset.
    """
    from hrgtc.thermometry.reference import options_with_map

    read_options = options_with_map(read_options, model.temperature_map)
    if model.is_single_axis:
        return compensate_file(source, output, model.axes[""], drift=drift,
                               read_options=read_options, **options)
    reading = read_options or rec_io.ReadOptions()
    for unit in model.axes.values():
        check_thermometer_kind(reading, unit)
    compensator = InstrumentCompensator(
        model, drift, gaps=reading.gaps,
        bands_hz={axis: plausible_frequency_band(unit) for axis, unit in model.axes.items()})
    return compensate_file(source, output, model, drift=drift,  # type: ignore[arg-type]
                           read_options=reading, compensator=compensator, **options)
