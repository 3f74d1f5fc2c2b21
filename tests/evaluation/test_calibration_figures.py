"""Tests of hrgtc.evaluation.calibration_figures: a calibration's figures, the same in every
renderer.

The plain text (``AxisCalibration.summary().text()``), the CLI's rich tables
(``hrgtc calibrate``), the HTML (``Summary.html()``) and the ``--json`` document
(``AxisCalibration.to_dict()``, where a figure's name is a place in it) are parsed back
and must give every figure of the calibration's :class:`~hrgtc.core.summary.Summary`, in
its section, with the same value, unit and interval, like ``test_run_figures`` for a run.
"""

from __future__ import annotations

import io
import json
import math
import re
from html import unescape

import pytest
from rich.console import Console

import hrgtc.cli.calibrate_cmd as calibrate_cmd
from hrgtc.pipeline.calibration import calibrate


def _agrees(figure, cell: str) -> bool:
    """``cell`` (a value, possibly followed by unit and interval) shows ``figure``'s value."""
    if isinstance(figure.value, str):
        return cell.startswith(figure.value)
    token = cell.split()[0] if cell.split() else ""
    if isinstance(figure.value, float) and math.isnan(figure.value):
        return token == "-"
    return float(token) == pytest.approx(float(figure.value), rel=10.0 ** (1 - figure.digits))


@pytest.fixture(scope="module")
def result(paper_campaign):
    files = paper_campaign
    return calibrate(files.soaks, [files.cooldown], [files.warmup]).axis


def _rich_tables(text: str) -> dict[tuple[str, str], list[str]]:
    """(table title, figure) -> [value, unit, interval] of the rich output."""
    cells, title, in_title = {}, "", False
    for line in text.splitlines():
        row = [c.strip() for c in line.split("│")[1:-1]]
        if len(row) == 4 and row[0] != "figure":
            cells[(title, row[0])] = row[1:]
        if line.strip() and line.strip()[0] not in "┏┃┡│└━─":  # a title, wrapped or not
            title = f"{title} {line.strip()}" if in_title else line.strip()
            in_title = True
        else:
            in_title = False
    return cells


def _text_lines(text: str) -> dict[tuple[str, str], str]:
    """(section, figure) -> what follows ``label: `` in the plain text."""
    out, heading = {}, ""
    for line in text.splitlines():
        if line.startswith("  ") and ": " in line:
            label, _, rest = line.strip().partition(": ")
            while (heading, label) not in FIGURE_KEYS and ": " in rest:  # a label with ': '
                more, _, rest = rest.partition(": ")
                label = f"{label}: {more}"
            out[(heading, label)] = rest
        elif line.endswith(":") and not line.startswith(" "):
            heading = line[:-1]
    return out


FIGURE_KEYS: set[tuple[str, str]] = set()


def _html_tables(page: str) -> dict[tuple[str, str], list[str]]:
    """(section, figure) -> [value, unit, interval] of ``Summary.html()``."""
    out, heading = {}, ""
    for row in re.findall(r"<tr>(.*?)</tr>", page):
        header = re.fullmatch(r'<th colspan="4">(.*)</th>', row)
        if header:
            heading = unescape(header.group(1))
            continue
        cells = [unescape(c) for c in re.findall(r"<td>(.*?)</td>", row)]
        if len(cells) == 4:
            out[(heading, cells[0])] = cells[1:]
    return out


def _json_value(document, name: str):
    """The value at a figure's name in the ``--json`` document, or KeyError."""
    node = document
    for token in re.findall(r"[^.\[\]]+|\[\d+\]", name):
        node = node[int(token[1:-1])] if token.startswith("[") else node[token]
    return node


