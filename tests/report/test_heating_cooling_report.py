"""The report's "heating and cooling apart" table (issue 29, item 3): a row per direction of
each run with its blocks, raw and compensated 10 s bias stability, improvement and (a
simulated run) the RMS of model minus true bias; a sentence for a direction without a block."""

from __future__ import annotations

import html
import json
import math
import re
import shutil
import subprocess

import pytest

from hrgtc.evaluation import evaluate
from hrgtc.evaluation.heating_cooling import DirectionStats
from hrgtc.pipeline.calibration import calibrate
from hrgtc.report import build_report
from hrgtc.report.inputs import report_inputs
from hrgtc.report.kinds import KINDS
from hrgtc.report.paper import heating_cooling
from hrgtc.report.render import render


@pytest.fixture(scope="module")
def unit(paper_campaign):
    result = calibrate(paper_campaign.soaks, [paper_campaign.cooldown], [paper_campaign.warmup])
    return paper_campaign, result.model


@pytest.fixture(scope="module")
def report(unit):
    """The report's data and page of the paper unit's cool-down and warm-up (simulated)."""
    files, model = unit
    data = KINDS["paper"].data(report_inputs(model, [files.cooldown, files.warmup]))
    return data, render(KINDS["paper"].template, report=data)


def _close(a: float | None, b: float | None) -> bool:
    """Equal to 1e-9, NaN (or None) equal to NaN (or None)."""
    if a is None or b is None:
        return a is None and b is None
    return (math.isnan(a) and math.isnan(b)) or a == pytest.approx(b, rel=1e-9)


def test_the_report_s_data_holds_the_evaluation_s_split(unit, report):
    """Two paths: the report's own evaluation (with plotting blocks) against ``hrgtc
    evaluate``'s JSON record of each run, direction by direction; a direction without a
    block is a sentence, not a row."""
    files, model = unit
    data, _ = report
    runs = data.axes[0].runs
    assert [r.run.name for r in runs] == [files.cooldown.name, files.warmup.name]
    shown = set()
    for section, path in zip(runs, (files.cooldown, files.warmup), strict=True):
        record = json.loads(json.dumps(evaluate(model, path).axis.to_dict()))["heating_cooling"]
        table = section.heating_cooling
        assert table is not None and table.truth  # simulated: the true bias is known
        assert table.block_s == record["block_s"] == 10.0
        rows = {row.direction: row for row in table.rows}
        for d in ("heating", "cooling"):
            expected = record[d]
            if not expected["blocks"]:
                assert d not in rows
                assert any(note.startswith(f"No {d} block") for note in table.notes)
                continue
            row = rows[d]
            shown.add(d)
            assert row.blocks == expected["blocks"] > 2
            for field in ("raw_dph", "compensated_dph", "improvement", "residual_rms_dph"):
                assert _close(getattr(row, field), expected[field]), (path.name, d, field)
            assert row.raw_dph > row.compensated_dph > 0  # the model helps either way
    assert shown == {"heating", "cooling"}  # the cool-down cools, the warm-up heats


def test_the_page_shows_each_row_as_the_data_has_it(report):
    """The template's cells are the data's numbers to 4 significant digits (3 for the
    improvement); the generic figure list of the split is gone (one table, not two)."""
    data, page = report
    for section in data.axes[0].runs:
        table = section.heating_cooling
        assert page.count(f"<caption>{table.caption}</caption>") == 1
        for row in table.rows:
            cells = [row.direction, str(row.blocks), f"{row.raw_dph:.4g}",
                     f"{row.compensated_dph:.4g}", f"{row.improvement:.3g}",
                     f"{row.residual_rms_dph:.4g}"]
            assert re.search(r"<tr><td>" + r"</td><td[^>]*>".join(map(re.escape, cells))
                             + r"</td></tr>", page), cells
        for note in table.notes:
            assert f'<p class="note">{note}</p>' in html.unescape(page)
    assert "heating: bias stability raw" not in page


