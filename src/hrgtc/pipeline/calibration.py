"""Calibrate a gyro or a whole instrument: one chain for one axis or many.

Sections 3 and 4 of [1] run on files, for every axis of the recordings: a multi-axis
recording holds one resonator per axis (``freq_hz_x``, ``rate_dph_x``, ...), a single-axis
file is the one-axis case (as pvlib's ``ModelChain`` serves one array or several with one
result type). Each axis gets its own thermometer and drift model
(:func:`hrgtc.pipeline.axis_calibration.fit_axis` on its view of the files), then, given
rate-table runs, its scale-factor error against frequency
(:func:`hrgtc.drift.scale_factor.fit_scale_factor`); the held-out runs are evaluated every
axis at once (:func:`hrgtc.evaluation.evaluate`), held-out rate-table runs give the
scale-factor error before and after. Gyros without a frequency output
(``read_options.thermometer="sensor"``) run the same chain on their temperature sensor.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.compensate.ranges import RangeReport
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.files import hash_ahead
from hrgtc.core.progress import StageProgress
from hrgtc.core.summary import Summary
from hrgtc.drift import ScaleFactorModel, find_rate_segments, fit_scale_factor, read_segment_table
from hrgtc.evaluation import Evaluation, evaluate
from hrgtc.evaluation.calibration_figures import instrument_summary
from hrgtc.evaluation.run_evaluation import warn_worse_than_raw
from hrgtc.evaluation.scale_check import ScaleFactorCheck, check_scale_factor, steady_segments
from hrgtc.model import AxisModel, Model, provenance
from hrgtc.pipeline import documents
from hrgtc.pipeline.axis_calibration import HOUSING_TERMS, AxisCalibration, fit_axis
from hrgtc.pipeline.holdout import holdout_split
from hrgtc.pipeline.terms import parse_aux
from hrgtc.recording import ReadOptions, Recording, axis_names
from hrgtc.recording.marks import refuse_compensated_training
from hrgtc.recording.read_once import ReadOnce
from hrgtc.settings.calibration import CROSS_AXIS_GAIN, CalibrationSettings
from hrgtc.settings.compensation import BIAS_ONLY
from hrgtc.settings.inputs import CalibrationInputs, TemperatureReferenceSettings
from hrgtc.settings.reading import ReadSettings
from hrgtc.thermometry.prior import ThermometerPrior
from hrgtc.thermometry.reference import TemperatureMap, TemperatureReference

__all__ = ["HOUSING_TERMS", "AxisCalibration", "Calibration", "RateTables", "calibrate",
           "fit_axis_scale_factor", "summary_rows"]

PathLike = str | os.PathLike[str]


@dataclass(frozen=True)
class RateTables:
    """The rate-table runs of a calibration (known input rates at several temperatures).

    Attributes
    ----------
    runs
        Runs to fit each axis's scale factor against frequency on; the input rate as the
        ``input_rate_dph`` column or ``segment_table``. None given: bias only.
    validate
        Held-out rate-table runs: scale-factor error before and after, per axis.
    segment_table
        CSV ``start_s,end_s,input_rate_dph`` of the runs' segments, for files without an
        input-rate column.
    """

    runs: Sequence[PathLike] = ()
    validate: Sequence[PathLike] = ()
    segment_table: PathLike | None = None


@dataclass(frozen=True)
class Calibration:
    """What :func:`calibrate` produced: the model and each axis's evidence.

    For a single-axis unit (``axes == {"": ...}``) ``plateaus``, ``table``,
    ``validation`` and ``prior_fit`` read the only axis's (a multi-axis calibration
    raises, naming its axes: ``calibration.axes['x'].validation``), as
    :class:`~hrgtc.model.Model` does for its parts.

    Attributes
    ----------
    model
        The model of every axis, with provenance.
    axes
        Axis (``""`` for a single-axis unit) -> :class:`AxisCalibration`: the axis as a
        one-axis model, its plateaus, Tables 1-2 and held-out runs.
    scale_checks
        The held-out rate-table runs' scale-factor error, each axis.
    cross_axis
        Axis -> the cross-axis trial (channels, held-out figures with and without, kept).
    """

    model: Model
    axes: dict[str, AxisCalibration]
    scale_checks: tuple[ScaleFactorCheck, ...] = ()
    cross_axis: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def axis(self) -> AxisCalibration:
        """The only axis's calibration; a multi-axis calibration raises, naming its axes."""
        if len(self.axes) != 1:
            first = next(iter(self.axes))
            raise InputError(f"the calibration of {self.model.unit!r} has axes "
                             f"{', '.join(self.axes)}: pick one: calibration.axes[{first!r}]")
        return next(iter(self.axes.values()))

    @property
    def plateaus(self) -> tuple[Any, ...]:
        """The only axis's plateaus (:attr:`AxisCalibration.plateaus`)."""
        return self.axis.plateaus

    @property
    def table(self) -> tuple[dict[str, float], ...]:
        """The only axis's Tables 1 and 2 (:attr:`AxisCalibration.table`)."""
        return self.axis.table

    @property
    def validation(self) -> tuple[Evaluation, ...]:
        """The only axis's held-out runs (:attr:`AxisCalibration.validation`)."""
        return self.axis.validation

    @property
    def prior_fit(self) -> Any:
        """The only axis's posterior under a population prior, if any."""
        return self.axis.prior_fit

    def summary(self) -> Summary:
        """The instrument's figures beside its axes' own (held-out rate tables, cross-axis
        trials, each axis's held-out medians; each axis's own: ``axes[a].summary()``); see
        :func:`hrgtc.evaluation.calibration_figures.instrument_summary`."""
        return instrument_summary(self)

    def to_dict(self) -> dict[str, Any]:
        """The document of ``hrgtc calibrate --json``: a single-axis unit without a scale
        factor as :meth:`AxisCalibration.to_dict` with its held-out runs
        (:class:`~hrgtc.pipeline.documents.CalibrationDocumentRecord`), else one entry per
        axis (``"-"`` for a single axis) with the held-out runs of a single axis
        (:class:`~hrgtc.pipeline.documents.InstrumentCalibrationRecord`); the temperature
        map (``--temp-ref``) when the model has one. Its JSON Schema:
        :func:`hrgtc.pipeline.documents.calibrate_json_schema`."""
        single = self.model.is_single_axis
        validation = [v.to_dict() for v in self.axes[""].validation] if single else None
        if single and not self.scale_checks and self.model.axes[""].scale_factor is None:
            return records.dump(self.axes[""], documents.CalibrationDocumentRecord,
                                **{**self.axes[""].document_parts(), "validation": validation},
                                temperature_map=self.model.temperature_map)
        axes = {}
        for axis, result in self.axes.items():
            sf = self.model.axes[axis].scale_factor
            axes[axis or "-"] = {**result.document_parts(),
                                 "scale_factor": None if sf is None else sf.to_dict()}
        return records.dump(self, documents.InstrumentCalibrationRecord, unit=self.model.unit,
                            axes=axes, scale_factor_checks=[c.to_dict()
                                                            for c in self.scale_checks],
                            validation=validation, temperature_map=self.model.temperature_map)

    def range_reports(self) -> dict[str, dict[str, RangeReport]]:
        """Held-out file -> axis -> its range report, where any axis went beyond the
        trained temperature or df/dt (``--strict`` fails then)."""
        out: dict[str, dict[str, RangeReport]] = {}
        for axis, result in self.axes.items():
            for run in result.validation:
                if run.ranges is not None and run.range_warnings():
                    out.setdefault(run.file, {})[axis] = run.ranges
        return out


