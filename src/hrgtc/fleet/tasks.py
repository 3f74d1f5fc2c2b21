"""One unit's work as a task: paths in, a small picklable :class:`UnitOutcome` out.

Each function runs the single-unit library function (``simulate_files``,
``calibrate``, ``evaluate``, ``build_report``) on one unit. The worker reads the
unit's files from their paths and writes its outputs itself; only paths,
settings and the outcome (a row of plain numbers) travel between the client and
the workers. A task never raises: whatever goes wrong becomes a failed outcome
with the error's type, message and, where the message names them, the file,
column and row, so one unit's bad input never stops the others.
"""

from __future__ import annotations

import json
import re
import time
import traceback
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

from msgspec import Meta

from hrgtc.core import records
from hrgtc.fleet.manifest import UnitFiles
from hrgtc.recording import ReadOptions
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.compensation import EvaluationSettings
from hrgtc.settings.fleet import FleetEvaluation

__all__ = ["UnitOutcome", "calibrate_unit", "evaluate_unit", "report_unit", "simulate_unit"]

#: Recording columns an error message may name.
_COLUMNS = ("time_s", "freq_hz", "rate_dph", "chamber_c", "housing_c", "resonator_c",
            "bias_dph")
_ROW = re.compile(r"\brows? (\d+)")
_QUOTED_COLUMN = re.compile(r"column '([^']+)'")


