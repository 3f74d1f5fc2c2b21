"""Reference tests: the paper's published numbers ([1] = Wang et al., Sensors 2012)."""

from __future__ import annotations

import io
import json

import numpy as np
from rich.console import Console
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.cli.summary_tables import print_summary
from hrgtc.evaluation.calibration_figures import paper_tables
from hrgtc.thermometry import paper
from summary_checks import check_renderings


def test_fitted_coefficients_rounded_equal_eq18():
    result = paper.reproduce()
    # Eq. (18) of [1]: 1.528e-5 T^3 - 9.702e-4 T^2 + 0.3716 T + 4424.901
    assert result.rounded_high_first == (1.528e-5, -9.702e-4, 0.3716, 4424.901)


def test_full_precision_coefficients_match_the_design_brief():
    # DESIGN.md: 1.52777778e-5, -9.70238095e-4, 0.371555556, 4424.90095
    np.testing.assert_allclose(
        paper.reproduce().coefficients_high_first,
        [1.52777778e-5, -9.70238095e-4, 0.371555556, 4424.90095],
        rtol=1e-8,
    )


def test_table2_temperatures_within_a_millidegree():
    computed = np.array(paper.reproduce().table2_computed_c)
    # Table 2 of [1]: -19.976, -10.058, -0.0026, 10.070, 20.011, 29.924, 40.031 °C
    published = np.array([-19.976, -10.058, -0.0026, 10.070, 20.011, 29.924, 40.031])
    assert np.max(np.abs(computed - published)) < 0.001
    # and the largest error against the actual temperatures stays below 0.1 °C, as printed
    assert np.max(np.abs(computed - paper.TABLE1_TEMPERATURE_C)) < 0.1


def test_paper_command_json():
    result = CliRunner().invoke(app, ["paper", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert len(data["eq18"]["coefficients_high_first"]) == 4
    expected = paper.reproduce().coefficients_high_first
    assert data["eq18"]["coefficients_high_first"] == list(expected)
    assert [row["published_c"] for row in data["table2"]] == list(paper.TABLE2_CALCULATED_C)
    for row in data["table2"]:
        assert set(row) == {"frequency_hz", "actual_c", "published_c", "computed_c"}
        assert abs(row["computed_c"] - row["published_c"]) < 0.001


def test_paper_command_tables():
    result = CliRunner().invoke(app, ["paper"])
    assert result.exit_code == 0, result.output
    assert "4424.901" in result.stdout and "-10.058" in result.stdout


def _printed_tables() -> str:
    out = io.StringIO()
    print_summary(paper_tables(paper.reproduce()), Console(file=out, width=400))
    return out.getvalue()


def test_paper_tables_agree_in_text_rich_html_and_json():
    """``hrgtc paper`` prints a Summary: its text, rich tables and HTML give each figure the
    same value, and each figure with a place in ``hrgtc paper --json`` has its value there."""
    result = paper.reproduce()
    document = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    places = check_renderings(paper_tables(result), _printed_tables(), document)
    assert places == 7 * 4 + 4 * 3  # Table 2's four columns, Eq. (18) three times


def test_paper_tables_show_the_printed_digits():
    tables = paper_tables(paper.reproduce())
    (table1, eq18, table2, stability) = (h for h, _ in tables.sections)
    # Table 1 of [1]: temperatures and frequencies as printed
    assert [r[:2] for r in tables.grid(table1)[1]] == [
        ["-20", "4416.97"], ["-10", "4421.05"], ["0", "4424.90"], ["10", "4428.56"],
        ["20", "4432.07"], ["30", "4435.56"], ["40", "4439.20"]]
    # Table 2 of [1]: the calculated temperatures as printed (10.070, -0.0026)
    headers, rows = tables.grid(table2)
    published = [r[headers.index("Table 2 of [1] [°C]")] for r in rows]
    assert published == ["-19.976", "-10.058", "-0.0026", "10.070", "20.011", "29.924",
                         "40.031"]
    assert all(abs(float(r[headers.index("hrgtc − [1] [°C]")])) < 0.001 for r in rows)
    # Eq. (18) of [1], and the refit rounded to its printed digits, equal to the digit
    headers, rows = tables.grid(eq18)
    expected = ["1.528e-05", "-0.0009702", "0.3716", "4424.901"]
    assert [r[headers.index("Eq. 18 of [1]")] for r in rows] == expected
    assert [r[headers.index("fitted, printed digits")] for r in rows] == expected
    # Section 4.2 of [1]: 3.0143 -> 0.5848 °/h
    assert [row[2] for row in tables.rows() if row[0] == stability] == ["3.0143", "0.5848"]
    printed = _printed_tables()
    assert all(text in printed for text in ("4424.901", "-0.0026", "10.070", "3.0143",
                                            "0.5848"))