def calibrate(
    soaks: Sequence[PathLike],
    drifts: Sequence[PathLike],
    validate: Sequence[PathLike] = (),
    *,
    settings: CalibrationSettings | None = None,
    inputs: CalibrationInputs | None = None,
    rate_tables: RateTables | None = None,
    prior: ThermometerPrior | PathLike | None = None,
    read_options: ReadOptions | None = None,
    progress: StageProgress | None = None,
) -> Calibration:
    """Calibrate a gyro or every axis of an instrument (a single-axis file: the one axis).

    Parameters
    ----------
    soaks
        Soak recordings (one per set-point, or files holding several); a multi-axis file
        holds every axis's columns.
    drifts
        Ramp recordings to fit each axis's drift model on (cool-down, warm-up, cycles);
        with two training runs or more (the soaks count) the fit reports each run's
        leave-one-run-out cross-validated bias stability, heating and cooling apart.
    validate
        Held-out runs: bias stability raw and compensated, each axis.
    settings
        The thermometer's order, the drift fit, whether the soaks join it
        (:func:`hrgtc.pipeline.axis_calibration.fit_axis`), ``scale_terms`` (candidate
        terms of the scale-factor model, in f as the drift model's) and ``cross_axis``:
        also try the other resonators' frequencies as candidate terms of each axis's drift
        model (a temperature difference across the unit is a gradient one resonator alone
        cannot see); kept per axis only where the held-out ``validate`` runs' 10 s bias
        stability improves by more than :data:`CROSS_AXIS_GAIN` (the decision is in
        :attr:`Calibration.cross_axis`). Its defaults when None.
    inputs
        What the calibration takes beside its recordings and its tuning
        (:class:`~hrgtc.settings.inputs.CalibrationInputs`, as ``hrgtc calibrate``'s
        options give them): extra logged channels as drift variables (``aux``,
        ``NAME=COLUMN``), a reference log of the temperature to fit the raw count's map
        from on the whole first drift run, stored in the model and applied to every file
        (``reference``), and the held-out end of the one drift file (``holdout``,
        :func:`~hrgtc.pipeline.holdout.holdout_split`).
    rate_tables
        Rate-table runs for each axis's scale factor and held-out ones to check it
        (:class:`RateTables`); None: bias only.
    prior
        A population prior (:class:`~hrgtc.thermometry.prior.ThermometerPrior` or its
        file, ``hrgtc fleet prior``): each thermometer is the posterior of the prior and
        the soaks (two or three suffice).
    read_options
        Column mapping, units, metadata overrides for every file; its ``thermometer``:
        ``"resonator"`` (the resonator's frequency, [1]) or ``"sensor"`` (a gyro without a
        frequency output: its temperature sensor, ``temperature_c``, is the thermometer;
        no soaks needed); its ``axis``: calibrate that axis of multi-axis files alone, as
        a single-axis model (None: every axis of the files).
    progress
        Optional ``callback(stage, done, total)``; stages are prefixed with the axis.
    """
    settings = settings or CalibrationSettings()
    inputs = inputs or CalibrationInputs()
    tables = rate_tables or RateTables()
    aux = parse_aux(inputs.aux)
    reading = _reading(soaks, drifts, validate, inputs, tables, read_options or ReadOptions(),
                       progress)
    fitted, models, crossed = _fit_axes(soaks, drifts, reading, settings, aux, prior, tables,
                                        progress)
    temperature_map = reading.temperature_map
    instrument = Model(models, next(iter(fitted.values())).model.unit,
                       _provenance(soaks, drifts, tables, fitted, settings, inputs, reading),
                       None if temperature_map is None else temperature_map.to_dict())
    # each held-out run read once for every axis
    # (a model worse than raw on its own held-out part is said)
    runs = [warn_worse_than_raw(evaluate(instrument, path, settings=BIAS_ONLY,
                                         read_options=reading.held_out)).axes
            for path in reading.validate]
    checks = tuple(check for path in tables.validate for check in check_scale_factor(
        path, instrument, reading.options, reading.segments))
    return Calibration(instrument, {axis: dataclasses.replace(
        fitted[axis], model=instrument.of_axis(axis),
        validation=tuple(run[axis] for run in runs)) for axis in reading.axes}, checks, crossed)


