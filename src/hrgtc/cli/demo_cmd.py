"""``hrgtc demo``: the paper's campaign end to end on the simulated paper-unit."""

from __future__ import annotations

from pathlib import Path

import typer

from hrgtc.cli._app import console, error_console, library_errors, print_json
from hrgtc.cli.calibrate_cmd import render, render_instrument
from hrgtc.cli.compensate_cmd import render_evaluation
from hrgtc.cli.options import ForceOption, JsonOption
from hrgtc.cli.params import option
from hrgtc.settings.fleet import DemoSettings


def demo_command(
    output: Path = typer.Option(Path("demo-out"), "-o", "--output", help="Folder to write into."),
    quick: bool = typer.Option(
        False, "--quick", help="5 Hz and 3 h soaks instead of 200 Hz and 5 h (for tests)."),
    seed: int = option(DemoSettings, "seed"),
    force: ForceOption = False,
    json_output: JsonOption = False,
) -> None:
    """Simulate the paper's campaign (7 soaks, a cool-down, a warm-up), calibrate, compensate,
    evaluate, report and export C, and compare with the paper's figures; then the same for
    the three-axis imu-3 with rate tables (bias and scale factor, every axis); then unit-play,
    a unit with a thermal memory, held out on a cycle with and without the history variables
    (heating and cooling apart).

    Example: hrgtc demo -o demo-out --force
    """
    from hrgtc.cli.summary_tables import print_summary
    from hrgtc.pipeline.demo import run_demo
    from hrgtc.pipeline.demo_history import to_dict as history_dict

    settings = DemoSettings.quick(seed) if quick else DemoSettings(seed=seed)
    seen: set[str] = set()

    def progress(stage: str, done: float, total: float) -> None:
        if not json_output and stage not in seen:
            seen.add(stage)
            error_console.print(f"[dim]… {stage}[/]")

    with library_errors():
        result = run_demo(output, settings, force=force, progress=progress)
    if json_output:
        print_json({
            "folder": str(result.folder),
            "calibration": result.calibration.to_dict(),
            "training": result.training.to_dict(),
            "validation": result.validation.to_dict(),
            "model_file": str(result.model_file),
            "report_file": str(result.report_file),
            "c_files": [str(p) for p in result.c_files],
            "instrument": None if result.instrument is None else {
                **result.instrument.calibration.to_dict(),
                "model_file": str(result.instrument.model_file),
                "report_file": str(result.instrument.report_file),
                "c_files": [str(p) for p in result.instrument.c_files]},
            "history": None if result.history is None else history_dict(result.history),
        })
        return
    render(result.calibration.axis)
    render_evaluation(result.training)
    render_evaluation(result.validation)
    print_summary(result.summary(), console)
    console.print(f"model: {result.model_file}")
    console.print(f"report: {result.report_file}")
    console.print("C: " + ", ".join(str(p) for p in result.c_files))
    if result.instrument is not None:
        demo = result.instrument
        console.rule("three-axis unit imu-3: bias and scale factor of every axis")
        render_instrument(demo.calibration)
        console.print(f"model: {demo.model_file}")
        console.print(f"compensated warm-up: {demo.compensated.output}")
        console.print(f"report: {demo.report_file}")
        console.print("C: " + ", ".join(str(p) for p in demo.c_files))
    if result.history is not None:
        history = result.history
        console.rule("unit-play, a true thermal memory: held-out cycle with and without "
                     "the history variables")
        print_summary(history.summary(), console)
        console.print(f"model: {history.model_file}")
        console.print(f"report: {history.report_file}")
