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
from collections.abc import Mapping, Sequence

import numpy as np

from hrgtc import recording as rec_io
from hrgtc.compensate.compensator import Compensator, output_columns
from hrgtc.compensate.file_pass import CompensationSummary, compensate_file
from hrgtc.compensate.ranges import RangeReport
from hrgtc.core.errors import InputError, RecordingError
from hrgtc.core.progress import Progress
from hrgtc.core.summary import Figure, Summary
from hrgtc.model import InstrumentModel, UnitModel, axis_suffix
from hrgtc.model_fit import check_thermometer_kind, plausible_frequency_band
from hrgtc.recording import Recording, axis_names, axis_view
from hrgtc.recording.axes import AXIS_PATTERN
from hrgtc.settings.compensation import CompensateSettings

__all__ = ["InstrumentCompensator", "compensate_instrument_file",
           "instrument_output_columns", "match_axes", "parse_axes", "recording_axes"]


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
        :func:`~hrgtc.model_fit.plausible_frequency_band`): a sample
        outside is an error naming its column and row, as the reader does for a
        single-axis file. None: not checked here.
    partial
        The model's axes were chosen among the recording's (``--axes``): other axes of
        the recording pass through. False: a recording axis the model lacks is an error.
    """

    def __init__(self, model: InstrumentModel | UnitModel, drift: str = "frequency",
                 engine: str = "fused", gaps: str = "ignore",
                 bands_hz: dict[str, tuple[float, float]] | None = None,
                 partial: bool = False) -> None:
        self.partial = partial
        if isinstance(model, UnitModel):
            model = InstrumentModel.single(model)
        self.model = model
        self.axes = {axis: Compensator(unit, drift, engine, gaps)
                     for axis, unit in model.axes.items()}
        self.bands_hz = dict(bands_hz or {})
        self.columns = instrument_output_columns(model)
        self._rows = 0

    def transform(self, chunk: Recording,
                  at_rest: Mapping[str, np.ndarray] | None = None) -> Recording:
        """The next chunk with every axis's output columns added.

        ``at_rest``: axis (``""`` for a single axis) -> True for each sample of ``chunk``
        at rest on that axis (see :meth:`Compensator.transform`); None: all.
        """
        rest = dict(at_rest or {})
        if self.model.is_single_axis:
            result = self.axes[""].transform(chunk, rest.get(""))
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
        extra = [axis for axis in found if axis not in self.axes]
        if extra and not self.partial:
            where = f" of {chunk.source}" if chunk.source else ""
            raise RecordingError(
                f"the recording{where} has axes {', '.join(found)} but the model "
                f"{self.model.unit!r} has {', '.join(self.axes)}: axis {', '.join(extra)} "
                f"would be left uncompensated; pass --axes {','.join(self.axes)} to "
                "compensate only those")
        added: dict[str, np.ndarray] = {}
        for axis, compensator in self.axes.items():
            view = axis_view(chunk, axis)
            self._check_band(axis, view)
            result = compensator.transform(view, rest.get(axis))
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

    def ranges(self) -> RangeReport:
        """The range report of the axis that went farthest (single axis: its report)."""
        reports = [c.ranges() for c in self.axes.values()]
        return max(reports, key=lambda r: sum(r.shares().values()))

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


def recording_axes(path: str | os.PathLike[str],
                   options: rec_io.ReadOptions | None = None) -> tuple[str, ...] | None:
    """Axis names of a recording file as read with ``options`` (its column mapping); ()
    for a single-axis file. Reads the file's column names only; None when the file cannot
    be opened (reading it will say why)."""
    from hrgtc.core.errors import HrgtcError
    from hrgtc.recording.mapping import check_axis_sets, parse_columns, with_other_case

    try:
        mapping = parse_columns((options or rec_io.ReadOptions()).columns)
        with rec_io.open_source(path) as source:
            if not mapping and _header_less(source.names):
                return None  # no axis can be told: reading says the header line is missing
            mapping = with_other_case(mapping, source.names)  # as reading maps them
            names = [*mapping, *(n for n in source.names if n not in mapping.values())]
            axes = tuple(axis_names(names))
            # an incomplete axis (freq_hz_z without rate_dph_z) is the reading's error to
            # name, not an axis mismatch with the model (issue 21)
            check_axis_sets(source, names, axes, mapping)
    except (HrgtcError, OSError, ValueError):
        return None
    return axes


def _header_less(names: Sequence[str]) -> bool:
    """True for the names a CSV without a header line gets (``column_1``, ``column_2``, ...)."""
    return bool(names) and all(n == f"column_{i}" for i, n in enumerate(names, start=1))


def parse_axes(text: str | Sequence[str] | None) -> tuple[str, ...] | None:
    """``"x,y"`` (the ``--axes`` option) -> ``("x", "y")``; None or empty: None."""
    if text is None:
        return None
    items = text.split(",") if isinstance(text, str) else list(text)
    names = tuple(a.strip() for a in items if a.strip())
    bad = [a for a in names if not AXIS_PATTERN.fullmatch(a)]
    if bad:
        raise InputError(f"--axes {','.join(names)}: {bad[0]!r} is not an axis name (a letter, "
                         "then letters or digits, as the column suffixes: --axes x,y)")
    return names or None


def match_axes(model: InstrumentModel, recording_axes: Sequence[str] | None,
               axes: Sequence[str] | None = None, source: str = "",
               model_source: str = "") -> InstrumentModel:
    """The model's axes to apply to a recording with ``recording_axes``: all of each, or
    those ``axes`` names.

    A model and a recording must have the same axes: a recording axis the model lacks
    would pass through uncompensated, a model axis the recording lacks has nothing to
    compensate. Either is an error unless ``axes`` (``--axes``) says which to
    compensate. A single-axis model applies to one axis of a multi-axis recording only
    when ``axes`` names it (then it is that axis's model, its outputs suffixed).

    Raises
    ------
    InputError
        The axis sets differ and ``axes`` does not say which, or ``axes`` names an axis
        the model or the recording lacks.
    """
    if recording_axes is None:  # the file cannot be opened: reading it will say why
        return model
    found = tuple(recording_axes)
    named = tuple(a for a in model.names if a)
    where = f"the recording {source}" if source else "the recording"
    of_model = f"the model {model_source or repr(model.unit)}"
    has = f"has axes {', '.join(found)}" if found else "is single-axis"
    if axes:
        axes = tuple(axes)
        lacking = [a for a in axes if a not in found]
        if lacking:
            raise InputError(f"--axes {','.join(axes)}: {where} has no axis "
                             f"{', '.join(lacking)} (it {has})")
        if model.is_single_axis:
            if len(axes) != 1:
                raise InputError(f"--axes {','.join(axes)}: {of_model} is single-axis; name "
                                 "the one recording axis to compensate with it")
            return InstrumentModel({axes[0]: model.axes[""]}, model.unit,
                                   dict(model.provenance), model.temperature_map)
        unknown = [a for a in axes if a not in named]
        if unknown:
            raise InputError(f"--axes {','.join(axes)}: {of_model} has no axis "
                             f"{', '.join(unknown)} (its axes: {', '.join(named)})")
        return InstrumentModel({a: model.axes[a] for a in axes}, model.unit,
                               dict(model.provenance), model.temperature_map)
    if model.is_single_axis and not found:
        return model
    if model.is_single_axis:
        raise InputError(f"{where} {has} and {of_model} is single-axis: pass --axes "
                         f"{found[0]} (one of {', '.join(found)}) to compensate that axis with "
                         "it, or use the instrument's multi-axis model")
    if not found:
        raise InputError(f"{where} is single-axis (freq_hz, rate_dph) and {of_model} has "
                         f"axes {', '.join(named)}: compensate each axis's recording with a "
                         "single-axis model, or name the columns by axis (rate_dph_x, ...)")
    extra = [a for a in found if a not in named]
    missing = [a for a in named if a not in found]
    if extra or missing:
        common = [a for a in named if a in found]
        what = (f"axis {', '.join(extra)} of the recording would be left uncompensated"
                if extra else f"the model's axis {', '.join(missing)} is not in the recording")
        hint = (f"pass --axes {','.join(common)} to compensate only those" if common else
                "is it another instrument's model?")
        raise InputError(f"{where} {has} but {of_model} has axes {', '.join(named)}: {what}; "
                         f"{hint}")
    return model


def compensate_instrument_file(
    source: str | os.PathLike[str],
    output: str | os.PathLike[str],
    model: InstrumentModel,
    *,
    drift: str = "frequency",
    read_options: rec_io.ReadOptions | None = None,
    axes: Sequence[str] | None = None,
    model_source: str = "",
    force: bool = False,
    settings: CompensateSettings | None = None,
    progress: Progress | None = None,
) -> CompensationSummary:
    """Compensate every axis of a recording file into a new file (bounded memory).

    As :func:`~hrgtc.compensate.file_pass.compensate_file` (``force``, ``progress``;
    ``settings`` its chunk size, :class:`~hrgtc.settings.compensation.CompensateSettings`
    defaults when None); each axis's frequency is checked against that axis's
    plausible band. A single-axis model is compensated exactly as by
    ``compensate_file``. The model's temperature map (a raw count's map to °C from
    ``calibrate --temp-ref``) is applied unless ``read_options`` give their own
    scale and offset. The model's and the recording's axes must agree unless ``axes``
    names those to compensate (:func:`match_axes`). ``model_source`` (the model file)
    is named in the errors.
    """
    from hrgtc.thermometry.reference import options_with_map

    chunk_rows = (settings or CompensateSettings()).chunk_rows
    read_options = options_with_map(read_options, model.temperature_map)
    reading = read_options or rec_io.ReadOptions()
    for unit in model.axes.values():  # before reading: a model of the other thermometer kind
        check_thermometer_kind(reading, unit, model_source or None)
    found = recording_axes(source, reading)
    partial = bool(axes)
    if found is not None:
        model = match_axes(model, found, axes, str(source), model_source)
    if model.is_single_axis:
        return compensate_file(source, output, model.axes[""], drift=drift,
                               read_options=read_options, force=force,
                               chunk_rows=chunk_rows, progress=progress)
    compensator = InstrumentCompensator(
        model, drift, gaps=reading.gaps,
        bands_hz={axis: plausible_frequency_band(unit) for axis, unit in model.axes.items()},
        partial=partial)
    return compensate_file(source, output, model, drift=drift,  # type: ignore[arg-type]
                           read_options=reading, compensator=compensator, force=force,
                           chunk_rows=chunk_rows, progress=progress)