@dataclass(frozen=True)
class _Reading:
    """How :func:`calibrate` reads its files, after the temperature map and the hold-out
    split: the training files' options (every axis from one reading: a
    :class:`~hrgtc.recording.read_once.ReadOnce`), the held-out runs' and which they are,
    the axes, the map and its reference log, the rate tables' segments."""

    options: ReadOptions
    held_out: ReadOptions
    validate: Sequence[PathLike]
    axes: tuple[str, ...]
    temperature_map: TemperatureMap | None
    reference: TemperatureReference | None
    segments: Any


def _reading(soaks: Sequence[PathLike], drifts: Sequence[PathLike],
             validate: Sequence[PathLike], inputs: CalibrationInputs, tables: RateTables,
             options: ReadOptions, progress: StageProgress | None) -> _Reading:
    """The reading of :func:`calibrate`'s files (the parameters are its own), every file
    refused when it is a compensated output."""
    # the provenance's SHA-256 of every input, on the second core while the fits read them
    hash_ahead([*soaks, *drifts, *validate, *tables.runs, *tables.validate])
    if options.thermometer not in ("resonator", "sensor"):
        raise InputError("thermometer must be 'resonator' or 'sensor', got "
                         f"{options.thermometer!r}")
    reference = temperature_reference(inputs.reference)
    temperature_map = None
    if reference is not None and drifts:  # all of the first run, before a split
        temperature_map = reference.fit(drifts[0], options)
        options = _through_map(options, temperature_map)
    validate_options = None
    holdout = inputs.holdout
    if holdout.holdout_s is not None or holdout.holdout_fraction is not None:
        options, validate_options, validate = holdout_split(
            options, soaks, drifts, validate, holdout.holdout_s, holdout.holdout_fraction)
        if progress is not None:
            progress(f"held out {drifts[0]} from {options.end} s on", 1.0, 1.0)
    if not drifts:
        raise InputError("no drift recordings given; pass --drift FILE (a cool-down or warm-up)")
    refuse_compensated_training([*soaks, *drifts, *validate, *tables.runs, *tables.validate])
    # every axis of the files, or the one axis the reading names (``read_options.axis``)
    axes = ("",) if options.axis else _axes_of(drifts[0], options)
    if len(axes) > 1:  # every axis calibrated from one reading of each file
        options = ReadOnce(**{f.name: getattr(options, f.name)
                              for f in dataclasses.fields(ReadOptions)})
    held_out = options if validate_options is None else _same_cache(validate_options, options)
    segments = (read_segment_table(tables.segment_table) if tables.segment_table is not None
                else None)
    return _Reading(options, held_out, tuple(validate), axes, temperature_map, reference,
                    segments)


