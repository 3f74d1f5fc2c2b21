"""The records of ``hrgtc calibrate --json`` and the JSON Schemas of ``calibrate --json`` and
``evaluate --json``.

One record per document part (:mod:`hrgtc.core.records`): :class:`CalibrationRecord` (one
axis's calibration, :meth:`~hrgtc.pipeline.axis_calibration.AxisCalibration.to_dict`),
:class:`InstrumentCalibrationRecord` (every axis) and their parts. ``hrgtc calibrate
--json`` writes one of two documents
(:meth:`~hrgtc.pipeline.calibration.Calibration.to_dict`) and ``hrgtc evaluate --json`` one
of two (a single-axis evaluation or every axis,
:meth:`~hrgtc.evaluation.run_evaluation.RunEvaluation.to_dict`): their schemas
(:func:`calibrate_json_schema`, :func:`evaluate_json_schema`) are the one of the two
records each. See docs/architecture.md ("One result contract").
"""

from __future__ import annotations

from functools import cache
from typing import Any

from hrgtc.core import records
from hrgtc.core.accounting import AccountingRecord
from hrgtc.core.records import Count, Positive, Record, Statistic
from hrgtc.drift.cross_validation import CrossValidationRecord
from hrgtc.drift.scale_factor import ScaleFactorRecord
from hrgtc.drift.stepwise import StepRecord
from hrgtc.evaluation.evaluation_result import EvaluationRecord
from hrgtc.evaluation.run_evaluation import InstrumentEvaluationRecord
from hrgtc.evaluation.scale_check import ScaleFactorCheckRecord

__all__ = ["CalibrationDocumentRecord", "CalibrationDriftRecord", "CalibrationRecord",
           "CalibrationThermometerRecord", "HousingRecord", "InstrumentAxisRecord",
           "InstrumentCalibrationRecord", "Table1Row", "calibrate_json_schema",
           "evaluate_json_schema"]


class Table1Row(Record):
    """One plateau of the unit's Tables 1 and 2. [°C, Hz, °C, °C]"""

    chamber_c: float
    freq_hz: Positive
    temperature_from_freq_c: float
    error_c: float


class CalibrationThermometerRecord(Record):
    """The thermometer of a calibration: Eq. (18) high order first, ±1σ, Tables 1 and 2."""

    coefficients_high_first: list[float]
    standard_errors_high_first: list[Statistic]
    table: list[Table1Row]


class CalibrationDriftRecord(Record):
    """The drift model of a calibration: the selected terms, how they were selected, the
    coefficients with ±1σ and p-values, the offsets and the accounting of the samples."""

    selected_terms: list[str]
    history: list[StepRecord]
    intercept_dph: float
    coefficients: dict[str, float]
    standard_errors: dict[str, Statistic]
    pvalues: dict[str, Statistic]
    window_s: Positive
    n_windows: Count
    selection: str
    n_not_at_rest: Count
    offset_mode: str
    offsets_dph: dict[str, float]
    pruning: dict[str, Any] | None
    cross_validation: CrossValidationRecord | None
    accounting: AccountingRecord | None


class HousingRecord(Record):
    """The classical housing-thermistor baseline: its terms and coefficients."""

    selected_terms: list[str]
    coefficients: dict[str, float]


class CalibrationRecord(Record):
    """The record of :class:`~hrgtc.pipeline.axis_calibration.AxisCalibration` (its
    ``to_dict``; ``hrgtc calibrate --json`` of a single-axis unit); ``prior`` is
    :meth:`~hrgtc.thermometry.prior.PriorFit.to_dict`."""

    thermometer: CalibrationThermometerRecord
    drift: CalibrationDriftRecord
    housing: HousingRecord | None
    validation: list[EvaluationRecord]
    prior: dict[str, Any] | None


class CalibrationDocumentRecord(CalibrationRecord):
    """``hrgtc calibrate --json`` of a single-axis unit without a scale factor: its
    calibration and the temperature map of ``--temp-ref`` (only when it has one; the map's
    fields as :meth:`~hrgtc.thermometry.reference.TemperatureMap.to_dict` writes them)."""

    omit_when_default = ("temperature_map",)

    temperature_map: dict[str, Any] | None = None


class InstrumentAxisRecord(CalibrationRecord):
    """One axis of :class:`InstrumentCalibrationRecord`: its calibration and its scale
    factor (null without rate-table runs)."""

    scale_factor: ScaleFactorRecord | None


class InstrumentCalibrationRecord(Record):
    """:class:`~hrgtc.pipeline.calibration.Calibration` of an instrument, or of a unit with
    a scale factor (its ``to_dict``, ``hrgtc calibrate --json``): the axes (``"-"`` for a
    single axis), the held-out rate-table checks, the cross-axis trials, the held-out runs
    of a single axis and the temperature map, each of the last two only when there is one."""

    omit_when_default = ("validation", "temperature_map")

    unit: str
    axes: dict[str, InstrumentAxisRecord]
    scale_factor_checks: list[ScaleFactorCheckRecord]
    #: axis -> the cross-axis trial (channels, held-out figures with and without, kept)
    cross_axis: dict[str, dict[str, Any]]
    validation: list[EvaluationRecord] | None = None
    temperature_map: dict[str, Any] | None = None


def _either(title: str, schema_id: str, choices: list[type[Record]]) -> dict[str, Any]:
    """The JSON Schema of a document that is one of ``choices``."""
    references, definitions = records.schema_components(choices)
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": schema_id,
            "title": title, "anyOf": list(references), "$defs": definitions}


@cache
def calibrate_json_schema() -> dict[str, Any]:
    """JSON Schema (Draft 2020-12) of ``hrgtc calibrate --json``
    (:meth:`~hrgtc.pipeline.calibration.Calibration.to_dict`): a single-axis calibration or
    an instrument's."""
    return _either("hrgtc calibrate --json", "https://hrgtc.invalid/schema/calibration.json",
                   [CalibrationDocumentRecord, InstrumentCalibrationRecord])


@cache
def evaluate_json_schema() -> dict[str, Any]:
    """JSON Schema (Draft 2020-12) of ``hrgtc evaluate --json``
    (:meth:`~hrgtc.evaluation.run_evaluation.RunEvaluation.to_dict`): a single-axis
    evaluation or an instrument's."""
    return _either("hrgtc evaluate --json", "https://hrgtc.invalid/schema/evaluate.json",
                   [EvaluationRecord, InstrumentEvaluationRecord])
