"""Tables as summaries: the unit's Table 1/2, plateaus and Eq. 18 beside the paper's
(``AxisCalibration.tables()``), the runs at a glance (``evaluation.glance_figures``) and
the report's tables made from them.

Each is a :class:`~hrgtc.core.summary.Summary` of table cells (``Summary.grid``); its plain
text, the rich tables ``hrgtc calibrate`` prints, its HTML and the ``--json`` document are
parsed back and must give every figure the same value (``summary_checks``), and the
report's tables must be the same cells.
"""

from __future__ import annotations

import io
import json
import re
from html import unescape

import numpy as np
import pytest
from rich.console import Console

import hrgtc.cli.calibrate_cmd as calibrate_cmd
from hrgtc.cli.summary_tables import print_summary
from hrgtc.evaluation.calibration_figures import EQ18, PLATEAUS, TABLE1, TABLE2
from hrgtc.evaluation.glance_figures import GLANCE, glance_summary
from hrgtc.pipeline.calibration import calibrate
from hrgtc.thermometry import paper
from summary_checks import check_renderings


@pytest.fixture(scope="module")
def result(paper_campaign):
    files = paper_campaign
    return calibrate(files.soaks, [files.cooldown], [files.warmup]).axis


def _printed(result, monkeypatch) -> str:
    out = io.StringIO()
    monkeypatch.setattr(calibrate_cmd, "console", Console(file=out, width=400))
    calibrate_cmd.render(result)
    return out.getvalue()


def test_tables_agree_in_text_rich_html_and_json(result, monkeypatch):
    tables = result.tables()
    assert [h for h, _ in tables.sections] == [TABLE1, TABLE2, PLATEAUS, EQ18]
    document = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    places = check_renderings(tables, _printed(result, monkeypatch), document)
    n = len(result.plateaus)
    assert places == 4 * n + result.model.thermometer.order + 1  # Table 2 and coefficients


def test_tables_hold_the_fit(result):
    """Table 1's residuals are the fit's, Table 2 is the inverse of Eq. 18 (what
    ``result.table`` holds), Eq. 18 of [1] is shown to the digit it is printed with."""
    tables = result.tables()
    th = result.model.thermometer
    figures = tables.figures()
    for k, row in enumerate(result.table):
        residual = figures[f"table1[{k}].residual_mhz"].value
        assert residual == pytest.approx(1e3 * (row["freq_hz"] - th.frequency(row["chamber_c"])),
                                         abs=1e-9)
        assert figures[f"thermometer.table[{k}].error_c"].value == pytest.approx(
            row["temperature_from_freq_c"] - row["chamber_c"], abs=1e-12)
    headers, rows = tables.grid(EQ18)
    assert headers == ["coefficient", "term", "this unit", "Eq. 18 of [1]"]
    assert [r[3] for r in rows] == [f"{c:.7g}" for c in paper.EQ18_PRINTED_HIGH_FIRST]
    assert [r[3] for r in rows] == ["1.528e-05", "-0.0009702", "0.3716", "4424.901"]
    assert [r[:2] for r in rows] == [["c3", "T³"], ["c2", "T²"], ["c1", "T"], ["c0", "const"]]
    # the printed decimals: 5 for a frequency, 3 for a chamber temperature, a signed error
    headers, rows = tables.grid(TABLE2)
    assert headers == ["frequency [Hz]", "chamber temperature [°C]",
                       "temperature from frequency [°C]", "error [°C]"]
    assert all(re.fullmatch(r"\d+\.\d{5}", r[0]) and re.fullmatch(r"[+-]\d\.\d{4}", r[3])
               for r in rows)


def test_a_sensor_thermometer_has_no_tables(result, monkeypatch):
    import dataclasses

    sensor = dataclasses.replace(result.model.thermometer, source="sensor")
    tables = dataclasses.replace(result, model=result.model.with_parts(
        thermometer=sensor)).tables()
    assert tables.sections == () and "no Table 1" in tables.text()


def test_glance_agrees_in_every_rendering(result):
    runs = result.validation
    summary = glance_summary(runs)
    out = io.StringIO()
    print_summary(summary, Console(file=out, width=400))
    document = {"runs": [json.loads(json.dumps(r.to_dict(), allow_nan=False)) for r in runs]}
    assert check_renderings(summary, out.getvalue(), document) >= 4 * len(runs)
    _, rows = summary.grid(GLANCE)
    assert rows[-1][:4] == ["paper [1], Section 4.2 (its cool-down)", "3.0143", "0.5848",
                            f"{3.0143 / 0.5848:.3g}"]
    assert float(rows[0][1]) == pytest.approx(runs[0].stability("raw", 10.0), rel=1e-3)


def test_the_reports_tables_are_the_summarys_cells(result):
    """The report's plateau, Table 1, Table 2 and coefficient tables show the cells of
    ``thermometer_tables`` (a missing number as "–")."""
    from report_pages import one_axis_page

    tables = result.tables()
    page = one_axis_page(result.model)
    shown = {}
    for caption, body in re.findall(r"<caption>(.*?)</caption>(.*?)</table>",
                                    page):
        head = [unescape(h) for h in re.findall(r"<th>(.*?)</th>", body)]
        rows = [[unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)]
                for row in re.findall(r"<tr>(.*?)</tr>", body)]
        shown[unescape(caption)] = (head, [r for r in rows if r])
    for heading, caption in ((PLATEAUS, "Plateaus of the unit (from the model file)"),
                             (TABLE1, "The unit's Table 1"), (TABLE2, "The unit's Table 2"),
                             (EQ18, "Coefficients beside the paper's, highest power first")):
        headers, rows = tables.grid(heading)
        assert shown[caption] == (headers, [["–" if c == "-" else c for c in r] for r in rows])
    assert np.isfinite([f.value for f in dict(tables.sections)[TABLE1]]).all()