def _fit_axes(soaks: Sequence[PathLike], drifts: Sequence[PathLike], reading: _Reading,
              settings: CalibrationSettings, aux: Mapping[str, str],
              prior: ThermometerPrior | PathLike | None, tables: RateTables,
              progress: StageProgress | None) -> tuple[dict[str, AxisCalibration],
                                                       dict[str, AxisModel],
                                                       dict[str, dict[str, Any]]]:
    """Each axis's fit (:func:`~hrgtc.pipeline.axis_calibration.fit_axis` on its view of the
    files), its cross-axis trial and its scale factor: the axes' calibrations, their parts
    and the trials."""
    fitted: dict[str, AxisCalibration] = {}
    models: dict[str, AxisModel] = {}
    crossed: dict[str, dict[str, Any]] = {}
    axes = reading.axes
    for axis in axes:
        axis_read = dataclasses.replace(reading.options, axis=axis or reading.options.axis)
        staged = None if progress is None else _prefixed(progress, axis)
        fit = {"soaks": soaks, "drifts": drifts, "settings": settings, "prior": prior,
               "read_options": axis_read, "progress": staged}
        result = fit_axis(**fit, aux=aux)
        if settings.cross_axis and len(axes) > 1:
            result, crossed[axis] = _cross_axis(result, axis, axes, reading.validate, aux, fit)
        model = result.model.axis
        if tables.runs:
            model = dataclasses.replace(model, scale_factor=fit_axis_scale_factor(
                model, tables.runs, axis_read, reading.segments, settings.scale_terms))
        fitted[axis], models[axis] = result, model
    return fitted, models, crossed


