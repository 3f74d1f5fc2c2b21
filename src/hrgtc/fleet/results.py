"""The fleet table: long form, one Parquet row per unit × axis.

A unit of one axis has one row (``axis`` ""), an instrument of three axes three
(``axis`` x, y, z), and a unit that failed one row (``axis`` None: its axes were
not known). A row holds the axis's thermometer (coefficients, Eq. 18 form of [1],
and the relative scaled coefficients a prior is built from), its Table 1 (soak
temperatures and settled frequencies), the temperature coefficient of frequency
at 20 °C, the drift terms kept (Eq. 22 form), the raw and compensated 10 s bias
stability of each held-out run with the shares of samples out of the calibrated
ranges; and the unit's status, wall time, model file and, for a failed unit, the
error and where it was (the same on each of the unit's rows).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from types import UnionType
from typing import (
    TYPE_CHECKING,
    Annotated,
    Any,
    Literal,
    Protocol,
    Union,
    get_args,
    get_origin,
    get_type_hints,
)

import msgspec
import pyarrow as pa
import pyarrow.parquet as pq

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.files import publish, refuse_existing, temporary_beside

if TYPE_CHECKING:
    from hrgtc.evaluation import Evaluation
    from hrgtc.pipeline.calibration import Calibration

__all__ = [
    "SCHEMA",
    "FleetRowRecord",
    "arrow_schema",
    "calibration_rows",
    "evaluation_row",
    "read_table",
    "row_json_schema",
    "table",
    "write_table",
]


class Outcome(Protocol):
    """What :func:`table` reads of a task's outcome (:class:`hrgtc.fleet.tasks.UnitOutcome`).

    A protocol rather than an import: ``tasks`` imports this module to build its rows,
    so importing ``tasks`` here, even for typing only, would close an import circle.
    """

    @property
    def unit(self) -> str: ...
    @property
    def status(self) -> str: ...
    @property
    def row(self) -> dict[str, Any]: ...
    @property
    def axes(self) -> tuple[dict[str, Any], ...]: ...
    @property
    def error(self) -> dict[str, Any] | None: ...
    @property
    def seconds(self) -> float: ...

class FleetRowRecord(records.Record, kw_only=True):
    """A row of the fleet table, one unit's axis: its columns in order, their types and bounds.

    The one definition of the table: :data:`SCHEMA` (the Arrow schema, every column
    nullable) and the table's JSON Schema (:func:`row_json_schema`) come from it, and
    :func:`table` checks each row against it. ``None`` where a unit has no value
    (a failed unit's results, a run's statistic that is not finite).
    """

    unit: str
    #: The axis of the row: "" for a single-axis unit, else its name (x, y, z, ...) as the
    #: recording's column suffix; None for a unit that failed before its axes were known.
    axis: str | None = None
    status: Literal["ok", "skipped", "failed"]
    seconds: records.NonNegative
    error_type: str | None = None
    error_message: str | None = None
    error_file: str | None = None
    error_column: str | None = None
    error_row: records.Count | None = None
    model_file: str | None = None
    n_soaks: records.Count | None = None
    temperature_low_c: float | None = None
    temperature_high_c: float | None = None
    centre_c: float | None = None
    scale_c: records.Positive | None = None
    coefficients_high_first: list[float] | None = None
    freq_centre_hz: float | None = None
    relative_coefficients: list[float] | None = None
    f20_hz: float | None = None
    tcf_ppm_per_c: float | None = None
    soak_temperatures_c: list[float] | None = None
    settled_freqs_hz: list[float] | None = None
    table_max_error_c: records.NonNegative | None = None
    terms_kept: list[str] | None = None
    n_terms: records.Count | None = None
    runs: list[str] | None = None
    raw_10s_dph: list[float | None] | None = None
    compensated_10s_dph: list[float | None] | None = None
    improvement_10s: list[float | None] | None = None
    out_of_range_fraction: list[float] | None = None
    rate_out_of_range_fraction: list[float] | None = None
    median_improvement_10s: float | None = None


def _arrow_type(kind: Any) -> pa.DataType:
    """The Arrow type of a record field's type (``X | None``: nullable ``X``)."""
    while get_origin(kind) is Annotated:
        kind = get_args(kind)[0]
    members = [m for m in get_args(kind) if m is not type(None)]
    if get_origin(kind) is Literal and all(isinstance(m, str) for m in members):
        return pa.string()
    if get_origin(kind) in (Union, UnionType) and len(members) == 1:
        return _arrow_type(members[0])
    if get_origin(kind) is list:
        return pa.list_(_arrow_type(members[0]))
    scalars = {str: pa.string(), float: pa.float64(), int: pa.int64(), bool: pa.bool_()}
    if kind in scalars:
        return scalars[kind]
    raise TypeError(f"no Arrow type for a record field of type {kind!r}")


def arrow_schema(record: type[records.Record]) -> pa.Schema:
    """The Arrow schema of a record of table rows: a nullable column per field, in order."""
    hints = get_type_hints(record, include_extras=True)
    return pa.schema([(field.name, _arrow_type(hints[field.name]))
                      for field in msgspec.structs.fields(record)])


