"""The thermal-history part of ``hrgtc demo``: a unit with a true memory, held out on a cycle.

The simulated ``unit-play`` (a play operator of width 2 °C on the resonator temperature,
docs/history.md) is trained as the paper's unit is, on soaks (the thermometer), a
cool-down and a warm-up, and held out on a temperature cycle 20 → −20 → 40 → 20 °C that
turns round twice. Two models are fitted on the same files: today's candidates, and the
same with the history variables ``gsat`` and ``play`` offered, the play's width learned
from :data:`hrgtc.drift.variables.play.WIDTHS_C` by the fits' leave-one-run-out score and
the model kept only when that score beats today's (the rule of docs/history.md). The
held-out cycle is evaluated with both, heating and cooling apart
(:class:`hrgtc.evaluation.heating_cooling.DirectionStats`), and the report of the chosen
model shows the training runs and the cycle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hrgtc.core.progress import StageProgress, for_stage
from hrgtc.core.summary import Figure, Summary
from hrgtc.evaluation import Evaluation, evaluate
from hrgtc.evaluation.heating_cooling import DIRECTIONS
from hrgtc.model import save_model
from hrgtc.pipeline.calibration import Calibration, calibrate
from hrgtc.report import build_report
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.compensation import ReportSettings
from hrgtc.settings.drift import GRADIENT_TERMS, DriftSettings
from hrgtc.settings.fleet import SETPOINTS_C
from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles
from hrgtc.simulate.profiles import from_mapping

__all__ = ["HELDOUT_CYCLE", "HISTORY_TERMS", "HistoryDemo", "run_history_demo"]

#: The held-out cycle (the one of bench/bench_heldout.py): down at 1 °C/min, up at
#: 0.5 °C/min, back at 1 °C/min, with holds where it turns.
HELDOUT_CYCLE = {"name": "cycle", "start_c": 20.0, "segments": [
    {"setpoint_c": -20.0, "ramp_c_per_min": 1.0}, {"setpoint_c": -20.0, "hold_h": 1.5},
    {"setpoint_c": 40.0, "ramp_c_per_min": 0.5}, {"setpoint_c": 40.0, "hold_h": 1.5},
    {"setpoint_c": 20.0, "ramp_c_per_min": 1.0}, {"setpoint_c": 20.0, "hold_h": 1.0}]}
#: Candidates of the model with the history variables: today's and gsat, play.
HISTORY_TERMS = (*GRADIENT_TERMS, "gsat", "play")
UNIT = "unit-play"


@dataclass(frozen=True)
class HistoryDemo:
    """Files and figures of the thermal-history part.

    Attributes
    ----------
    without, with_history
        The calibration with today's candidates, and with ``gsat`` and ``play`` offered
        (at the learned width).
    kept
        Whether the history model's leave-one-run-out score beat today's (the model the
        file and the report hold is then the history model).
    play_width_c
        The learned width. [°C]
    scores_dph
        Width -> leave-one-run-out score of the history fit; ``"without"``: today's. [°/h]
    cycle_without, cycle_with
        The held-out cycle evaluated with each model.
    """

    without: Calibration
    with_history: Calibration
    kept: bool
    play_width_c: float
    scores_dph: dict[str, float]
    cycle_without: Evaluation
    cycle_with: Evaluation
    model_file: Path
    report_file: Path

    def figures(self) -> dict[str, dict[str, float]]:
        """``{"heating"|"cooling"|"whole_run": {"raw", "without", "with", "without_residual",
        "with_residual"}}``: the figures of :meth:`summary` as plain floats. [°/h]"""
        out = {}
        for direction in (*DIRECTIONS, "whole run"):
            raw, without, without_residual = _figures(self.cycle_without, direction)
            _, with_history, with_residual = _figures(self.cycle_with, direction)
            out[direction.replace(" ", "_")] = {
                "raw": raw, "without": without, "with": with_history,
                "without_residual": without_residual, "with_residual": with_residual}
        return out

    def summary(self) -> Summary:
        """The held-out cycle's 10 s bias stability, heating and cooling apart: raw, and
        compensated by each model (with the RMS of model minus the simulator's true bias)."""
        cells: list[Figure] = []
        for direction in (*DIRECTIONS, "whole run"):
            cells += _row(direction, self.cycle_without, self.cycle_with)
        terms = ", ".join(self.with_history.model.drift.selected)
        notes = (f"history model ({terms}; play width {self.play_width_c:g} °C): "
                 f"leave-one-run-out {self.scores_dph[f'{self.play_width_c:g}']:.4g} °/h "
                 f"against {self.scores_dph['without']:.4g} °/h without: "
                 + ("kept" if self.kept else "not kept (the file holds today's model)"),)
        return Summary(f"{UNIT}: held-out cycle, heating and cooling apart (10 s bias "
                       "stability; model - true bias)", (("cycle", tuple(cells)),), notes)


def _row(direction: str, without: Evaluation, with_history: Evaluation) -> list[Figure]:
    """One row of :meth:`HistoryDemo.summary`: raw, each model's compensated and residual."""
    key = direction.replace(" ", "_")

    def cell(name: str, column: str, value: float, definition: str) -> Figure:
        return Figure(f"cycle.{key}.{name}", f"{direction}: {column}", value, "°/h",
                      spec=".4f", row=key, column=column, definition=definition)

    figures = [Figure(f"cycle.{key}.direction", direction, direction, row=key,
                      column="held-out cycle"),
               cell("raw", "raw", _figures(without, direction)[0],
                    "1σ of the 10 s means of the raw rate.")]
    for label, evaluation in (("without", without), ("with history", with_history)):
        _, stability, residual = _figures(evaluation, direction)
        name = label.replace(" ", "_")
        figures += [cell(f"{name}.compensated", label, stability,
                         f"1σ of the 10 s means of the rate compensated {label} the history "
                         "variables."),
                    cell(f"{name}.residual", f"{label}: model - truth", residual,
                         "RMS of the model's bias minus the simulated true bias (10 s means "
                         "while heating or cooling; every sample over the whole run).")]
    return figures


def _figures(evaluation: Evaluation, direction: str) -> tuple[float, float, float]:
    """Raw and compensated bias stability and RMS of model - truth of one direction (or of
    the whole run). [°/h]"""
    if direction == "whole run":
        residual = evaluation.residual_rms_dph
        return (evaluation.raw_10s, evaluation.compensated_10s,
                math.nan if residual is None else float(residual))
    stats = evaluation.directions
    if stats is None:
        return math.nan, math.nan, math.nan
    residual = math.nan if stats.residual_rms_dph is None else stats.residual_rms_dph[direction]
    return stats.raw_dph[direction], stats.compensated_dph[direction], residual


def run_history_demo(folder: Path, rate_hz: float, soak_hours: float, seed: int, *,
                     force: bool = False, progress: StageProgress | None = None
                     ) -> HistoryDemo:
    """Simulate ``unit-play``'s campaign into ``folder``, fit both models, evaluate the
    held-out cycle with each, write the chosen model and its report."""
    from hrgtc.drift.variables.play import WIDTHS_C, learn_width

    def simulate(runs: list, name: str, offset: int) -> list[Path]:
        written = simulate_files(runs, folder / name, "parquet", unit=UNIT,
                                 sample_rate_hz=rate_hz, seed=seed + offset, force=force,
                                 progress=for_stage(progress, f"{UNIT}: simulate {name}"))
        return [Path(w.path) for w in written]

    soaks = simulate([profiles.soak(t, soak_hours) for t in SETPOINTS_C], "soaks", 20)
    training = [*simulate([profiles.cooldown(20.0, -20.0, 5.0)], "cooldown", 21),
                *simulate([profiles.warmup(-20.0, 20.0, 5.0)], "warmup", 22)]
    cycle = simulate([from_mapping(HELDOUT_CYCLE)], "cycle", 23)[0]

    def fit(drift: DriftSettings, stage: str) -> Calibration:
        def calibration_stage(name: str, done: float, total: float) -> None:
            if progress is not None:
                progress(f"{UNIT}: calibrate {stage}: {name}", done, total)

        return calibrate(soaks, training, settings=CalibrationSettings(drift=drift),
                         progress=calibration_stage)

    without = fit(DriftSettings(), "today's candidates")
    fits: dict[float, Calibration] = {}

    def score(width: float) -> float:
        fits[width] = fit(DriftSettings(terms=HISTORY_TERMS, play_width_c=width),
                          f"with gsat, play ({width:g} °C)")
        return _score(fits[width])

    width, scores = learn_width(score, WIDTHS_C)
    kept = scores[width] < _score(without)
    chosen = fits[width] if kept else without
    model_file = save_model(chosen.model, folder / f"{UNIT}.json", force=force)
    points = ReportSettings.max_points
    evaluations = {label: evaluate(c.model, cycle, max_points=points,
                                   progress=for_stage(progress, f"{UNIT}: evaluate cycle"
                                                      f" ({label})")).axis
                   for label, c in (("without", without), ("with", fits[width]))}
    report_file = build_report(chosen.model, [*training, evaluations[
        "with" if kept else "without"]], folder / "report.html", soaks=soaks, force=force,
        progress=for_stage(progress, f"{UNIT}: report"))
    return HistoryDemo(without, fits[width], bool(kept), float(width),
                       {**{f"{w:g}": float(s) for w, s in scores.items()},
                        "without": _score(without)},
                       evaluations["without"], evaluations["with"], model_file, report_file)


def _score(calibration: Calibration) -> float:
    """The fit's leave-one-run-out score (inf when it has none). [°/h]"""
    validation = calibration.model.drift.cross_validation
    return math.inf if validation is None else float(validation.score_dph)


def to_dict(demo: HistoryDemo) -> dict[str, Any]:
    """Plain JSON types of the history part (``hrgtc demo --json``)."""
    return {"unit": UNIT, "kept": demo.kept, "play_width_c": demo.play_width_c,
            "scores_dph": demo.scores_dph, "figures": demo.figures(),
            "terms_with_history": list(demo.with_history.model.drift.selected),
            "terms_without": list(demo.without.model.drift.selected),
            "cycle_without": demo.cycle_without.to_dict(),
            "cycle_with": demo.cycle_with.to_dict(),
            "summary": demo.summary().to_dict(),
            "model_file": str(demo.model_file), "report_file": str(demo.report_file)}
