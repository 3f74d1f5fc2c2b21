"""``hrgtc report``: one self-contained HTML file with the unit's Figs. 3-6 and tables."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hrgtc.cli._app import console, library_errors, print_json, progress_bar
from hrgtc.cli.options import AxesOption, ForceOption, JsonOption, reading_options
from hrgtc.cli.params import settings_options
from hrgtc.settings.compensation import ReportSettings

if TYPE_CHECKING:
    from hrgtc.recording import ReadOptions


@reading_options
@settings_options(ReportSettings)
def report_command(
    runs: list[Path] = typer.Argument(
        ..., metavar="RUN...", help="Runs to compensate and show (Fig. 6), one section each."),
    model: Path = typer.Option(
        ..., "--model", "-m", help="Model file written by 'hrgtc calibrate'."),
    output: Path = typer.Option(..., "-o", "--output", help="HTML file to write."),
    soak: list[Path] = typer.Option(
        None, "--soak", help="Soak recording for Figs. 3 and 5 (repeat); default: the soaks "
        "named in the model file, where they still exist."),
    force: ForceOption = False,
    json_output: JsonOption = False,
    axes: AxesOption = None,
    inputs: ReadOptions | None = None,
    settings: ReportSettings | None = None,
) -> None:
    """Write the HTML report: settling of the soaks (Fig. 3), T-f fit (Fig. 4, Table 1),
    temperature from frequency (Fig. 5, Table 2), raw and compensated output with bias
    stability and Allan deviation (Fig. 6), and the stepwise drift model (Eq. 22).

    Example: hrgtc report --model unit.json cooldown.parquet warmup.parquet -o report.html
    """
    from hrgtc.cli.compensate_cmd import note_unchecked
    from hrgtc.compensate.multi_axis import parse_axes
    from hrgtc.core.files import check_writable, refuse_existing, refuse_input
    from hrgtc.model import load_model
    from hrgtc.report import build_report

    with library_errors(), progress_bar("report", enabled=not json_output) as progress:
        refuse_input(output, [*runs, model, *(soak or [])])
        refuse_existing(output, force)
        check_writable(output, 20e6)  # before the passes over the runs
        settings = dataclasses.replace(settings or ReportSettings(), axes=parse_axes(axes))
        path = build_report(model, runs, output, settings, soaks=soak or None, force=force,
                            progress=progress, read_options=inputs)
        loaded = load_model(model)
    note_unchecked(loaded, model)
    size = path.stat().st_size
    if json_output:
        print_json({"report": str(path), "bytes": size, "runs": [str(r) for r in runs]})
        return
    console.print(f"Report written to {path} ({size / 1e6:.2f} MB)", soft_wrap=True)