@dataclass(frozen=True)
class UnitOutcome:
    """What a task did for one unit.

    Attributes
    ----------
    unit
        The unit's name.
    status
        ``"ok"``, ``"skipped"`` (resumed: inputs unchanged) or ``"failed"``.
    row
        The unit's row of the fleet table (plain JSON types).
    error
        ``{"type", "message", "file", "column", "row"}`` for a failed unit.
    seconds
        Wall time of the task. [s]
    cpu_seconds
        CPU time of the task's process while it ran (tasks are single-threaded, so
        the work itself, whatever else the machine runs). [s]
    """

    unit: str
    status: str
    row: dict[str, Any] = field(default_factory=dict)
    error: dict[str, Any] | None = None
    seconds: float = 0.0
    cpu_seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (the unit's outcome file), as :class:`UnitOutcomeRecord` writes
        them (strict JSON: a number that is not finite becomes None)."""
        return records.dump(self, UnitOutcomeRecord)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> UnitOutcome:
        """Inverse of :meth:`to_dict` (checked against :class:`UnitOutcomeRecord`)."""
        values = records.load(data, UnitOutcomeRecord, "unit-outcome")
        error = values["error"]
        if error is not None:  # as error_record gives it: a traceback only when there is one
            values["error"] = {k: v for k, v in error.items()
                               if k != "traceback" or v is not None}
        return cls(**values)


class ErrorRecord(records.Record, kw_only=True):
    """Why a unit failed (:func:`error_record`): the error's type and message, and the
    file, column and row the message names (None where it names none)."""

    omit_when_default = ("traceback",)

    type: str
    message: str
    file: str | None = None
    column: str | None = None
    row: Annotated[int, Meta(ge=0)] | None = None
    #: The last lines of the traceback of an error that is not hrgtc's own (a bug).
    traceback: tuple[str, ...] | None = None


class UnitOutcomeRecord(records.Record, kw_only=True):
    """A :class:`UnitOutcome` in its file (``<unit>.outcome.json`` beside the model): field
    names and bounds, from which its ``to_dict``/``from_dict`` and JSON Schema come."""

    unit: str
    status: Literal["ok", "skipped", "failed"]
    #: The unit's row of the fleet table (:mod:`hrgtc.fleet.results`).
    row: dict[str, Any] = records.empty()
    error: ErrorRecord | None = None
    seconds: records.NonNegative = 0.0
    cpu_seconds: records.NonNegative = 0.0


def error_record(exc: BaseException, paths: tuple[str, ...] = ()) -> dict[str, Any]:
    """Type, message and where: the file, column and row the message names (else None)."""
    message = str(exc) or type(exc).__name__
    file = next((p for p in paths if p in message), None) or next(
        (p for p in paths if Path(p).name in message), None)
    quoted = _QUOTED_COLUMN.search(message)
    column = quoted.group(1) if quoted else next(
        (c for c in _COLUMNS if re.search(rf"\b{c}\b", message)), None)
    row = _ROW.search(message)
    record = {"type": type(exc).__name__, "message": message, "file": file,
              "column": column, "row": int(row.group(1)) if row else None}
    from hrgtc.core.errors import HrgtcError

    if not isinstance(exc, HrgtcError):  # a bug or an unforeseen input: keep where it was
        record["traceback"] = tuple(traceback.format_exception(exc)[-3:])
    return record


def failed(unit: str, exc: BaseException, paths: tuple[str, ...], start: float) -> UnitOutcome:
    """A failed outcome for ``exc``."""
    return UnitOutcome(unit, "failed", {}, error_record(exc, paths), time.perf_counter() - start)


def outcome_path(output_dir: str | Path, unit: str) -> Path:
    """Where a unit's outcome record is kept beside its model."""
    return Path(output_dir) / f"{unit}.outcome.json"


def model_path(output_dir: str | Path, unit: str) -> Path:
    """The unit's model file in the models folder."""
    return Path(output_dir) / f"{unit}.json"


def _input_hashes(files: UnitFiles) -> list[dict[str, str]]:
    from hrgtc.core.files import file_sha256

    return [{"role": role, "path": path, "sha256": file_sha256(path)}
            for role, paths in files.roles().items() for path in paths]


def _resumable(files: UnitFiles, output_dir: str) -> UnitOutcome | None:
    """The stored outcome when the unit's model exists and its input hashes still match."""
    target, record = model_path(output_dir, files.unit), outcome_path(output_dir, files.unit)
    if not (target.is_file() and record.is_file()):
        return None
    from hrgtc.model import load_model

    try:
        stored = load_model(target).provenance.get("inputs", [])
        outcome = UnitOutcome.from_dict(json.loads(record.read_text(encoding="utf-8")))
    except Exception:  # a damaged model or record is calibrated again
        return None
    if outcome.status != "ok" or stored != _input_hashes(files):
        return None
    return UnitOutcome(files.unit, "skipped", outcome.row, None, 0.0)


def calibrate_unit(files: UnitFiles, output_dir: str, settings: CalibrationSettings,
                   read_options: ReadOptions | None = None, resume: bool = False,
                   prior_path: str | None = None) -> UnitOutcome:
    """Calibrate one unit (:func:`hrgtc.pipeline.calibration.calibrate`) and write its model file.

    Writes ``<output_dir>/<unit>.json`` (the model) and ``<unit>.outcome.json``
    (its row), overwriting them: the driver has checked what may be overwritten.
    With ``resume``, a unit whose model exists and whose inputs' SHA-256 equal
    those in the model's provenance is skipped (its stored row returned).
    """
    start, cpu = time.perf_counter(), time.process_time()
    try:
        if resume:
            previous = _resumable(files, output_dir)
            if previous is not None:
                return previous
        import warnings

        from hrgtc.fleet.results import calibration_row
        from hrgtc.model import save_model
        from hrgtc.pipeline.calibration import calibrate

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the table reports out-of-range shares
            result = calibrate(files.soaks, files.drifts, files.validate,
                               read_options=read_options, prior=prior_path, settings=settings)
        target = model_path(output_dir, files.unit)
        save_model(result.model, target, force=True)
        outcome = UnitOutcome(files.unit, "ok", calibration_row(result, str(target)), None,
                              time.perf_counter() - start, time.process_time() - cpu)
        _write_outcome(output_dir, outcome)
        return outcome
    except Exception as exc:
        outcome = failed(files.unit, exc, files.paths, start)
        try:
            _write_outcome(output_dir, outcome)
        except OSError:
            pass
        return outcome


def _write_outcome(output_dir: str, outcome: UnitOutcome) -> None:
    from hrgtc.core.files import write_text_atomic

    write_text_atomic(outcome_path(output_dir, outcome.unit),
                      json.dumps(outcome.to_dict(), indent=1, allow_nan=True) + "\n", force=True)


def evaluate_unit(files: UnitFiles, models_dir: str, read_options: ReadOptions | None = None,
                  allan: bool = FleetEvaluation.allan) -> UnitOutcome:
    """Evaluate one unit's validation runs (or its drift runs without any) with its model."""
    start = time.perf_counter()
    try:
        import warnings

        from hrgtc.evaluation import evaluate
        from hrgtc.fleet.results import evaluation_row
        from hrgtc.model import load_model

        model = load_model(model_path(models_dir, files.unit))
        runs = files.validate or files.drifts
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            settings = EvaluationSettings(allan=allan)
            evaluations = [evaluate(model, run, settings=settings,
                                    read_options=read_options).axis for run in runs]
        return UnitOutcome(files.unit, "ok", evaluation_row(evaluations), None,
                           time.perf_counter() - start)
    except Exception as exc:
        return failed(files.unit, exc, files.paths, start)


def report_unit(files: UnitFiles, models_dir: str, output_dir: str,
                read_options: ReadOptions | None = None, force: bool = False) -> UnitOutcome:
    """Write one unit's HTML report (:func:`hrgtc.report.build_report`)."""
    start = time.perf_counter()
    try:
        import warnings

        from hrgtc.report import build_report

        target = Path(output_dir) / f"{files.unit}.html"
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            build_report(model_path(models_dir, files.unit), files.validate or files.drifts,
                         target, soaks=files.soaks, force=force, read_options=read_options)
        return UnitOutcome(files.unit, "ok", {"unit": files.unit, "report_file": str(target)},
                           None, time.perf_counter() - start)
    except Exception as exc:
        return failed(files.unit, exc, files.paths, start)


def simulate_unit(seed: int, index: int, root: str, sample_rate_hz: float, soak_hours: float,
                  setpoints_c: tuple[float, ...], ramp_hours: float, file_format: str,
                  force: bool) -> UnitOutcome:
    """Simulate one unit of the population: soaks, a cool-down, a warm-up and ``truth.json``.

    Files: ``ROOT/<unit>/soaks/soak_<T>C``, ``drift/cooldown``, ``validate/warmup``.
    """
    start = time.perf_counter()
    name = f"s{seed}-u{index:04d}"
    try:
        from hrgtc.core.files import write_text_atomic
        from hrgtc.fleet.population import draw_unit, truth
        from hrgtc.simulate import simulate_files
        from hrgtc.simulate import standard_profiles as profiles

        unit, draw = draw_unit(seed, index)
        folder = Path(root) / unit.name
        base = 1_000_003 * seed + 8 * index  # distinct campaign seeds per unit and role
        high, low = max(setpoints_c), min(setpoints_c)
        written = simulate_files([profiles.soak(t, soak_hours) for t in setpoints_c],
                                 folder / "soaks", file_format, unit=unit,
                                 sample_rate_hz=sample_rate_hz, seed=base + 1, force=force,
                                 workers=1)
        written += simulate_files([profiles.cooldown(20.0, low, ramp_hours)], folder / "drift",
                                  file_format, unit=unit, sample_rate_hz=sample_rate_hz,
                                  seed=base + 2, force=force, workers=1)
        written += simulate_files([profiles.warmup(low, min(high, 20.0), ramp_hours)],
                                  folder / "validate", file_format, unit=unit,
                                  sample_rate_hz=sample_rate_hz, seed=base + 3, force=force,
                                  workers=1)
        write_text_atomic(folder / "truth.json", json.dumps(truth(unit, draw), indent=1) + "\n",
                          force=force)
        return UnitOutcome(unit.name, "ok", {"unit": unit.name, "files": len(written),
                                             "rows": sum(w.rows for w in written)},
                           None, time.perf_counter() - start)
    except Exception as exc:
        return failed(name, exc, (), start)
