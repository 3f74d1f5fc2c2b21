"""Tests of hrgtc.evaluation.run_figures: one run's figures, the same in every renderer.

The plain text (``Evaluation.summary()``), the CLI's rich tables (``hrgtc evaluate``), the
HTML report's run section and the ``--json`` document (``Evaluation.to_dict()``) are parsed
back and must give every figure of the run's :class:`~hrgtc.core.summary.Summary` with the
same value, so the renderers cannot drift apart.
"""

from __future__ import annotations

import io
import math
import re
from html.parser import HTMLParser

import pytest
from rich.console import Console

import hrgtc.cli.compensate_cmd as compensate_cmd
from hrgtc.core.summary import Figure
from hrgtc.evaluation import evaluate
from hrgtc.pipeline.calibration import calibrate


@pytest.fixture(scope="module")
def run(paper_campaign):
    files = paper_campaign
    model = calibrate(files.soaks, [files.cooldown]).model
    return evaluate(model, files.warmup, max_points=300).axis, model


def _agrees(figure: Figure, cell: str) -> bool:
    """``cell`` (a renderer's value, possibly followed by unit and interval) shows
    ``figure``'s value."""
    if isinstance(figure.value, str):
        return cell.startswith(figure.value)
    token = cell.split()[0] if cell.split() else ""
    if isinstance(figure.value, float) and math.isnan(figure.value):
        return token == "-"
    return float(token) == pytest.approx(float(figure.value), rel=10.0 ** (1 - figure.digits))


def _json_value(document: dict, name: str):
    """The value at a figure's name (``bias_stability_dph.raw.10``, ``ranges.variables[0]
    .fraction``) in the ``--json`` document; a τ of ``0.5`` is one key."""
    node, pending = document, ""
    for token in name.removeprefix("evaluation.").split("."):
        pending = f"{pending}.{token}" if pending else token
        key, index = re.match(r"([^\[]+)((?:\[\d+\])*)$", pending).groups()
        if key not in node:  # the first part of a key with a dot (τ = 0.5)
            continue
        node, pending = node[key], ""
        for k in re.findall(r"\d+", index):
            node = node[int(k)]
    assert not pending, name
    return node


class _Tables(HTMLParser):
    def __init__(self, text: str) -> None:
        super().__init__()
        self.rows: list[list[str]] = []
        self._cell: list[str] | None = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        if tag == "tr":
            self.rows.append([])
        elif tag == "td":
            self._cell = []

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self.rows[-1].append("".join(self._cell).strip())
            self._cell = None


def test_text_rich_html_and_json_show_the_same_figures(run, monkeypatch):
    from report_pages import one_axis_page

    result, model = run
    summary = result.figures(warnings=False)
    figures = list(summary.figures().values())
    labels = [f.label for f in figures]
    assert len(set(labels)) == len(labels)  # a label names one figure in a table
    # the run has every kind of section the renderers must carry
    names = set(summary.figures())
    for part in ("bias_stability_dph.raw.10", "allan.compensated.arw_deg_per_rt_h",
                 "ranges.temperature_fraction", "heating_cooling.heating.compensated_dph",
                 "accounting.read", "prediction_std_dph.median", "mean_dph.compensated"):
        assert f"evaluation.{part}" in names

    text = [line.strip() for line in result.summary().text().splitlines()]
    out = io.StringIO()
    monkeypatch.setattr(compensate_cmd, "console", Console(file=out, width=400))
    compensate_cmd.render_evaluation(result)
    rich = {cells[0]: cells[1:] for line in out.getvalue().splitlines()
            if len(cells := [c.strip() for c in line.split("│")[1:-1]]) == 4}
    page = one_axis_page(model, [result])
    (section,) = re.findall(r'<section id="run-1">(.*?)</section>', page, flags=re.S)
    html = {row[0]: row[1:] for row in _Tables(section).rows if len(row) == 4}
    # heating and cooling apart: the report's own table, a row per direction with a block
    split = {row[0]: row[1:] for row in _Tables(section).rows
             if row and row[0] in ("heating", "cooling")}
    columns = {"10 s blocks": 0, "bias stability raw": 1, "bias stability compensated": 2,
               "improvement": 3, "RMS model - true bias": 4}
    document = result.to_dict()

    for figure in figures:
        line = next(v for v in text if v.startswith(f"{figure.label}: "))
        assert _agrees(figure, line.removeprefix(f"{figure.label}: ")), (figure, line)
        assert _agrees(figure, rich[figure.label][0]), (figure, rich[figure.label])
        if ".heating_cooling." in figure.name:
            direction, _, what = figure.label.partition(": ")
            if direction in split:
                assert _agrees(figure, split[direction][columns[what]]), (figure, split)
            else:  # no block: a sentence instead of a row
                assert figure.value == 0 or math.isnan(figure.value), figure
                assert f"No {direction} block" in section
        else:
            assert _agrees(figure, html[figure.label][0]), (figure, html[figure.label])
            assert html[figure.label][1:] == [figure.unit, figure.interval_text()]
        assert rich[figure.label][1:] == [figure.unit, figure.interval_text()]
        if figure.interval is not None:  # the interval in the text too
            assert figure.interval_text() in line
        value = _json_value(document, figure.name)
        if isinstance(figure.value, str):
            assert value is None  # a noise term that could not be read: its reason instead
        elif value is None:
            assert math.isnan(figure.value)
        else:
            assert value == pytest.approx(figure.value, rel=1e-12)
    assert set(rich) >= set(labels) and set(split) == {"heating"}  # the warm-up heats
    assert set(html) >= {f.label for f in figures if ".heating_cooling." not in f.name}


def test_bias_stability_figures_carry_the_block_count(run):
    result, _ = run
    figure = result.figures()["evaluation.bias_stability_dph.compensated.10"]
    n = result.bias_stability_blocks["compensated"][10.0]
    assert figure.interval == result.stability_interval("compensated", 10.0)
    assert figure.interval_kind.endswith(f"N {n}") and n > 100


def test_the_evaluations_parts_round_trip_through_their_records(run):
    """NoiseTerms, AllanResult, RangeReport and Accounting: to_dict -> JSON -> from_dict
    gives the same document, and a bad value is refused naming its place."""
    import json

    from hrgtc.core.errors import InputError
    from hrgtc.evaluation.allan import AllanResult

    result, _ = run
    parts = [*result.noise.values(), *result.allan.values(), result.ranges, result.accounting]
    for part in parts:
        document = json.loads(json.dumps(part.to_dict(), allow_nan=False))
        assert type(part).from_dict(document).to_dict() == document
    bad = result.allan["raw"].to_dict() | {"n_samples": -1}
    with pytest.raises(InputError, match=r"n_samples"):
        AllanResult.from_dict(bad)
