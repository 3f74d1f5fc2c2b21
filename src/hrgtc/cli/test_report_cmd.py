"""``hrgtc test-report``: a test campaign's IEEE-style report, judged against a spec, as HTML,
PDF and JSON."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import typer

from hrgtc.cli._app import console, library_errors, print_json
from hrgtc.cli.options import ForceOption, JsonOption, reading_options

if TYPE_CHECKING:
    from hrgtc.recording import ReadOptions


@reading_options
def test_report_command(
    manifest: Path = typer.Argument(
        ..., metavar="MANIFEST", help="The campaign manifest (TOML): unit, site, equipment and "
        "the runs with their roles (docs/guide/test-report.md)."),
    output: Path = typer.Option(
        ..., "-o", "--output", help="HTML file to write; the JSON and the PDF are written "
        "beside it (.json, .pdf)."),
    spec: Path = typer.Option(
        None, "--spec", help="spec.toml: the limits per figure; each is judged with guard "
        "bands (accept, reject, indeterminate). Default: nothing judged."),
    pdf: bool = typer.Option(
        True, "--pdf/--no-pdf", help="Print the PDF with headless Chromium."),
    force: ForceOption = False,
    json_output: JsonOption = False,
    inputs: ReadOptions | None = None,
) -> None:
    """Write the test report of a campaign: turn-on time, warm-up drift, bias repeatability,
    bias temperature and gradient sensitivity before and after compensation, scale factor
    (with a rate table), Allan noise terms; each with its clause, definition, uncertainty
    and coverage factor, and a verdict per figure of the spec.

    Your own files are read with the column mapping and units of every command (--col,
    --time-unit, --rate-unit, ...), the same for every run of the manifest.

    Example: hrgtc test-report campaign.toml --spec spec.toml -o report.html
    """
    from hrgtc.core.files import check_writable, refuse_input
    from hrgtc.report.test_report import outputs, write_test_report

    with library_errors():
        written = outputs(output, pdf)
        refuse_input(written, [manifest, *([spec] if spec else [])])
        check_writable(output, 5e6)
        files = write_test_report(manifest, output, spec=spec, force=force, pdf=pdf,
                                  read_options=inputs)
    if json_output:
        print_json({"html": str(files.html), "json": str(files.json),
                    "pdf": None if files.pdf is None else str(files.pdf),
                    **files.report.to_dict()})
        return
    from hrgtc.cli.summary_tables import print_summary

    print_summary(files.report.summary(), console)
    console.print(f"Written: {', '.join(str(p) for p in written)}", soft_wrap=True)
