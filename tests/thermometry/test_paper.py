"""Reference tests: the paper's published numbers ([1] = Wang et al., Sensors 2012)."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.thermometry import paper


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
