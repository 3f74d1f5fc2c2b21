"""Compensation: subtract the drift model from a gyro's output, in batch or streaming.

One :class:`Compensator` serves a model of one axis or many (as pvlib's ModelChain
serves one array or several): each axis has its own
:class:`~hrgtc.compensate.axis.AxisCompensator` (its own thermometer, drift model, df/dt
filter state and scale factor). A single-axis model adds the plain columns
(``rate_comp_dph``, ``in_range``, ...); a multi-axis recording is split into single-axis
views (:func:`hrgtc.recording.axis_view`, no copies), each axis compensated, and the
outputs added under the axis's suffix (``rate_comp_dph_x``, ``in_range_x``, ...).

The streaming :class:`Compensator` keeps the causal df/dt filter's state between chunks,
so a file of any size is compensated in bounded memory and any chunking gives the batch
result (file to file: :func:`hrgtc.compensate.file_pass.compensate_file`). The batch
:func:`compensate` is "new compensator, one chunk". Eq. (22) of [1] applied as in
Section 4.2 (Fig. 6).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from hrgtc.compensate.axis import ENGINES, OUTPUT_COLUMNS, SCALE_COLUMN, AxisCompensator
from hrgtc.compensate.axis import output_columns as axis_output_columns
from hrgtc.compensate.ranges import RangeReport
from hrgtc.core.errors import InputError, RecordingError
from hrgtc.core.summary import Figure, Summary
from hrgtc.model import Model, axis_suffix
from hrgtc.recording import Recording, axis_names, axis_view

__all__ = ["ENGINES", "OUTPUT_COLUMNS", "SCALE_COLUMN", "Compensator", "compensate",
           "output_columns"]


def output_columns(model: Model) -> tuple[str, ...]:
    """Columns compensation with ``model`` adds: each axis's outputs under its suffix
    (:data:`OUTPUT_COLUMNS`, and :data:`SCALE_COLUMN` for an axis with a scale factor;
    plain for a single-axis model)."""
    return tuple(f"{name}{axis_suffix(axis)}" for axis, part in model.axes.items()
                 for name in axis_output_columns(part))


class Compensator:
    """Streaming compensation of every axis of a model, chunk by chunk.

    Parameters
    ----------
    model
        The model (:class:`~hrgtc.model.Model`; a single-axis unit is the one-axis case,
        its outputs the plain columns).
    drift
        Which drift model to apply: ``"frequency"`` (the paper's, default) or
        ``"housing"`` (the classical thermistor baseline kept in the model file).
    engine
        ``"fused"`` (one compiled pass per chunk, default) or ``"numpy"`` (the
        array-by-array reference); both give the same numbers to rounding. A model
        with the heating/cooling switch ``dpos``, the second rate filter ``d2`` or an
        extra channel ``a_NAME`` runs on the numpy engine either way.
    gaps
        ``"split"``: the df/dt filter restarts at rest after every gap; any other
        policy (``"bridge"``, ``"error"``, ``"ignore"``, default): the filter is carried
        across the gap with the gap's Δt (see :class:`~hrgtc.compensate.axis.AxisCompensator`).
    bands_hz
        Axis -> plausible frequency band (see
        :func:`~hrgtc.model_fit.plausible_frequency_band`): a sample outside is an error
        naming its column and row, as the reader does for a single-axis file. None: not
        checked here.
    partial
        The model's axes were chosen among the recording's (``--axes``): other axes of
        the recording pass through. False: a recording axis the model lacks is an error.

    Examples
    --------
    >>> # comp = Compensator(load_model("unit.json"))
    >>> # for chunk in iter_chunks("run.parquet"): out = comp.transform(chunk)
    """

    def __init__(self, model: Model, drift: str = "frequency", engine: str = "fused",
                 gaps: str = "ignore", bands_hz: dict[str, tuple[float, float]] | None = None,
                 partial: bool = False) -> None:
        self.partial = partial
        self.model = model
        self.axes = {axis: AxisCompensator(part, drift, engine, gaps)
                     for axis, part in model.axes.items()}
        self.bands_hz = dict(bands_hz or {})
        self.columns = output_columns(model)
        self._rows = 0

    @property
    def axis(self) -> AxisCompensator:
        """The only axis's engine (its counters: ``settling``, ``segments``, ...); a
        multi-axis model raises, naming its axes."""
        if len(self.axes) == 1:
            return next(iter(self.axes.values()))
        raise InputError(f"the model of {self.model.unit!r} has axes "
                         f"{', '.join(self.axes)}: pick one, compensator.axes[name]")

    def transform(self, chunk: Recording,
                  at_rest: Mapping[str, np.ndarray] | np.ndarray | None = None) -> Recording:
        """The next chunk with every axis's output columns added.

        ``at_rest``: axis (``""`` for a single axis) -> True for each sample of ``chunk``
        at rest on that axis (see :meth:`AxisCompensator.transform`), or the one array of
        a single-axis model; None: all.
        """
        rest = at_rest if isinstance(at_rest, Mapping) else {"": at_rest}
        if "" in self.axes:  # the plain columns: the axis's output as it is
            result = self.axes[""].transform(chunk, rest.get(""))
            self._rows += len(chunk)
            return result
        self._check_axes(chunk)
        added: dict[str, np.ndarray] = {}
        for axis, compensator in self.axes.items():
            view = axis_view(chunk, axis)
            self._check_band(axis, view)
            result = compensator.transform(view, rest.get(axis))
            for name in axis_output_columns(compensator.model):
                added[f"{name}_{axis}"] = result[name]
        self._rows += len(chunk)
        return chunk.with_columns(**added)

    def warm(self, chunk: Recording) -> None:
        """Load the fused kernel for ``chunk``'s column types, compensating nothing
        (:meth:`AxisCompensator.warm`, each axis on its view)."""
        for axis, compensator in self.axes.items():
            compensator.warm(axis_view(chunk, axis) if axis else chunk)

    def _check_axes(self, chunk: Recording) -> None:
        found = axis_names(chunk.names)
        missing = [axis for axis in self.axes if axis not in found]
        where = f" of {chunk.source}" if chunk.source else ""
        if missing:
            raise RecordingError(
                f"the recording{where} has no columns of axis {', '.join(missing)} "
                f"(its axes: {', '.join(found) or 'none, a single-axis file'}); the model "
                f"{self.model.unit!r} has axes {', '.join(self.axes)}"
            )
        extra = [axis for axis in found if axis not in self.axes]
        if extra and not self.partial:
            raise RecordingError(
                f"the recording{where} has axes {', '.join(found)} but the model "
                f"{self.model.unit!r} has {', '.join(self.axes)}: axis {', '.join(extra)} "
                f"would be left uncompensated; pass --axes {','.join(self.axes)} to "
                "compensate only those")

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
                f"{where}column freq_hz_{axis}, row {row}: {float(freq[bad[0]])!r} Hz is outside "
                f"the band {band[0]:.6g} to {band[1]:.6g} Hz this axis can reach ({bad.size} such "
                "rows in this chunk); is it another unit's file, or the wrong column?"
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

    def worst(self) -> AxisCompensator:
        """The axis's engine that went farthest beyond its trained ranges."""
        return max(self.axes.values(), key=lambda c: sum(c.ranges().shares().values()))

    def ranges(self) -> RangeReport:
        """The range report of the axis that went farthest (single axis: its report)."""
        return self.worst().ranges()

    def axis_ranges(self) -> dict[str, RangeReport]:
        """Each axis's range report."""
        return {axis: c.ranges() for axis, c in self.axes.items()}

    def summary(self) -> Summary:
        """Each axis's samples so far and their shares beyond the trained temperature and
        df/dt (and still settling), with the trained and seen ranges; a section per axis."""
        sections = []
        for axis, compensator in self.axes.items():
            r = compensator.ranges()
            figures = (
                Figure("samples", "samples", r.samples),
                Figure("temperature_fraction", "beyond the trained temperatures",
                       r.temperature_fraction, spec=".2%", definition="Share of the samples "
                       "whose temperature is outside the trained range."),
                Figure("rate_fraction", "beyond the trained df/dt", r.rate_fraction, spec=".2%",
                       definition="Share of the samples whose df/dt is outside the trained "
                       "range."),
                Figure("settling_fraction", "df/dt filter settling", r.settling_fraction,
                       spec=".2%"),
                Figure("seen_c", "temperatures seen", r.seen_c[1] - r.seen_c[0], "°C",
                       tuple(r.seen_c), "range"),
                Figure("trained_c", "temperatures trained", r.trained_c[1] - r.trained_c[0],
                       "°C", tuple(r.trained_c), "range"))
            one = Summary("", ((f"axis {axis or '-'}", figures),))
            sections += one.renamed(f"axes.{axis or '-'}.").sections
        return Summary(f"instrument {self.model.unit}: shares beyond the trained ranges",
                       tuple(sections))


def compensate(model: Model, recording: Recording, drift: str = "frequency",
               engine: str = "fused") -> Recording:
    """Batch compensation of a whole run: a new :class:`Compensator`, one chunk."""
    return Compensator(model, drift, engine).transform(recording)