#: The fleet table's Arrow schema, from :class:`FleetRowRecord`.
SCHEMA = arrow_schema(FleetRowRecord)


def row_json_schema() -> dict[str, Any]:
    """The JSON Schema of a fleet table row (:class:`FleetRowRecord`)."""
    return records.json_schema(FleetRowRecord, "hrgtc fleet table row",
                               "https://hrgtc.invalid/schemas/fleet-row.json")


def _num(value: Any) -> float | None:
    return None if value is None or not math.isfinite(float(value)) else float(value)


def evaluation_row(evaluations: Sequence[Evaluation]) -> dict[str, Any]:
    """Per-run bias stability and range shares of a unit's held-out runs."""
    improvements = [_num(v.improvement_10s) for v in evaluations]
    finite = sorted(v for v in improvements if v is not None)
    median = None if not finite else (finite[(len(finite) - 1) // 2]
                                      + finite[len(finite) // 2]) / 2
    return {
        "runs": [v.file for v in evaluations],
        "raw_10s_dph": [_num(v.raw_10s) for v in evaluations],
        "compensated_10s_dph": [_num(v.compensated_10s) for v in evaluations],
        "improvement_10s": improvements,
        "out_of_range_fraction": [float(v.out_of_range_fraction) for v in evaluations],
        "rate_out_of_range_fraction": [float(v.rate_out_of_range_fraction) for v in evaluations],
        "median_improvement_10s": median,
    }


def calibration_rows(calibration: Calibration) -> tuple[dict[str, Any], ...]:
    """A calibrated unit's rows, one per axis: the axis's thermometer, Table 1, drift terms
    and held-out runs (each axis's ``validation``)."""
    from hrgtc.thermometry.prior import relative_coefficients

    rows = []
    for axis, result in calibration.axes.items():
        part = calibration.model.axes[axis]
        th = part.thermometer
        a0, relative = relative_coefficients(th, th.centre_c, th.scale_c)
        f20 = float(th.frequency(20.0))
        rows.append({
            "axis": axis, "n_soaks": len(result.plateaus),
            "temperature_low_c": th.temperature_range_c[0],
            "temperature_high_c": th.temperature_range_c[1],
            "centre_c": th.centre_c, "scale_c": th.scale_c,
            "coefficients_high_first": list(th.coefficients_high_first),
            "freq_centre_hz": a0, "relative_coefficients": [float(v) for v in relative],
            "f20_hz": f20, "tcf_ppm_per_c": float(th.slope_hz_per_c(20.0)) / f20 * 1e6,
            "soak_temperatures_c": [r["chamber_c"] for r in result.table],
            "settled_freqs_hz": [r["freq_hz"] for r in result.table],
            "table_max_error_c": max((abs(r["error_c"]) for r in result.table), default=None),
            "terms_kept": list(part.drift.selected), "n_terms": len(part.drift.selected),
            **evaluation_row(result.validation),
        })
    return tuple(rows)


def table(outcomes: Sequence[Outcome]) -> pa.Table:
    """The fleet table of some outcomes: a row per unit × axis, units in name order and each
    unit's axes in its model's order (an outcome without axes: one row, its ``row``)."""
    rows = []
    for outcome in sorted(outcomes, key=lambda o: o.unit):
        error = outcome.error or {}
        for part in outcome.axes or ({},):
            row = {name: None for name in SCHEMA.names}
            row.update({k: v for k, v in outcome.row.items() if k in row})
            row.update({k: v for k, v in part.items() if k in row})
            row.update(unit=outcome.unit, status=outcome.status, seconds=outcome.seconds,
                       error_type=error.get("type"), error_message=error.get("message"),
                       error_file=error.get("file"), error_column=error.get("column"),
                       error_row=error.get("row"))
            where = f"unit {outcome.unit!r}" + (f", axis {row['axis']!r}" if part else "")
            records.load(row, FleetRowRecord, f"fleet table row of {where}")
            rows.append(row)
    return pa.Table.from_pylist(rows, schema=SCHEMA)


def write_table(outcomes: Sequence[Outcome], path: str | os.PathLike[str],
                force: bool = False) -> Path:
    """Write the fleet table to Parquet atomically."""
    target = Path(path)
    refuse_existing(target, force)
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = temporary_beside(target)
    try:
        pq.write_table(table(outcomes), temporary)
        publish(temporary, target, force)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return target


def read_table(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """The rows of a fleet table (plain Python values)."""
    try:
        data = pq.read_table(path)
    except FileNotFoundError:
        raise InputError(f"{path}: no such fleet table; run 'hrgtc fleet calibrate'") from None
    except (OSError, pa.ArrowException) as exc:
        raise InputError(f"{path}: not a readable fleet table: {exc}") from exc
    if "unit" not in data.column_names or "status" not in data.column_names:
        raise InputError(f"{path}: not a fleet table (no unit and status columns)")
    return data.to_pylist()
