"""Tests of hrgtc.core.summary: figures with value, unit and interval, and their renderings."""

from __future__ import annotations

import json
import math

from hrgtc.core.summary import Figure, Summary


def test_a_value_with_its_standard_error():
    figure = Figure.with_error("drift.intercept_dph", "B0", 1.25, 0.05, "°/h")
    assert figure.interval == (1.2, 1.3)
    assert figure.interval_kind == "±1σ"
    assert figure.text() == "B0: 1.25 °/h ± 0.05"
    assert Figure.with_error("x", "x", 1.0, math.nan).interval is None


def test_an_interval_that_is_not_symmetric_is_written_as_bounds():
    figure = Figure("s", "bias stability", 0.957, "°/h", (0.93, 0.99), "68.3% CI", digits=3)
    assert figure.text() == "bias stability: 0.957 °/h [0.93, 0.99] (68.3% CI)"


def test_missing_values_are_null_in_json_and_a_dash_in_text():
    summary = Summary("t", (("a", (Figure("a.x", "x", math.nan, "Hz"), Figure("a.n", "n", 7))),))
    assert summary.text().splitlines() == ["t", "a:", "  x: -", "  n: 7"]
    data = json.loads(json.dumps(summary.to_dict(), allow_nan=False))
    assert data["sections"][0]["figures"][0]["value"] is None
    assert summary.rows() == [("a", "x", "-", "Hz", ""), ("a", "n", "7", "", "")]


def test_html_is_escaped():
    page = Summary("<unit>", (("s", (Figure("s.t", "terms", "f<df"),)),)).html()
    assert "&lt;unit&gt;" in page and "<td>f&lt;df</td>" in page


def test_a_table_cell_keeps_its_place_and_format_in_json():
    cell = Figure("table1[0].freq_hz", "plateau 1, natural frequency", 4416.97, "Hz",
                  spec=".2f", row="0", column="natural frequency")
    data = cell.to_dict()
    assert (data["spec"], data["row"], data["column"]) == (".2f", "0", "natural frequency")
    # a figure that is no cell keeps the keys it always had (the --json documents)
    assert set(Figure("a.n", "n", 7).to_dict()) == {"name", "label", "value", "unit",
                                                     "interval", "interval_kind"}
    # the JSON form gives the same cell back
    again = Figure(**{k: v for k, v in data.items() if k != "interval"})
    assert again == cell and again.number() == "4416.97"


def test_a_layout_renders_the_figures_and_survives_renaming():
    """A layout line is a format string over the figures' names (dots and brackets in a
    name included); renamed() moves the names and the layout's references together; str()
    is the text; a definition is in the JSON and the HTML title, only when set."""
    from hrgtc.core.summary import Figure, Summary, escape

    figures = (Figure("runs[0].rms_dph", "rms", 0.012345, "°/h",
                      definition="RMS of the residual."),
               Figure("name", "unit", "SN-{1}"))
    summary = Summary("t", (("s", figures),),
                      layout=(escape("{literal}") + " {name}: rms {runs[0].rms_dph:.3g} °/h",))
    assert summary.text() == "{literal} SN-{1}: rms 0.0123 °/h" == str(summary)
    inner = summary.renamed("axes.x.")
    assert inner.text() == summary.text()
    assert set(inner.figures()) == {"axes.x.runs[0].rms_dph", "axes.x.name"}
    assert Summary("u", inner.sections, layout=("> " + inner.lines()[0],)).text() == (
        "> {literal} SN-{1}: rms 0.0123 °/h")
    assert summary["runs[0].rms_dph"].to_dict()["definition"] == "RMS of the residual."
    assert "definition" not in summary["name"].to_dict()
    assert '<td title="RMS of the residual.">rms</td>' in summary.html()
    assert Summary("empty", layout=()).text() == ""
    assert Summary("plain", (("s", figures),)).lines() == (
        "plain", "s:", "  rms: 0.012345 °/h", "  unit: SN-{{1}}")
