"""Write a test report: HTML (the ``test-report`` kind's templates), PDF and JSON.

:func:`write_test_report` computes the report's data (the kind's data function,
:func:`hrgtc.testreport.result.campaign_report`), renders the page with the autoescaped
templates of ``templates/test-report/``, writes the JSON of every figure beside it and
prints the page to PDF with the same headless Chromium the report tests open it with
(``--print-to-pdf``). Each file is written atomically and never overwritten without
``force``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.files import refuse_existing, write_text_atomic
from hrgtc.recording import ReadOptions
from hrgtc.report.figures import COMPENSATED, RAW, Plot, plot
from hrgtc.report.kinds import kind as report_kind
from hrgtc.report.render import number, render
from hrgtc.report.tables import Table
from hrgtc.testreport.manifest import Campaign, load_campaign
from hrgtc.testreport.result import TestReport, TestReportInputs
from hrgtc.testreport.spec import load_spec

__all__ = ["BROWSERS", "TestReportFiles", "outputs", "print_pdf", "test_report_plots",
           "test_report_tables", "write_test_report"]

PathLike = str | os.PathLike[str]

#: The headless browsers tried for the PDF, in order.
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


@dataclass(frozen=True)
class TestReportFiles:
    """What :func:`write_test_report` wrote, and the report's data."""

    html: Path
    json: Path
    pdf: Path | None
    report: TestReport

    __test__ = False


def _cell(value: float | None, digits: int = 5) -> str:
    return number(value, digits)


def test_report_tables(report: TestReport) -> dict[str, object]:
    """The tables of the page behind the figures: turn-ons, soaks, plateaus, Allan curves."""
    tables: dict[str, object] = {
        "turn_on_table": Table(
            "Turn-ons: settled bias (after settle_s, Earth rate subtracted)",
            ("run", "day", "bias [°/h]", "σ/√N of its block means [°/h]", "compensated [°/h]",
             "turn-on time [s]", "warm-up drift [°/h]"),
            tuple((t.name, t.day or "–", _cell(t.bias_dph), _cell(t.bias_se_dph, 3),
                   _cell(t.compensated_dph), _cell(t.turn_on_time_s),
                   _cell(t.warm_up_drift_dph, 4)) for t in report.turn_ons)),
        "soak_table": Table(
            "Soaks: settled temperature and bias",
            ("run", "temperature [°C]", "bias [°/h]", "compensated [°/h]"),
            tuple((p.name, _cell(p.temperature_c), _cell(p.bias_dph), _cell(p.compensated_dph))
                  for p in report.soaks)),
        "plateau_table": Table(
            "Rate-table plateaus: scale-factor error (output − Ω = b + k·Ω)",
            ("temperature [°C]", "k [ppm]", "standard error [ppm]", "holds"),
            tuple((_cell(p.temperature_c), _cell(p.k_ppm), _cell(p.k_se_ppm, 3), str(p.holds))
                  for p in report.plateaus)),
    }
    allan = []
    for key, curve in report.allan.items():
        level = "" if curve.confidence is None else f", χ² interval at {curve.confidence:.4g}"
        allan.append(Table(
            f"Overlapping Allan deviation of {report.allan_run}, {key}{level}",
            ("τ [s]", "σ [°/h]", "lower [°/h]", "upper [°/h]"),
            tuple((_cell(t), _cell(d, 4),
                   _cell(None if curve.lower is None else curve.lower[i], 4),
                   _cell(None if curve.upper is None else curve.upper[i], 4))
                  for i, (t, d) in enumerate(zip(curve.taus_s, curve.deviation, strict=True)))))
    tables["allan_tables"] = allan
    return tables


def _allan_plot(report: TestReport) -> Plot:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.6, 3.4), layout="constrained")
    ax = figure.subplots()
    for key, curve in report.allan.items():
        colour = RAW if key == "raw" else COMPENSATED
        ax.loglog(curve.taus_s, curve.deviation, "-o", ms=2.5, color=colour, label=key)
        if curve.lower is not None and curve.upper is not None:
            ax.fill_between(curve.taus_s, curve.lower, curve.upper, color=colour, alpha=0.15,
                            lw=0)
    ax.set_xlabel("averaging time τ [s]")
    ax.set_ylabel("Allan deviation [°/h]")
    ax.legend(loc="best")
    return plot(figure, f"Overlapping Allan deviation of {report.allan_run} against τ, log-log, "
                "with its χ² interval as a band")


def _soak_plot(report: TestReport) -> Plot:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.6, 3.4), layout="constrained")
    ax = figure.subplots()
    t = np.array([p.temperature_c for p in report.soaks])
    for key, colour, values in (
            ("raw", RAW, [p.bias_dph for p in report.soaks]),
            ("compensated", COMPENSATED, [p.compensated_dph for p in report.soaks])):
        if any(v is None for v in values):
            continue
        y = np.array(values, dtype=np.float64)
        ax.plot(t, y, "o", color=colour, label=key)
        slope, intercept = np.polyfit(t, y, 1)
        line = np.array([t.min(), t.max()])
        ax.plot(line, intercept + slope * line, "-", color=colour, lw=0.8)
    ax.set_xlabel(f"{report.campaign.settings.temperature_column} [°C]")
    ax.set_ylabel("settled bias [°/h]")
    ax.legend(loc="best")
    return plot(figure, "The soaks' settled biases against their temperatures, raw and "
                "compensated, with their least-squares lines")


