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
from hrgtc.report.figures import SoakTrace
from hrgtc.report.render import macros
from hrgtc.report.tables import (
    CHANGED,
    INPUTS,
    MISSING,
    SOAK_ERROR,
    UNCHANGED,
    grid_table,
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


def _unit_model():
    """A resonator's unit model (a golden model file, with its plateaus)."""
    from pathlib import Path

    from hrgtc.model import load_model

    return load_model(Path(__file__).parents[1] / "data" / "golden-models" / "v2"
                      / "unit-resonator-254ab6c.json")


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
    # the report's table is these cells (the paper report's header shows grid_table's)
    page = str(macros().table(grid_table(summary, INPUTS, INPUTS)))
    assert _report_table(page, INPUTS) == (headers, rows)


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
    # the report's table is these cells, in the page of a unit with this soak
    from report_pages import one_axis_page

    page = one_axis_page(_unit_model(), traces=[trace])
    assert _report_table(page, SOAK_ERROR) == (headers, rows)