def test_text_rich_html_and_json_show_the_same_figures(result, monkeypatch):
    summary = result.summary(warnings=False)
    keys = [(heading, f.label) for heading, figures in summary.sections for f in figures]
    assert len(set(keys)) == len(keys)  # a label names one figure in its section
    FIGURE_KEYS.update(keys)
    names = set(summary.figures())
    for name in ("thermometer.coefficients[3]", "thermometer.max_error_c", "drift.intercept_dph",
                 "drift.coefficients.f", "drift.history[0].fstat", "drift.n_samples",
                 "validation[0].bias_stability_dph.compensated.10",
                 "validation[0].heating_cooling.heating.compensated_dph"):
        assert name in names, name

    text = _text_lines(summary.text())
    out = io.StringIO()
    monkeypatch.setattr(calibrate_cmd, "console", Console(file=out, width=400))
    calibrate_cmd.render(result)
    printed = out.getvalue()
    rich = _rich_tables(printed)
    html = _html_tables(summary.html())
    document = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    in_json = 0
    for heading, figures in summary.sections:
        for figure in figures:
            key = (heading, figure.label)
            assert _agrees(figure, text[key]), (figure, text[key])
            if figure.interval is not None:
                assert figure.interval_text() in text[key]
            # a title line above a table (the summary's own title) joins its heading
            found = [cells for (title, label), cells in rich.items()
                     if label == figure.label and (title == heading
                                                   or title.endswith(f" {heading}"))]
            assert len(found) == 1, (key, found)
            for cells in (found[0], html[key]):
                assert _agrees(figure, cells[0]), (figure, cells)
                assert cells[1:] == [figure.unit, figure.interval_text()], (figure, cells)
            try:
                value = _json_value(document, figure.name)
            except (KeyError, IndexError, TypeError):
                continue
            in_json += 1
            if value is None:
                assert isinstance(figure.value, str) or math.isnan(figure.value)
            else:
                assert value == pytest.approx(figure.value, rel=1e-12), figure
    # the drift model's and the held-out run's figures are places of the document
    assert in_json > len(result.model.drift.selected) * 2 + 20
    for note in summary.notes:  # the equations and what figures cannot say
        assert " ".join(note.split()) in " ".join(printed.split())
    assert "Eq. (18) form: f = " in printed and "B = " in printed


def test_the_prior_fit_is_a_figure(result):
    """A prior's temperature uncertainty (what ``hrgtc calibrate --prior`` printed) is one of
    the calibration's figures, read from the fit."""
    import dataclasses
    from types import SimpleNamespace

    fit = SimpleNamespace(prior=SimpleNamespace(n_units=7), max_temperature_std_c=0.0125)
    summary = dataclasses.replace(result, prior_fit=fit).summary()
    figure = summary["thermometer.prior.max_temperature_std_c"]
    assert (figure.value, figure.unit) == (0.0125, "°C")
    assert summary["thermometer.prior.n_units"].value == 7


def test_the_reports_calibration_tables_show_the_summarys_figures(result):
    """The report's thermometer, stepwise and drift-model tables (from the model file's
    unit, as ``hrgtc report`` reads it) hold every figure of those sections."""
    from report_pages import one_axis_page

    page = one_axis_page(result.model)
    cells = {}
    for caption, body in re.findall(r"<caption>(.*?)</caption>(.*?)</table>", page):
        for row in re.findall(r"<tr>(.*?)</tr>", body):
            found = [unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)]
            if len(found) == 4:
                cells[(unescape(caption).split(" (")[0].split(":")[0], found[0])] = found[1:]
    summary = result.summary()
    captions = {"thermometer (Eq. 18)": "Thermometer", "stepwise steps": "Stepwise steps",
                "drift model (Eq. 22)": "The final model"}
    shown = 0
    for heading, caption in captions.items():
        for figure in dict(summary.sections)[heading]:
            row = cells[(caption, figure.label)]
            assert _agrees(figure, row[0]), (figure, row)
            assert row[1:] == [figure.unit, figure.interval_text()], (figure, row)
            shown += 1
    assert shown > 20



def test_the_training_sample_count_says_it_is_what_was_read(result):
    """The table's "training samples" was the samples read (181439 on a 3-day fridge
    run) right above the accounting's "181140 used": named "read", it is the accounting's
    first figure."""
    summary = result.summary(warnings=False)
    (figure,) = [f for _, figures in summary.sections for f in figures
                 if f.name == "drift.n_samples"]
    assert figure.label == "training samples read"
    assert figure.value == result.model.drift.accounting.read