def test_no_block_says_why():
    """A run with no block in either direction says why; one with only one direction has
    one row and a sentence for the other; a temperature sensor's words have no resonator;
    a recorded run (no true bias) has no residual column."""
    nan = math.nan
    empty = DirectionStats(10.0, {"heating": 0, "cooling": 0}, {"heating": nan, "cooling": nan},
                           {"heating": nan, "cooling": nan}, reason="the run is shorter than "
                           "its warm-up")
    table = heating_cooling(empty, "r.csv", sensor=True)
    assert table.rows == () and table.notes == (
        "Heating and cooling apart: no 10 s block (the run is shorter than its warm-up).",)
    one = DirectionStats(10.0, {"heating": 0, "cooling": 40}, {"heating": nan, "cooling": 2.0},
                         {"heating": nan, "cooling": 0.5})
    for sensor in (True, False):
        table = heating_cooling(one, "r.csv", sensor=sensor)
        assert [r.direction for r in table.rows] == ["cooling"] and not table.truth
        assert table.rows[0].improvement == 4.0 and table.rows[0].residual_rms_dph is None
        assert table.notes == ("No heating block: the run's 40 blocks of 10 s outside the dead "
                               f"band of the {'' if sensor else 'resonator '}temperature rate "
                               "were all cooling.",)
        assert ("resonator" in table.caption) is not sensor


def test_a_run_named_with_markup_shows_as_text(unit, tmp_path):
    files, model = unit
    evil = "<i>hot<i>&<script>"
    run = tmp_path / f"{evil}.parquet"
    run.write_bytes(files.warmup.read_bytes())
    output = build_report(model.with_parts(plateaus=()), [run], tmp_path / "report.html",
                          soaks=[])
    text = output.read_text(encoding="utf-8")
    assert "<i>hot" not in text and "<script" not in text
    assert ("<caption>Heating and cooling apart of &lt;i&gt;hot&lt;i&gt;&amp;&lt;script&gt;"
            ".parquet: 10 s bias stability") in text


_PROBE = """<script>
window.addEventListener("load", () => {
  const found = Array.from(document.querySelectorAll("table")).filter(
    (t) => t.caption && t.caption.textContent.startsWith("Heating and cooling apart"));
  const marker = document.createElement("pre");
  marker.id = "hrgtc-split";
  marker.textContent = JSON.stringify(found.map((t) => ({
    caption: t.caption.textContent,
    height: t.getBoundingClientRect().height,
    rows: Array.from(t.tBodies[0].rows).map((r) => Array.from(r.cells).map(
      (c) => c.textContent)),
  })));
  document.body.appendChild(marker);
});
</script>"""


def test_headless_chromium_shows_the_table(report, tmp_path):
    """A real browser lays out one table per run, with the data's rows (``make test``
    installs Debian's chromium)."""
    assert shutil.which("chromium"), "chromium is not installed: run 'make test' (it installs it)"
    data, page = report
    probe = tmp_path / "probe.html"
    probe.write_text(page.replace("</body>", _PROBE + "</body>"), encoding="utf-8")
    command = [
        shutil.which("chromium"), "--headless", "--no-sandbox", "--disable-gpu",
        "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", f"--user-data-dir={tmp_path / 'ud'}",
        "--virtual-time-budget=10000", "--dump-dom", probe.as_uri(),
    ]
    dom = subprocess.run(command, capture_output=True, text=True, timeout=120, check=True).stdout
    found = re.search(r'<pre id="hrgtc-split">(.*?)</pre>', dom, re.S)
    assert found, dom[-2000:]
    tables = json.loads(found.group(1).replace("&amp;", "&").replace("&lt;", "<")
                        .replace("&gt;", ">").replace("&quot;", '"'))
    runs = data.axes[0].runs
    assert [t["caption"] for t in tables] == [r.heating_cooling.caption for r in runs]
    for shown, section in zip(tables, runs, strict=True):
        assert shown["height"] > 0  # laid out, not hidden
        assert [row[0] for row in shown["rows"]] == [r.direction for r in
                                                     section.heating_cooling.rows]
        for cells, row in zip(shown["rows"], section.heating_cooling.rows, strict=True):
            assert float(cells[2]) == pytest.approx(row.raw_dph, rel=1e-3)
            assert float(cells[3]) == pytest.approx(row.compensated_dph, rel=1e-3)
            assert float(cells[5]) == pytest.approx(row.residual_rms_dph, rel=1e-3)