def test_report_plots(report: TestReport) -> list[tuple[Plot, str]]:
    """The page's figures and their captions: the soaks' biases against temperature (three
    soaks or more), the Allan deviation."""
    out = []
    if len(report.soaks) >= 3:
        out.append((_soak_plot(report), "Bias against temperature: each soak's settled bias "
                    "and the least-squares line whose slope is the bias temperature sensitivity."))
    if report.allan:
        out.append((_allan_plot(report), f"Overlapping Allan deviation of {report.allan_run} "
                    "after settle_s; the band is its χ² interval at the coverage of k."))
    return out


def _browser(browser: PathLike | None) -> str:
    if browser is not None:
        return str(browser)
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    raise InputError(f"no headless browser for the PDF ({', '.join(BROWSERS)} not on the "
                     "PATH): install chromium, or write the HTML and JSON only (pdf=False, "
                     "--no-pdf)")


def print_pdf(html: PathLike, pdf: PathLike, *, force: bool = False,
              browser: PathLike | None = None, timeout_s: float = 120.0) -> Path:
    """Print the page ``html`` to ``pdf`` with headless Chromium (``--print-to-pdf``).

    Raises
    ------
    InputError
        No browser found, or the browser failed (its message quoted).
    OutputExistsError
        ``pdf`` exists and ``force`` is False.
    """
    target = Path(pdf)
    refuse_existing(target, force)
    command = _browser(browser)
    with tempfile.TemporaryDirectory(prefix="hrgtc-pdf-") as work:
        printed = Path(work) / "page.pdf"
        done = subprocess.run(
            [command, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             f"--user-data-dir={Path(work) / 'profile'}", "--no-pdf-header-footer",
             f"--print-to-pdf={printed}", Path(html).resolve().as_uri()],
            capture_output=True, text=True, timeout=timeout_s, check=False)
        if done.returncode != 0 or not printed.is_file():
            raise InputError(f"{command} could not print {html} to PDF (exit "
                             f"{done.returncode}): {done.stderr.strip()[-500:]}")
        if force:
            target.unlink(missing_ok=True)
        shutil.move(str(printed), target)
    return target


def write_test_report(
    manifest: Campaign | PathLike,
    output: PathLike,
    *,
    spec: PathLike | None = None,
    force: bool = False,
    pdf: bool = True,
    browser: PathLike | None = None,
    read_options: ReadOptions | None = None,
) -> TestReportFiles:
    """The test report of a campaign as HTML, PDF and JSON.

    Parameters
    ----------
    manifest
        The campaign manifest (TOML, docs/guide/test-report.md) or a loaded one.
    output
        The HTML file; the JSON and the PDF are written beside it with the suffixes
        ``.json`` and ``.pdf``.
    spec
        ``spec.toml``, the limits of the decision rule; None: nothing is judged.
    force
        Overwrite existing outputs.
    pdf
        Print the PDF (needs a headless Chromium, :data:`BROWSERS`).
    browser
        The browser to print with (default: the first of :data:`BROWSERS` on the PATH).
    read_options
        How to read the runs (default: the manifest's ``file_axis`` only).

    Raises
    ------
    OutputExistsError
        An output exists and ``force`` is False (checked before any run is read).
    InputError
        A wrong manifest or spec, a run that cannot give what its role needs, no browser
        for the PDF.
    """
    paths = outputs(output, pdf)
    html = paths[0]
    refuse_existing(paths, force)
    if pdf:
        _browser(browser)  # before the runs are read
    campaign = manifest if isinstance(manifest, Campaign) else load_campaign(manifest)
    from hrgtc.testreport.figures import FIGURES

    limits = {} if spec is None else load_spec(spec, tuple(FIGURES))
    chosen = report_kind("test-report")
    data = chosen.data(TestReportInputs(campaign, limits, None if spec is None else Path(spec),
                                        read_options))
    write_text_atomic(html, render(chosen.template, report=data, plots=test_report_plots(data),
                                   **test_report_tables(data)), force=force)
    write_text_atomic(paths[1], json.dumps(data.to_dict(), indent=2, ensure_ascii=False) + "\n",
                      force=force)
    printed = print_pdf(html, paths[2], force=force, browser=browser) if pdf else None
    return TestReportFiles(html, paths[1], printed, data)


def outputs(output: PathLike, pdf: bool = True) -> tuple[Path, ...]:
    """The files :func:`write_test_report` writes for ``output``."""
    html = Path(output)
    return (html, html.with_suffix(".json")) + ((html.with_suffix(".pdf"),) if pdf else ())
