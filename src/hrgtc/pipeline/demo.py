"""The paper's whole campaign, end to end, on the simulated ``paper-unit``; then a whole
three-axis instrument.

Simulate seven soaks (-20 ... 40 °C, Section 3 of [1]), a cool-down to train
and a warm-up with another seed to validate (Section 4.2, Fig. 6); calibrate;
compensate; evaluate; write the model, the compensated warm-up, the HTML report
and the C files into one folder. Then the same for the three-axis ``imu-3`` with
rate tables (bias and scale factor of every axis, held-out warm-up and rate table),
into ``imu-3/``; then ``unit-play``, a unit with a true thermal memory, trained on a
cool-down and a warm-up with and without the history variables and held out on a cycle
(:mod:`hrgtc.pipeline.demo_history`), into ``unit-play/``. What ``hrgtc demo`` and
``make demo`` run.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

from hrgtc.compensate import OUTPUT_COLUMNS, CompensationSummary, compensate_file
from hrgtc.compensate.file_pass import compensated_metadata
from hrgtc.core.errors import HrgtcWarning
from hrgtc.core.files import refuse_existing
from hrgtc.core.progress import StageProgress, for_stage
from hrgtc.core.summary import Summary
from hrgtc.evaluation import Evaluation, evaluate
from hrgtc.evaluation.instrument_figures import stability_table
from hrgtc.export.export_c import export_c
from hrgtc.model import save_model
from hrgtc.pipeline.calibration import Calibration, RateTables, calibrate
from hrgtc.pipeline.demo_history import HistoryDemo, run_history_demo
from hrgtc.recording import ReadOptions, RecordingWriter
from hrgtc.report import build_report
from hrgtc.settings.compensation import ReportSettings
from hrgtc.settings.fleet import SETPOINTS_C, DemoSettings
from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles

#: Most points per curve in the report's figures.
REPORT_POINTS = ReportSettings.max_points


@dataclass(frozen=True)
class DemoResult:
    """Files written and figures computed by :func:`run_demo`."""

    folder: Path
    calibration: Calibration
    training: Evaluation
    validation: Evaluation
    compensated: CompensationSummary
    model_file: Path
    report_file: Path
    c_files: tuple[Path, ...]
    instrument: InstrumentDemo | None = None
    history: HistoryDemo | None = None

    def summary(self) -> Summary:
        """10 s bias stability raw → compensated: the paper's, the training cool-down's
        and the held-out warm-up's
        (:func:`hrgtc.evaluation.instrument_figures.stability_table`)."""
        return stability_table((("paper-unit cool-down (training)", self.training),
                                ("paper-unit warm-up (held out)", self.validation)))


@dataclass(frozen=True)
class InstrumentDemo:
    """The three-axis part of the demo: files and figures."""

    calibration: Calibration
    model_file: Path
    compensated: CompensationSummary
    report_file: Path
    c_files: tuple[Path, ...]


def run_demo(
    folder: str | os.PathLike[str] = "demo-out",
    settings: DemoSettings | None = None,
    *,
    force: bool = False,
    progress: StageProgress | None = None,
) -> DemoResult:
    """Simulate, calibrate, compensate, evaluate, report and export, into ``folder``.

    Raises
    ------
    OutputExistsError
        When ``folder`` already holds demo output and ``force`` is False.
    """
    s = settings or DemoSettings()
    root = Path(folder)
    model_file = root / "paper-unit.json"
    refuse_existing(model_file, force, f"{root} already holds a demo")


    def simulate(runs: list, folder: str, seed: int, stage: str) -> list:
        return simulate_files(runs, root / folder, "parquet", unit="paper-unit",
                              sample_rate_hz=s.sample_rate_hz, seed=seed, force=force,
                              progress=for_stage(progress, f"simulate {stage}"))

    soaks = simulate([profiles.soak(t, s.soak_hours) for t in SETPOINTS_C], "soaks", s.seed,
                     "soaks")
    cool = simulate([profiles.cooldown(20.0, -20.0, s.ramp_hours)], "runs", s.seed + 1,
                    "cool-down")[0]
    warm = simulate([profiles.warmup(-20.0, 20.0, s.ramp_hours)], "runs", s.seed + 2,
                    "warm-up")[0]
    soak_paths = [Path(w.path) for w in soaks]

    def calibration_stage(name: str, done: float, total: float) -> None:
        if progress is not None:
            progress(f"calibrate: {name}", done, total)

    result = calibrate(soak_paths, [Path(cool.path)], progress=calibration_stage)
    save_model(result.model, model_file, force=force)
    # Each run is compensated once: the pass that evaluates the warm-up also writes its
    # compensated file, and both passes keep the plotting blocks the report draws.
    training = evaluate(result.model, cool.path, max_points=REPORT_POINTS,
                        progress=for_stage(progress, "evaluate cool-down")).axis
    compensated_path = root / "runs" / "warmup_compensated.parquet"
    head = ReadOptions().head(warm.path, rows=1)
    names = (*head.names, *OUTPUT_COLUMNS)
    with RecordingWriter(compensated_path, compensated_metadata(head.metadata, result.model),
                         names, force=force) as writer:
        validation = evaluate(result.model, warm.path, max_points=REPORT_POINTS,
                              on_output=writer.write,
                              progress=for_stage(progress, "compensate and evaluate warm-up")
                              ).axis
    compensated = CompensationSummary(
        str(warm.path), str(compensated_path), validation.n_samples,
        validation.out_of_range_fraction, validation.rate_out_of_range_fraction)
    result = replace(result, axes={"": replace(result.axis, validation=(validation,))})
    report_file = build_report(
        result.model, [training, validation], root / "report.html", soaks=soak_paths,
        force=force, progress=for_stage(progress, "report"),
    )
    c_files = tuple(export_c(result.model, root / "c", force=force))
    instrument = None
    if s.instrument_rate_hz is not None:
        instrument = run_instrument_demo(root / "imu-3", s, force=force, progress=progress)
    history = None
    if s.history_rate_hz is not None:
        history = run_history_demo(root / "unit-play", s.history_rate_hz, HISTORY_SOAK_HOURS,
                                   s.seed, force=force, progress=progress)
    return DemoResult(root, result, training, validation, compensated, model_file,
                      report_file, c_files, instrument, history)


#: Soak length of the thermal-history part, the same in ``--quick``. [h]
HISTORY_SOAK_HOURS = 5.0
#: Rate-table plateaus of the three-axis demo: training, and held out between them. [°C]
TABLE_PLATEAUS_C = (-15.0, 0.0, 15.0, 30.0)
HELDOUT_TABLE_C = (-5.0, 22.0)


def run_instrument_demo(folder: Path, s: DemoSettings, *, force: bool = False,
                        progress: StageProgress | None = None) -> InstrumentDemo:
    """The simulated three-axis ``imu-3``: soaks, cool-down, rate tables -> one model of
    every axis (bias and scale factor); held out: a warm-up and a rate table at two other
    temperatures; compensated warm-up, per-axis report and C into ``folder``."""
    rate = float(s.instrument_rate_hz or 10.0)
    axes = ("x", "y", "z")

    def simulate(runs: list, name: str, seed: int) -> list[Path]:
        written = simulate_files(runs, folder / name, "parquet", unit="imu-3",
                                 sample_rate_hz=rate, seed=seed, force=force,
                                 progress=for_stage(progress, f"imu-3: simulate {name}"))
        return [Path(w.path) for w in written]

    soaks = simulate([profiles.soak(t, s.soak_hours) for t in SETPOINTS_C], "soaks", s.seed + 10)
    cool = simulate([profiles.cooldown(20.0, -20.0, s.ramp_hours)], "runs", s.seed + 11)
    warm = simulate([profiles.warmup(-20.0, 20.0, s.ramp_hours)], "runs", s.seed + 12)
    table = simulate([profiles.rate_table(TABLE_PLATEAUS_C, hold_s=60.0, soak_h=2.0, axes=axes)],
                     "ratetable", s.seed + 13)
    heldout = simulate([profiles.rate_table(HELDOUT_TABLE_C, hold_s=60.0, soak_h=2.0,
                                            axes=axes)], "ratetable_heldout", s.seed + 14)

    def calibration_stage(name: str, done: float, total: float) -> None:
        if progress is not None:
            progress(f"imu-3: calibrate {name}", done, total)

    with warnings.catch_warnings():  # four table temperatures: the cubic is left out, known
        warnings.simplefilter("ignore", HrgtcWarning)
        calibration = calibrate(soaks, cool, warm, rate_tables=RateTables(table, heldout),
                                progress=calibration_stage)
    model_file = save_model(calibration.model, folder / "imu-3.json", force=force)
    compensated = compensate_file(
        warm[0], folder / "runs" / "warmup_compensated.parquet", calibration.model, force=force,
        progress=for_stage(progress, "imu-3: compensate warm-up"))
    report_file = build_report(calibration.model, [*cool, *warm], folder / "report.html",
                               soaks=soaks, force=force,
                               progress=for_stage(progress, "imu-3: report"))
    c_files = tuple(export_c(calibration.model, folder / "c", force=force))
    return InstrumentDemo(calibration, model_file, compensated, report_file, c_files)
