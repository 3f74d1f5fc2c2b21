"""One unit's work as a task: paths in, a small picklable :class:`UnitOutcome` out.

Each function runs the library function of one unit (``simulate_files``, the
calibration chain, the evaluation, ``build_report``) on one unit, of one axis or
several: a unit whose files hold the columns of several axes (``freq_hz_x``, ...)
is calibrated and evaluated on every axis, each axis a row of the fleet table. The
calibration chain is called in one place, :func:`_calibrate_unit`, the evaluation in
one, :func:`_evaluate_run`. The worker reads the unit's files from their paths and
writes its outputs itself; only paths, settings and the outcome (rows of plain
numbers) travel between the client and the workers. A task never raises: whatever
goes wrong becomes a failed outcome with the error's type, message and, where the
message names them, the file, column and row, so one unit's bad input never stops
the others.
"""

from __future__ import annotations

import json
import re
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal

from msgspec import Meta

from hrgtc.core import records
from hrgtc.fleet.manifest import UnitFiles
from hrgtc.recording import ReadOptions
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.compensation import EvaluationSettings
from hrgtc.settings.fleet import FleetEvaluation, FleetSimulation

__all__ = ["UnitOutcome", "calibrate_unit", "evaluate_unit", "report_unit", "simulate_unit"]

if TYPE_CHECKING:
    from hrgtc.evaluation import Evaluation
    from hrgtc.model import Model
    from hrgtc.pipeline.calibration import Calibration

#: Recording columns an error message may name.
_COLUMNS = ("time_s", "freq_hz", "rate_dph", "chamber_c", "housing_c", "resonator_c",
            "bias_dph")
_ROW = re.compile(r"\brows? (\d+)")
_QUOTED_COLUMN = re.compile(r"column '([^']+)'")


@dataclass(frozen=True)
class UnitOutcome(records.Written):
    """What a task did for one unit.

    Attributes
    ----------
    unit
        The unit's name.
    status
        ``"ok"``, ``"skipped"`` (resumed: inputs unchanged) or ``"failed"``.
    row
        The unit's columns of the fleet table, the same on each of its axes' rows
        (plain JSON types; without ``axes``, the unit's one row).
    error
        ``{"type", "message", "file", "column", "row"}`` for a failed unit.
    seconds
        Wall time of the task. [s]
    cpu_seconds
        CPU time of the task's process while it ran (tasks are single-threaded, so
        the work itself, whatever else the machine runs). [s]
    axes
        The columns of each of the unit's axes, one row of the fleet table each, in the
        model's axis order (``axis`` "" for a single-axis unit; empty for a failed unit).
    """

    omit_when_default = ("axes",)  # a unit's outcome written before the long form

    unit: str
    status: Literal["ok", "skipped", "failed"]
    #: The unit's columns of the fleet table (:mod:`hrgtc.fleet.results`).
    row: dict[str, Any] = field(default_factory=dict)
    error: Annotated[dict[str, Any], ErrorRecord] | None = None
    seconds: records.NonNegative = 0.0
    cpu_seconds: records.NonNegative = 0.0
    #: The columns of each axis, a row of the fleet table each (none: the one ``row``).
    axes: tuple[dict[str, Any], ...] = ()

    def __post_init__(self) -> None:
        if self.error is not None:  # as error_record gives it: a traceback only when known
            object.__setattr__(self, "error", {k: v for k, v in self.error.items()
                                               if k != "traceback" or v is not None})


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


#: :class:`UnitOutcome` in its file (``<unit>.outcome.json`` beside the model), generated
#: from its fields.
UnitOutcomeRecord = records.record_of(
    UnitOutcome, doc="A :class:`UnitOutcome` in its file (``<unit>.outcome.json`` beside the "
    "model): field\nnames and bounds, from which its ``to_dict``/``from_dict`` and JSON Schema "
    "come.")


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
    if outcome.status != "ok" or not outcome.axes or stored != _input_hashes(files):
        return None  # (an outcome without axes: written before the long form)
    return UnitOutcome(files.unit, "skipped", outcome.row, None, 0.0, axes=outcome.axes)


def _calibrate_unit(files: UnitFiles, settings: CalibrationSettings,
                    read_options: ReadOptions | None,
                    prior_path: str | None) -> Calibration:
    """The one call of the calibration chain for a unit, every axis of it
    (:func:`hrgtc.pipeline.calibration.calibrate`: a single-axis unit is the one-axis
    case, axis ""). Warnings are silenced: the table reports the shares out of the
    calibrated ranges.
    """
    import warnings

    from hrgtc.pipeline.calibration import calibrate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return calibrate(files.soaks, files.drifts, files.validate, read_options=read_options,
                         prior=prior_path, settings=settings)


