"""Calibrate a whole instrument: every axis of a multi-axis unit, bias and scale factor.

A multi-axis recording holds one resonator per axis (``freq_hz_x``, ``rate_dph_x``,
...). Each axis is calibrated as a single gyro (:func:`hrgtc.calibration.calibrate`
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

from hrgtc.calibration import CalibrationResult, calibrate
from hrgtc.compensate import InstrumentCompensator
from hrgtc.drift import (
    ScaleFactorModel,
    find_rate_segments,
    fit_group,
    fit_scale_factor,
    group_segments,
    read_segment_table,
)
from hrgtc.drift.scale_factor import TOLERANCE_SHARE
from hrgtc.errors import InputError
from hrgtc.evaluation import Evaluation, evaluate
from hrgtc.model import InstrumentModel, UnitModel, provenance
from hrgtc.progress import StageProgress
from hrgtc.recording import ReadOptions, Recording, axis_names
from hrgtc.recording.marks import refuse_compensated_training

__all__ = ["InstrumentCalibration", "ScaleFactorCheck", "calibrate_instrument",
           "check_scale_factor"]

PathLike = str | os.PathLike[str]


@dataclass(frozen=True)
class ScaleFactorCheck:
    """Scale-factor error of a held-out rate-table run, one axis, before and after.

    At each temperature (the run's holds grouped as in the fit), the least-squares slope
    of rate − Ω against Ω over the holds (IEEE Std 1431: the bias, common to all holds
    of a group, drops out): ``raw_ppm`` of the gyro's output, ``compensated_ppm`` of the
    compensated output (bias and scale factor removed).
    """

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

    def to_dict(self) -> dict[str, Any]:
        return {"file": self.file, "axis": self.axis, "freq_hz": list(self.freq_hz),
                "holds": list(self.holds), "raw_ppm": list(self.raw_ppm),
                "compensated_ppm": list(self.compensated_ppm),
                "raw_max_ppm": self.raw_max_ppm, "compensated_max_ppm": self.compensated_max_ppm}


@dataclass(frozen=True)
class InstrumentCalibration:
    """What :func:`calibrate_instrument` produced: the model and each axis's evidence."""

    model: InstrumentModel
    axes: dict[str, CalibrationResult]
    validation: dict[str, tuple[Evaluation, ...]] = field(default_factory=dict)
    scale_checks: tuple[ScaleFactorCheck, ...] = ()
    #: Axis -> the cross-axis trial (channels, held-out figures with and without, kept).
    cross_axis: dict[str, dict[str, Any]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The layout of ``hrgtc calibrate --json`` (one entry per axis)."""
        axes = {}
        for axis, result in self.axes.items():
            entry = result.to_dict()
            entry["validation"] = [v.to_dict() for v in self.validation.get(axis, ())]
            sf = self.model.axes[axis].scale_factor
            entry["scale_factor"] = None if sf is None else sf.to_dict()
            axes[axis or "-"] = entry
        return {"unit": self.model.unit, "axes": axes,
                "scale_factor_checks": [c.to_dict() for c in self.scale_checks],
                "cross_axis": dict(self.cross_axis)}


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
    scale_terms: Sequence[str] = ("f", "f^2", "f^3"),
    thermometer: str = "resonator",
    cross_axis: bool = False,
    read_options: ReadOptions | None = None,
    progress: StageProgress | None = None,
    validate_options: ReadOptions | None = None,
    **settings: Any,
) -> InstrumentCalibration:
    """Calibrate every axis of an instrument (a single-axis file: the one axis).

    Parameters
    ----------
    soaks, drifts, validate
        As :func:`hrgtc.calibration.calibrate`, for every axis (a multi-axis file
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
    scale_terms
        Candidate terms of the scale-factor model (in f, as the drift model's).
    cross_axis
        Also try the other resonators' frequencies as candidate terms of each axis's
        drift model (a temperature difference across the unit is a gradient one resonator
        alone cannot see); kept per axis only where the held-out ``validate`` runs' 10 s
        bias stability improves by more than 2 % (the decision is in ``cross_axis``).
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
    settings
        Further keyword arguments of :func:`hrgtc.calibration.calibrate`.
    """
    if thermometer not in ("resonator", "sensor"):
        raise InputError(f"thermometer must be 'resonator' or 'sensor', got {thermometer!r}")
    options = dataclasses.replace(read_options or ReadOptions(), thermometer=thermometer)
    if not drifts:
        raise InputError("no drift recordings given; pass --drift FILE (a cool-down or warm-up)")
    refuse_compensated_training([*soaks, *drifts, *validate, *rate_tables,
                                 *validate_rate_tables])
    axes = axis_names(options.head(drifts[0]).names) or ("",)
    table = read_segment_table(segment_table) if segment_table is not None else None
    results: dict[str, CalibrationResult] = {}
    models: dict[str, UnitModel] = {}
    crossed: dict[str, dict[str, Any]] = {}
    for axis in axes:
        axis_read = axis_options(options, axis)
        staged = None if progress is None else _prefixed(progress, axis)
        result = calibrate(soaks, drifts, (), read_options=axis_read, progress=staged,
                           thermometer=thermometer, **settings)
        if cross_axis and len(axes) > 1:
            result, crossed[axis] = _cross_axis(result, axis, axes, soaks, drifts, validate,
                                                axis_read, staged, thermometer, settings)
        model = result.model
        if rate_tables:
            model = dataclasses.replace(model, scale_factor=fit_axis_scale_factor(
                model, rate_tables, axis_read, table, scale_terms))
        results[axis], models[axis] = result, model
    unit = next(iter(models.values())).unit
    inputs = {"soak": [str(p) for p in soaks], "drift": [str(p) for p in drifts],
              "validate": [str(p) for p in validate],
              "rate_table": [str(p) for p in rate_tables],
              "validate_rate_table": [str(p) for p in validate_rate_tables]}
    first = next(iter(results.values())).model.provenance.get("settings", {})
    record = provenance(inputs, {**first, "axes": list(axes), "thermometer": thermometer,
                                 "scale_terms": list(scale_terms),
                                 "segment_table": None if segment_table is None
                                 else str(segment_table)})
    models = {axis: dataclasses.replace(m, provenance=record) for axis, m in models.items()}
    instrument = InstrumentModel(models, unit, record)
    held_out = options if validate_options is None else dataclasses.replace(
        validate_options, thermometer=thermometer)
    validation = {axis: tuple(evaluate(path, models[axis], allan=False,
                                       read_options=axis_options(held_out, axis))
                              for path in validate) for axis in axes}
    checks = tuple(check_scale_factor(path, instrument, options, table)
                   for path in validate_rate_tables)
    return InstrumentCalibration(instrument, results, validation,
                                 tuple(c for group in checks for c in group), crossed)


#: Cross-axis candidates are kept when the held-out 10 s bias stability drops by more.
CROSS_AXIS_GAIN = 0.02


def _cross_axis(result: CalibrationResult, axis: str, axes: Sequence[str],
                soaks: Sequence[PathLike], drifts: Sequence[PathLike],
                validate: Sequence[PathLike], options: ReadOptions, progress: Any,
                thermometer: str, settings: Mapping[str, Any]
                ) -> tuple[CalibrationResult, dict[str, Any]]:
    """Refit ``axis`` with the other resonators' frequencies as candidates (``a_f<other>``:
    each a thermometer of its own part of the unit, so their differences are the gradients
    across it) and keep that model only if it lowers the median held-out 10 s bias
    stability by more than :data:`CROSS_AXIS_GAIN`."""
    others = {f"f{b}": f"freq_hz_{b}" for b in axes if b != axis}
    if not validate:
        return result, {"kept": False, "why": "no held-out run (--validate) to judge by",
                        "channels": others}
    aux = {**dict(settings.get("aux") or {}), **others}
    trial = calibrate(soaks, drifts, (), read_options=options, progress=progress,
                      thermometer=thermometer, **{**settings, "aux": aux})

    def held_out(model: UnitModel) -> float:
        return float(np.median([evaluate(path, model, allan=False, read_options=options)
                                .compensated_10s for path in validate]))

    without, with_ = held_out(result.model), held_out(trial.model)
    kept = with_ < without * (1.0 - CROSS_AXIS_GAIN)
    record = {"kept": bool(kept), "channels": others, "held_out_10s_dph_without": without,
              "held_out_10s_dph_with": with_,
              "selected": [t for t in trial.model.drift.selected if t.startswith("a_")
                           or "*a_" in t]}
    return (trial if kept else result), record


def fit_axis_scale_factor(model: UnitModel, rate_tables: Sequence[PathLike],
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


def steady_segments(run: Recording, segments: Sequence[Any], model: UnitModel,
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


def check_scale_factor(path: PathLike, model: InstrumentModel, options: ReadOptions,
                       table: Any = None) -> tuple[ScaleFactorCheck, ...]:
    """Scale-factor error of a held-out rate-table run, each axis, before and after."""
    checks = []
    compensated = InstrumentCompensator(model).transform(options.read(path))
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
