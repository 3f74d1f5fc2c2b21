"""Calibrate a whole instrument: every axis of a multi-axis unit, bias and scale factor.

A multi-axis recording holds one resonator per axis (``freq_hz_x``, ``rate_dph_x``,
...). Each axis is calibrated as a single gyro (:func:`hrgtc.pipeline.calibration.calibrate`
on its single-axis view: its own thermometer and drift model), then, given rate-table
runs, its scale-factor error against frequency is fitted
(:func:`hrgtc.drift.scale_factor.fit_scale_factor`); held-out runs are evaluated per
axis, and held-out rate-table runs give the scale-factor error before and after. A
single-axis file is the one-axis case. Gyros without a frequency output
(``thermometer="sensor"``) run the same pipeline on their temperature sensor.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.compensate import Compensator
from hrgtc.compensate.ranges import RangeReport
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.progress import StageProgress
from hrgtc.core.summary import Summary
from hrgtc.drift import (
    ScaleFactorModel,
    find_rate_segments,
    fit_group,
    fit_scale_factor,
    group_segments,
    read_segment_table,
)
from hrgtc.drift.scale_factor import TOLERANCE_SHARE
from hrgtc.evaluation import Evaluation, evaluate
from hrgtc.evaluation.calibration_figures import instrument_summary
from hrgtc.evaluation.instrument_figures import evaluation_tables
from hrgtc.evaluation.instrument_pass import evaluate_axes
from hrgtc.model import AxisModel, Model, provenance
from hrgtc.pipeline import documents
from hrgtc.pipeline.calibration import HOUSING_TERMS, CalibrationResult, calibrate
from hrgtc.pipeline.holdout import holdout_split
from hrgtc.recording import ReadOptions, Recording, axis_names
from hrgtc.recording.marks import refuse_compensated_training
from hrgtc.recording.read_once import ReadOnce
from hrgtc.settings.calibration import CROSS_AXIS_GAIN, CalibrationSettings
from hrgtc.settings.compensation import BIAS_ONLY, EvaluationSettings
from hrgtc.settings.reading import ReadSettings
from hrgtc.thermometry.prior import ThermometerPrior
from hrgtc.thermometry.reference import TemperatureMap, TemperatureReference

__all__ = ["InstrumentCalibration", "InstrumentEvaluation", "ScaleFactorCheck",
           "calibrate_instrument", "check_scale_factor", "evaluate_instrument",
           "holdout_split"]

PathLike = str | os.PathLike[str]


@dataclass(frozen=True)
class ScaleFactorCheck(records.Dumped):
    """Scale-factor error of a held-out rate-table run, one axis, before and after.

    At each temperature (the run's holds grouped as in the fit), the least-squares slope
    of rate − Ω against Ω over the holds (IEEE Std 1431: the bias, common to all holds
    of a group, drops out): ``raw_ppm`` of the gyro's output, ``compensated_ppm`` of the
    compensated output (bias and scale factor removed).
    """

    written_by = documents.ScaleFactorCheckRecord  # the calibrate --json document's part

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


@dataclass(frozen=True)
class InstrumentCalibration:
    """What :func:`calibrate_instrument` produced: the model and each axis's evidence."""

    model: Model
    axes: dict[str, CalibrationResult]
    validation: dict[str, tuple[Evaluation, ...]] = field(default_factory=dict)
    scale_checks: tuple[ScaleFactorCheck, ...] = ()
    #: Axis -> the cross-axis trial (channels, held-out figures with and without, kept).
    cross_axis: dict[str, dict[str, Any]] = field(default_factory=dict)

    def summary(self) -> Summary:
        """The instrument's figures beside its axes' own (held-out rate tables, cross-axis
        trials, each axis's held-out medians); see
        :func:`hrgtc.evaluation.calibration_figures.instrument_summary`."""
        return instrument_summary(self)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (:class:`InstrumentCalibrationRecord`, the layout of ``hrgtc
        calibrate --json``: one entry per axis, ``"-"`` for a single axis)."""
        return records.dump(self, documents.InstrumentCalibrationRecord, **self._parts(),
                            validation=None)

    def _parts(self) -> dict[str, Any]:
        axes = {}
        for axis, result in self.axes.items():
            sf = self.model.axes[axis].scale_factor
            axes[axis or "-"] = {
                **result.document_parts(),
                "validation": [v.to_dict() for v in self.validation.get(axis, ())],
                "scale_factor": None if sf is None else sf.to_dict()}
        return {"unit": self.model.unit, "axes": axes,
                "scale_factor_checks": [c.to_dict() for c in self.scale_checks]}

    def document(self) -> dict[str, Any]:
        """The document of ``hrgtc calibrate --json``: a single-axis unit without a scale
        factor as :meth:`CalibrationResult.to_dict` (with its held-out runs;
        :class:`CalibrationDocumentRecord`), else :meth:`to_dict` (with the held-out runs of
        a single axis); the temperature map (``--temp-ref``) when the model has one. Its
        JSON Schema: :func:`hrgtc.pipeline.documents.calibrate_json_schema`."""
        single = self.model.is_single_axis
        validation = [v.to_dict() for v in self.validation[""]] if single else None
        if single and not self.scale_checks and self.model.axes[""].scale_factor is None:
            return records.dump(self.axes[""], documents.CalibrationDocumentRecord,
                                **{**self.axes[""].document_parts(), "validation": validation},
                                temperature_map=self.model.temperature_map)
        return records.dump(self, documents.InstrumentCalibrationRecord, **self._parts(),
                            validation=validation, temperature_map=self.model.temperature_map)

    def range_reports(self) -> dict[str, dict[str, RangeReport]]:
        """Held-out file -> axis -> its range report, where any axis went beyond the
        trained temperature or df/dt (``--strict`` fails then)."""
        out: dict[str, dict[str, RangeReport]] = {}
        for axis, runs in self.validation.items():
            for run in runs:
                if run.ranges is not None and run.range_warnings():
                    out.setdefault(run.file, {})[axis] = run.ranges
        return out


def axis_options(options: ReadOptions, axis: str) -> ReadOptions:
    """``options`` reading the single-axis view of ``axis`` ("" : the file as it is)."""
    return dataclasses.replace(options, axis=axis or None)


def calibrate_instrument(
    soaks: Sequence[PathLike],
    drifts: Sequence[PathLike],
    validate: Sequence[PathLike] = (),
    *,
    rate_tables: Sequence[PathLike] = (),
    validate_rate_tables: Sequence[PathLike] = (),
    segment_table: PathLike | None = None,
    settings: CalibrationSettings | None = None,
    aux: Mapping[str, str] | None = None,
    housing_terms: Sequence[str] | None = HOUSING_TERMS,
    prior: ThermometerPrior | PathLike | None = None,
    thermometer: str = ReadSettings.thermometer,
    read_options: ReadOptions | None = None,
    progress: StageProgress | None = None,
    validate_options: ReadOptions | None = None,
    temperature_map: TemperatureMap | None = None,
    temperature_reference: TemperatureReference | None = None,
    holdout_s: float | None = None,
    holdout_fraction: float | None = None,
) -> InstrumentCalibration:
    """Calibrate every axis of an instrument (a single-axis file: the one axis).

    Parameters
    ----------
    soaks, drifts, validate
        As :func:`hrgtc.pipeline.calibration.calibrate`, for every axis (a multi-axis file
        holds every axis's columns).
    rate_tables
        Rate-table runs (known input rates at several temperatures; the input rate
        as the ``input_rate_dph`` column or ``segment_table``): each axis's scale
        factor against frequency. None given: bias only.
    validate_rate_tables
        Held-out rate-table runs: scale-factor error before and after, per axis.
    segment_table
        CSV ``start_s,end_s,input_rate_dph`` of the rate-table runs' segments, for
        files without an input-rate column.
    settings
        The settings of :func:`hrgtc.pipeline.calibration.calibrate` for every axis, with
        ``scale_terms`` (candidate terms of the scale-factor model, in f as the drift
        model's) and ``cross_axis``: also try the other resonators' frequencies as
        candidate terms of each axis's drift model (a temperature difference across the
        unit is a gradient one resonator alone cannot see); kept per axis only where the
        held-out ``validate`` runs' 10 s bias stability improves by more than
        :data:`CROSS_AXIS_GAIN` (the decision is in ``cross_axis``).
    aux, housing_terms, prior
        As :func:`hrgtc.pipeline.calibration.calibrate`.
    thermometer
        ``"resonator"`` (the resonator's frequency, [1]) or ``"sensor"`` (a gyro
        without a frequency output: its temperature sensor, ``temperature_c``, is
        the thermometer; no soaks needed).
    read_options
        Column mapping, units, metadata overrides for every file.
    progress
        Optional ``callback(stage, done, total)``; stages are prefixed with the axis.
    validate_options
        Reading options of the ``validate`` runs when they differ (a held-out last part
        of the training file: ``start`` where the training's ``end`` is); default
        ``read_options``.
    temperature_map, temperature_reference
        A map of the raw temperature count to °C (applied to every file, stored in the
        model), or the reference log to fit it from on the whole first drift run.
    holdout_s, holdout_fraction
        Validate on the end of the one drift file (:func:`holdout_split`).
    """
    settings = settings or CalibrationSettings()
    scale_terms, cross_axis = settings.scale_terms, settings.cross_axis
    # what the cross-axis trial passes to calibrate again (with the axis's read options)
    fit = {"soaks": soaks, "drifts": drifts, "settings": settings, "aux": aux,
           "housing_terms": housing_terms, "prior": prior, "thermometer": thermometer}
    if thermometer not in ("resonator", "sensor"):
        raise InputError(f"thermometer must be 'resonator' or 'sensor', got {thermometer!r}")
    options = dataclasses.replace(read_options or ReadOptions(), thermometer=thermometer)
    if temperature_reference is not None and temperature_map is not None:
        raise InputError("give a temperature map or a reference log to fit one, not both")
    if temperature_reference is not None and drifts:  # all of the first run, before a split
        temperature_map = temperature_reference.fit(drifts[0], options)
    if temperature_map is not None:
        options = _through_map(options, temperature_map)
        validate_options = (None if validate_options is None
                            else _through_map(validate_options, temperature_map))
    if holdout_s is not None or holdout_fraction is not None:
        options, validate_options, validate = holdout_split(
            options, soaks, drifts, validate, holdout_s, holdout_fraction)
        if progress is not None:
            progress(f"held out {drifts[0]} from {options.end} s on", 1.0, 1.0)
    if not drifts:
        raise InputError("no drift recordings given; pass --drift FILE (a cool-down or warm-up)")
    refuse_compensated_training([*soaks, *drifts, *validate, *rate_tables,
                                 *validate_rate_tables])
    axes = _axes_of(drifts[0], options)
    if len(axes) > 1:  # every axis calibrated from one reading of each file
        options = ReadOnce(**{f.name: getattr(options, f.name)
                              for f in dataclasses.fields(ReadOptions)})
    table = read_segment_table(segment_table) if segment_table is not None else None
    results: dict[str, CalibrationResult] = {}
    models: dict[str, AxisModel] = {}
    crossed: dict[str, dict[str, Any]] = {}
    for axis in axes:
        axis_read = axis_options(options, axis)
        staged = None if progress is None else _prefixed(progress, axis)
        result = calibrate(soaks, drifts, (), settings=settings, aux=aux,
                           housing_terms=housing_terms, prior=prior, read_options=axis_read,
                           progress=staged, thermometer=thermometer, marks_checked=True)
        if cross_axis and len(axes) > 1:
            result, crossed[axis] = _cross_axis(result, axis, axes, validate, axis_read,
                                                staged, fit)
        model = result.model.axis
        if rate_tables:
            model = dataclasses.replace(model, scale_factor=fit_axis_scale_factor(
                model, rate_tables, axis_read, table, scale_terms))
        results[axis], models[axis] = result, model
    unit = next(iter(results.values())).model.unit
    inputs = {"soak": [str(p) for p in soaks], "drift": [str(p) for p in drifts],
              "validate": [str(p) for p in validate],
              "rate_table": [str(p) for p in rate_tables],
              "validate_rate_table": [str(p) for p in validate_rate_tables],
              "temperature_reference": [] if temperature_reference is None
              else [str(temperature_reference.path)]}
    first = next(iter(results.values())).model.provenance.get("settings", {})
    reference = {} if temperature_reference is None else {
        "temperature_reference": temperature_reference.to_dict()}
    hashed = {f["path"]: f["sha256"] for r in results.values()  # the axes' records
              for f in r.model.provenance.get("inputs", ())}
    record = provenance(inputs, {**first, "axes": list(axes), "thermometer": thermometer,
                                 "scale_terms": list(scale_terms),
                                 "segment_table": None if segment_table is None
                                 else str(segment_table), "holdout_s": holdout_s,
                                 "holdout_fraction": holdout_fraction, **reference}, hashed)
    instrument = Model(models, unit, record, None if temperature_map is None
                                 else temperature_map.to_dict())
    held_out = options if validate_options is None else _same_cache(dataclasses.replace(
        validate_options, thermometer=thermometer), options)
    # each held-out run read once for every axis (evaluation.instrument_pass)
    runs = [evaluate_axes(path, instrument, settings=BIAS_ONLY, read_options=held_out)
            for path in validate]
    validation = {axis: tuple(run[axis] for run in runs) for axis in axes}
    checks = tuple(check_scale_factor(path, instrument, options, table)
                   for path in validate_rate_tables)
    return InstrumentCalibration(instrument, results, validation,
                                 tuple(c for group in checks for c in group), crossed)


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


def _cross_axis(result: CalibrationResult, axis: str, axes: Sequence[str],
                validate: Sequence[PathLike], options: ReadOptions, progress: Any,
                fit: Mapping[str, Any]) -> tuple[CalibrationResult, dict[str, Any]]:
    """Refit ``axis`` with the other resonators' frequencies as candidates (``a_f<other>``:
    each a thermometer of its own part of the unit, so their differences are the gradients
    across it) and keep that model only if it lowers the median held-out 10 s bias
    stability by more than :data:`CROSS_AXIS_GAIN`. The thermometer (plateaus, Tables 1-2)
    is ``result``'s: only the drift model is fitted again."""
    others = {f"f{b}": f"freq_hz_{b}" for b in axes if b != axis}
    if not validate:
        return result, {"kept": False, "why": "no held-out run (--validate) to judge by",
                        "channels": others}
    aux = {**dict(fit["aux"] or {}), **others}
    trial = calibrate(fit["soaks"], fit["drifts"], (), settings=fit["settings"], aux=aux,
                      housing_terms=fit["housing_terms"], prior=fit["prior"],
                      read_options=options, progress=progress, thermometer=fit["thermometer"],
                      soak_fit=result.soak_fit,  # the same thermometer: the drift fit only
                      marks_checked=True)

    def held_out(model: Model) -> float:
        return float(np.median([evaluate(path, model, settings=BIAS_ONLY, read_options=options)
                                .compensated_10s for path in validate]))

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
        run = options.read(path)
        segments.extend(steady_segments(run, find_rate_segments(run, table), model))
    if not segments:
        raise InputError(
            f"no rate-table segments found in {', '.join(map(str, rate_tables))}: give the "
            "input rate as an input_rate_dph column or a --segments table"
        )
    return fit_scale_factor(segments, model.drift.settings, terms=tuple(terms))


#: Largest change of the resonator temperature within a rate-table hold used for the
#: scale factor (the rest, e.g. the table at rest while the chamber slews, is left out). [°C]
STEADY_CHANGE_C = 0.2


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
    """Scale-factor error of a held-out rate-table run, each axis, before and after."""
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


def _prefixed(progress: StageProgress, axis: str) -> StageProgress:
    def report(stage: str, done: float, total: float) -> None:
        progress(f"axis {axis}: {stage}" if axis else stage, done, total)
    return report


def summary_rows(calibration: InstrumentCalibration) -> list[Mapping[str, Any]]:
    """One row per axis for the unit's summary: held-out raw/compensated 10 s bias
    stability (median over the held-out runs) and the scale-factor residual."""
    rows = []
    for axis, unit_model in calibration.model.axes.items():
        runs = calibration.validation.get(axis, ())
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


@dataclass(frozen=True, eq=False)
class InstrumentEvaluation:
    """What :func:`evaluate_instrument` measured: each axis's figures and the scale-factor
    check of a rate-table run (the result of ``hrgtc evaluate``).

    Attributes
    ----------
    model
        The instrument's model as applied (its axes those evaluated).
    axes
        Axis (``""`` for a single-axis model) -> :class:`~hrgtc.evaluation.Evaluation`.
    scale_checks
        Scale-factor error at each temperature of a rate-table run, raw and compensated
        (empty unless the run has ``input_rate_dph`` columns and the model a scale factor).
    """

    model: Model
    axes: dict[str, Evaluation]
    scale_checks: tuple[ScaleFactorCheck, ...] = ()

    def summary(self) -> Summary:
        """The axes side by side and the scale-factor check, beside each axis's own
        (:func:`hrgtc.evaluation.instrument_figures.evaluation_tables`)."""
        return evaluation_tables(self)

    def axis_summary(self) -> list[dict[str, float | str]]:
        """One row per axis: 10 s bias stability raw and compensated, improvement, mean and
        RMS of the compensated output, shares beyond the trained ranges. [°/h]"""
        return [{"axis": axis, "raw_10s_dph": r.raw_10s,
                 "compensated_10s_dph": r.compensated_10s,
                 "improvement_10s": r.improvement_10s,
                 "compensated_mean_dph": r.mean_dph.get("compensated", float("nan")),
                 "compensated_rms_dph": r.rms_dph.get("compensated", float("nan")),
                 "out_of_range_fraction": r.out_of_range_fraction,
                 "rate_out_of_range_fraction": r.rate_out_of_range_fraction}
                for axis, r in self.axes.items()]

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (the layout of ``hrgtc evaluate --json``): a single-axis model's
        evaluation as it is (:class:`~hrgtc.evaluation.evaluation_result.EvaluationRecord`);
        else the unit, each axis and the summary (:class:`InstrumentEvaluationRecord`; NaN:
        None). Its JSON Schema: :func:`hrgtc.pipeline.documents.evaluate_json_schema`."""
        if self.model.is_single_axis:
            return self.axes[""].to_dict()
        return records.dump(self, documents.InstrumentEvaluationRecord, unit=self.model.unit,
                            axes={a: r.to_dict() for a, r in self.axes.items()},
                            summary=self.axis_summary())

    def allan_csv(self) -> str:
        """The deviation curves of every axis as CSV (an ``axis`` column first when there
        are several): series, tau_s, deviation, lower, upper, n, edf."""
        if list(self.axes) == [""]:
            return self.axes[""].allan_csv()
        lines: list[str] = []
        for axis, result in self.axes.items():
            header, *rows = result.allan_csv().splitlines()
            if not lines:
                lines.append("axis," + header)
            lines.extend(f"{axis},{row}" for row in rows)
        return "\n".join(lines) + "\n"


def evaluate_instrument(
    run: PathLike,
    model: Model,
    *,
    axes: Sequence[str] | None = None,
    read_options: ReadOptions | None = None,
    settings: EvaluationSettings | None = None,
    max_points: int | None = None,
    progress: Any = None,
    model_source: str = "",
) -> InstrumentEvaluation:
    """Raw vs compensated figures of every axis of a run, the file read once for all axes.

    The model's temperature map (``calibrate --temp-ref``) is applied unless
    ``read_options`` give their own scale and offset; the model's and the run's axes must
    agree unless ``axes`` names those to evaluate
    (:func:`hrgtc.compensate.multi_axis.match_axes`). Each axis is measured as
    :func:`hrgtc.evaluation.evaluate` measures a single-axis run
    (:func:`hrgtc.evaluation.instrument_pass.evaluate_axes`); a rate-table run (with
    ``input_rate_dph`` columns) of a model with a scale factor also gets its scale-factor
    check (:func:`check_scale_factor`, which reads the run again: its holds are found on
    the whole compensated run).

    Parameters
    ----------
    run
        The recording file.
    model
        The instrument's model (a single-axis model is the one-axis case).
    axes
        The axes to evaluate (``--axes``); None: all of them.
    read_options
        How to read the run.
    settings, max_points
        As :func:`hrgtc.evaluation.evaluate`.
    progress
        ``progress(rows done, rows)`` of the reading.
    model_source
        The model file's name, for the messages.
    """
    from hrgtc.compensate.multi_axis import match_axes, recording_axes
    from hrgtc.model_fit import check_thermometer_kind
    from hrgtc.thermometry.reference import options_with_map

    options = options_with_map(read_options or ReadOptions(), model.temperature_map)
    check_thermometer_kind(options, model, model_source or None)  # before the recording's axes
    model = match_axes(model, recording_axes(run, options), axes, str(run), model_source)
    results = evaluate_axes(run, model, settings=settings, read_options=options,
                            max_points=max_points, progress=progress)
    checks: tuple[ScaleFactorCheck, ...] = ()
    if any(m.scale_factor is not None for m in model.axes.values()):
        names = options.head(run).names
        if any(n == "input_rate_dph" or n.startswith("input_rate_dph_") for n in names):
            checks = check_scale_factor(run, model, options)
    return InstrumentEvaluation(model, results, checks)