def temperature_reference(settings: TemperatureReferenceSettings) -> TemperatureReference | None:
    """The reference log of ``--temp-ref`` and how to read it, as the library's type (None
    when no log is given)."""
    from hrgtc.thermometry.reference import parse_reference_columns

    if settings.reference_log is None:
        if settings.described():
            raise InputError(f"{settings.described()[0]} describes a reference log: give the "
                             "log with --temp-ref")
        return None
    return TemperatureReference(
        settings.reference_log, parse_reference_columns(list(settings.reference_columns)),
        unit=settings.reference_unit, start=settings.reference_start, tz=settings.reference_tz,
        lag_s=settings.reference_lag_s)


def _provenance(soaks: Sequence[PathLike], drifts: Sequence[PathLike], tables: RateTables,
                fitted: Mapping[str, AxisCalibration], settings: CalibrationSettings,
                inputs: CalibrationInputs, reading: _Reading) -> dict[str, Any]:
    """The model's provenance: every input file (hashed once) and the settings of the
    axes' fits with what the chain adds (axes, scale terms, segment table, hold-out, the
    reference log)."""
    reference = reading.reference
    files = {"soak": [str(p) for p in soaks], "drift": [str(p) for p in drifts],
             "validate": [str(p) for p in reading.validate],
             "rate_table": [str(p) for p in tables.runs],
             "validate_rate_table": [str(p) for p in tables.validate],
             "temperature_reference": [] if reference is None else [str(reference.path)]}
    first = next(iter(fitted.values())).model.provenance.get("settings", {})
    hashed = {f["path"]: f["sha256"] for r in fitted.values()  # the axes' records
              for f in r.model.provenance.get("inputs", ())}
    return provenance(files, {
        **first, "axes": list(reading.axes), "thermometer": reading.options.thermometer,
        "scale_terms": list(settings.scale_terms),
        "segment_table": None if tables.segment_table is None else str(tables.segment_table),
        "holdout_s": inputs.holdout.holdout_s, "holdout_fraction": inputs.holdout.holdout_fraction,
        **({} if reference is None else {"temperature_reference": reference.to_dict()})},
        hashed)


def _through_map(options: ReadOptions, temperature_map: TemperatureMap) -> ReadOptions:
    """``options`` reading the raw count through ``temperature_map`` (in the place of the
    reading's temperature scale and offset)."""
    from hrgtc.thermometry.reference import options_with_map

    return options_with_map(dataclasses.replace(
        options, temp_scale=ReadSettings.temp_scale,
        temp_offset_c=ReadSettings.temp_offset_c), temperature_map)


def _axes_of(path: PathLike, options: ReadOptions) -> tuple[str, ...]:
    """The axes of a recording (``("",)``: single-axis), from its column names."""
    from hrgtc.compensate.multi_axis import recording_axes

    found = recording_axes(path, options)
    if found is None:  # the file cannot be opened: reading it says why
        found = tuple(axis_names(options.head(path).names))
    return found or ("",)


def _same_cache(options: ReadOptions, cached: ReadOptions) -> ReadOptions:
    """``options`` reading through the files already read by ``cached`` (a
    :class:`ReadOnce`), if it is one."""
    if not isinstance(cached, ReadOnce) or isinstance(options, ReadOnce):
        return options
    return ReadOnce(**{f.name: getattr(options, f.name)
                       for f in dataclasses.fields(ReadOptions)}, cache=cached.cache)


