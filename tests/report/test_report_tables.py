"""The report's provenance and soak-error tables as summaries (``hrgtc.report.tables``).

Each renders like every other table (``summary_checks``: plain text, rich, HTML and the
places of a JSON document give every figure the same value), holds what it claims (the state
of each input on disk, the error statistics of known errors) and is the table the report
shows.
"""

from __future__ import annotations

import io
import json
import re
from html import unescape

import numpy as np
import pytest
from rich.console import Console

from hrgtc.cli.summary_tables import print_summary
from hrgtc.core.files import file_sha256
from hrgtc.core.summary import Figure, Summary
from hrgtc.evaluation.calibration_figures import TABLE2
from hrgtc.report.figures import SoakTrace
from hrgtc.report.html import _header, _Page, _temperature
from hrgtc.report.tables import (
    CHANGED,
    INPUTS,
    MISSING,
    SOAK_ERROR,
    UNCHANGED,
    provenance_summary,
    soak_error_summary,
)
from summary_checks import check_renderings


def _rich(summary) -> str:
    out = io.StringIO()
    print_summary(summary, Console(file=out, width=400))
    return out.getvalue()


def _report_table(page: str, caption: str) -> tuple[list[str], list[list[str]]]:
    (table,) = re.findall(rf"<caption>{re.escape(caption)}</caption>(.*?)</table>", page,
                          flags=re.S)
    head = [unescape(h) for h in re.findall(r"<th>(.*?)</th>", table)]
    rows = [[unescape(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", row)]
            for row in re.findall(r"<tr>(.*?)</tr>", table.split("</thead>")[1])]
    return head, rows


@pytest.fixture
def provenance(tmp_path):
    same, changed = tmp_path / "soak_0C.csv", tmp_path / "cool.csv"
    same.write_text("t,f\n0,4424.9\n")
    changed.write_text("t,f\n0,1\n")
    inputs = [{"role": "soak", "path": str(same), "sha256": file_sha256(same)},
              {"role": "drift", "path": str(changed), "sha256": file_sha256(changed)},
              {"role": "validation", "path": str(tmp_path / "gone.csv"), "sha256": "0" * 64}]
    changed.write_text("t,f\n0,2\n")  # edited after the calibration
    return {"hrgtc_version": "test", "inputs": inputs}


def test_provenance_table(provenance):
    summary = provenance_summary(provenance)
    assert check_renderings(summary, _rich(summary), provenance) == 3 * 2  # role and path
    headers, rows = summary.grid(INPUTS)
    assert headers == ["role", "file", "SHA-256 (first 12)", "on disk now"]
    assert [r[3] for r in rows] == [UNCHANGED, CHANGED, MISSING]
    assert [r[2] for r in rows] == [i["sha256"][:12] for i in provenance["inputs"]]
    assert provenance_summary({"inputs": []}).sections == ()
    # the report's table is these cells
    page = _Page()
    model = type("M", (), {"provenance": provenance, "unit": "SN-1",
                          "thermometer": type("T", (), {"source": "frequency"})()})()
    _header(page, model, "t", None)
    assert _report_table("".join(page.parts), INPUTS) == (headers, rows)


def test_soak_error_table():
    time_s = np.arange(0.0, 4 * 3600.0 + 1, 600.0)  # 4 h in 10 min blocks
    error = np.where(time_s >= time_s[-1] - 3600.0, 0.002, 0.004)
    error[0] = -0.01
    truth = np.full(time_s.size, 20.0)
    trace = SoakTrace("s/soak_20C.csv", "soak_20C.csv", 600.0, time_s, 4432 + 0 * time_s,
                      truth + error, None, truth)
    untrue = SoakTrace("s/bench.csv", "bench.csv", 600.0, time_s, 4432 + 0 * time_s,
                       truth, None, None)
    summary = soak_error_summary([untrue, trace])
    headers, rows = summary.grid(SOAK_ERROR)
    assert headers == ["soak", "rms error [°C]", "max |error| [°C]",
                       "max |error|, last hour [°C]"]
    assert rows == [["soak_20C.csv", f"{np.sqrt(np.mean(error**2)):.3g}", "0.01", "0.002"]]
    figures = summary.figures()
    assert figures["soaks[0].max_abs_error_c"].value == pytest.approx(0.01, abs=1e-12)
    document = {"soaks": [{"rms_error_c": float(np.sqrt(np.mean(error**2)))}]}
    assert check_renderings(summary, _rich(summary), json.loads(json.dumps(document))) == 1
    assert soak_error_summary([untrue]).sections == ()
    # the report's table is these cells
    page = _Page()
    table2 = Summary("t", ((TABLE2, (Figure("e", "e", 0.1, row="0", column="error"),)),))
    _temperature(page, [], [trace], table2)
    assert _report_table("".join(page.parts), SOAK_ERROR) == (headers, rows)