def calibrate_unit(files: UnitFiles, output_dir: str, settings: CalibrationSettings,
                   read_options: ReadOptions | None = None, resume: bool = False,
                   prior_path: str | None = None) -> UnitOutcome:
    """Calibrate one unit, every axis of it (:func:`_calibrate_unit`), and write its model file.

    Writes ``<output_dir>/<unit>.json`` (the model, one file for every axis) and
    ``<unit>.outcome.json`` (its rows), overwriting them: the driver has checked what may
    be overwritten. With ``resume``, a unit whose model exists and whose inputs' SHA-256
    equal those in the model's provenance is skipped (its stored rows returned).
    """
    start, cpu = time.perf_counter(), time.process_time()
    try:
        if resume:
            previous = _resumable(files, output_dir)
            if previous is not None:
                return previous
        from hrgtc.fleet.results import calibration_rows
        from hrgtc.model import save_model

        calibration = _calibrate_unit(files, settings, read_options, prior_path)
        target = model_path(output_dir, files.unit)
        save_model(calibration.model, target, force=True)
        outcome = UnitOutcome(files.unit, "ok", {"unit": files.unit, "model_file": str(target)},
                              None, time.perf_counter() - start, time.process_time() - cpu,
                              calibration_rows(calibration))
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


def _evaluate_run(run: str, model: Model, settings: EvaluationSettings,
                  read_options: ReadOptions | None) -> dict[str, Evaluation]:
    """The one call of the evaluation for a run: axis ("" for a single-axis model) -> its
    evaluation (:func:`hrgtc.evaluation.evaluate`). Warnings are silenced: the table
    reports the shares out of the calibrated ranges."""
    import warnings

    from hrgtc.evaluation import evaluate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return evaluate(model, run, settings=settings, read_options=read_options).axes


def evaluate_unit(files: UnitFiles, models_dir: str, read_options: ReadOptions | None = None,
                  allan: bool = FleetEvaluation.allan) -> UnitOutcome:
    """Evaluate one unit's validation runs (or its drift runs without any) with its model,
    every axis of it: a row per axis."""
    start = time.perf_counter()
    try:
        from hrgtc.fleet.results import evaluation_row
        from hrgtc.model import load_model

        model = load_model(model_path(models_dir, files.unit))
        settings = EvaluationSettings(allan=allan)
        runs = [_evaluate_run(run, model, settings, read_options)
                for run in files.validate or files.drifts]
        rows = tuple({"axis": axis, **evaluation_row([run[axis] for run in runs])}
                     for axis in model.axes)
        return UnitOutcome(files.unit, "ok", {"unit": files.unit}, None,
                           time.perf_counter() - start, axes=rows)
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


def simulate_unit(settings: FleetSimulation, index: int, root: str,
                  force: bool) -> UnitOutcome:
    """Simulate unit ``index`` of the population (:mod:`hrgtc.fleet.population`; an
    instrument of ``settings.axes`` axes when more than one): soaks, a cool-down, a
    warm-up and the ground truth.

    Files: ``ROOT/<unit>/soaks/soak_<T>C``, ``drift/cooldown``, ``validate/warmup`` and
    ``truth.json`` (an instrument: ``truth-<axis>.json``, each axis's resonator and draw).
    """
    start = time.perf_counter()
    seed = settings.seed
    name = f"s{seed}-u{index:04d}"
    try:
        from hrgtc.core.files import write_text_atomic
        from hrgtc.fleet.population import draw_instrument, draw_unit, truth
        from hrgtc.simulate import simulate_files
        from hrgtc.simulate import standard_profiles as profiles

        if settings.axes > 1:
            unit, draws = draw_instrument(seed, index, settings.axes)
            truths = {f"truth-{axis}.json": truth(unit.axes[axis], draw)
                      for axis, draw in draws.items()}
        else:
            unit, draw = draw_unit(seed, index)
            truths = {"truth.json": truth(unit, draw)}
        folder = Path(root) / unit.name
        base = 1_000_003 * seed + 8 * index  # distinct campaign seeds per unit and role
        setpoints_c = tuple(float(t) for t in settings.setpoints_c)
        high, low, ramp_hours = max(setpoints_c), min(setpoints_c), settings.ramp_hours
        runs = (("soaks", [profiles.soak(t, settings.soak_hours) for t in setpoints_c]),
                ("drift", [profiles.cooldown(20.0, low, ramp_hours)]),
                ("validate", [profiles.warmup(low, min(high, 20.0), ramp_hours)]))
        written = []
        for k, (role, campaign) in enumerate(runs, start=1):
            written += simulate_files(campaign, folder / role, settings.file_format, unit=unit,
                                      sample_rate_hz=settings.sample_rate_hz, seed=base + k,
                                      force=force, workers=1)
        for file, document in truths.items():
            write_text_atomic(folder / file, json.dumps(document, indent=1) + "\n",
                              force=force)
        return UnitOutcome(unit.name, "ok", {"unit": unit.name, "files": len(written),
                                             "rows": sum(w.rows for w in written)},
                           None, time.perf_counter() - start)
    except Exception as exc:
        return failed(name, exc, (), start)