def _cross_axis(result: AxisCalibration, axis: str, axes: Sequence[str],
                validate: Sequence[PathLike], aux: Mapping[str, str],
                fit: Mapping[str, Any]) -> tuple[AxisCalibration, dict[str, Any]]:
    """Refit ``axis`` with the other resonators' frequencies as candidates (``a_f<other>``:
    each a thermometer of its own part of the unit, so their differences are the gradients
    across it) and keep that model only if it lowers the median held-out 10 s bias
    stability by more than :data:`CROSS_AXIS_GAIN`. The thermometer (plateaus, Tables 1-2)
    is ``result``'s: only the drift model is fitted again (``fit``: the arguments of the
    axis's :func:`~hrgtc.pipeline.axis_calibration.fit_axis`)."""
    others = {f"f{b}": f"freq_hz_{b}" for b in axes if b != axis}
    if not validate:
        return result, {"kept": False, "why": "no held-out run (--validate) to judge by",
                        "channels": others}
    # the same thermometer: the drift fit only
    trial = fit_axis(**fit, aux={**aux, **others}, soak_fit=result.soak_fit)

    def held_out(model: Model) -> float:  # the axis's view, as it was fitted on
        return float(np.median([
            evaluate(model, path, settings=BIAS_ONLY, read_options=fit["read_options"])
            .axis.compensated_10s for path in validate]))

    without, with_ = held_out(result.model), held_out(trial.model)
    kept = with_ < without * (1.0 - CROSS_AXIS_GAIN)
    record = {"kept": bool(kept), "channels": others, "held_out_10s_dph_without": without,
              "held_out_10s_dph_with": with_,
              "selected": [t for t in trial.model.drift.selected if t.startswith("a_")
                           or "*a_" in t]}
    return (trial if kept else result), record


def fit_axis_scale_factor(model: AxisModel, rate_tables: Sequence[PathLike],
                          options: ReadOptions, table: Any,
                          terms: Sequence[str]) -> ScaleFactorModel:
    """One axis's scale factor from its view of the rate-table runs."""
    segments = []
    for path in rate_tables:
        run: Recording = options.read(path)
        segments.extend(steady_segments(run, find_rate_segments(run, table), model))
    if not segments:
        raise InputError(
            f"no rate-table segments found in {', '.join(map(str, rate_tables))}: give the "
            "input rate as an input_rate_dph column or a --segments table"
        )
    return fit_scale_factor(segments, model.drift.settings, terms=tuple(terms))


def _prefixed(progress: StageProgress, axis: str) -> StageProgress:
    def report(stage: str, done: float, total: float) -> None:
        progress(f"axis {axis}: {stage}" if axis else stage, done, total)
    return report


def summary_rows(calibration: Calibration) -> list[Mapping[str, Any]]:
    """One row per axis for the unit's summary: held-out raw/compensated 10 s bias
    stability (median over the held-out runs) and the scale-factor residual."""
    rows = []
    for axis, unit_model in calibration.model.axes.items():
        runs = calibration.axes[axis].validation
        raw = [v.raw_10s for v in runs]
        comp = [v.compensated_10s for v in runs]
        checks = [c for c in calibration.scale_checks if c.axis == axis]
        rows.append({
            "axis": axis or "-",
            "terms": list(unit_model.drift.selected),
            "raw_10s_dph": float(np.median(raw)) if raw else None,
            "compensated_10s_dph": float(np.median(comp)) if comp else None,
            "scale_terms": None if unit_model.scale_factor is None
            else list(unit_model.scale_factor.selected),
            "scale_raw_max_ppm": max((c.raw_max_ppm for c in checks), default=None),
            "scale_residual_max_ppm": max((c.compensated_max_ppm for c in checks),
                                          default=None),
        })
    return rows
