"""The decision rule of spec.toml (ILAC-G8 guard bands) on a golden set of values.

``tests/data/testreport/decision-golden.csv`` holds values, expanded uncertainties and
limits, values exactly at a limit included, with the verdict a spreadsheet gives
(``=IF(value+U_plus<=max, "accept", IF(value-U_minus>max, "reject", "indeterminate"))`` for
an upper limit, the mirror for a lower one). The test computes each verdict again from
the CSV's text in exact rational arithmetic, independently of ``decide``, and holds both
to the CSV's column.
"""

from __future__ import annotations

import csv
from fractions import Fraction
from pathlib import Path

import pytest

from hrgtc.core.errors import InputError
from hrgtc.testreport.figures import FIGURES
from hrgtc.testreport.spec import Limit, decide, load_spec

GOLDEN = Path(__file__).parents[1] / "data" / "testreport" / "decision-golden.csv"


def _rows() -> list[dict[str, str]]:
    with GOLDEN.open(encoding="utf-8") as stream:
        return list(csv.DictReader(stream))


def _exact(row: dict[str, str]) -> str:
    """The verdict from the CSV's decimal text, in fractions (no binary rounding)."""
    if not row["value"]:
        return "not measured"
    if not row["min"] and not row["max"]:
        return "no limit"
    if not row["U_minus"]:
        return "indeterminate"
    v, lo, hi = (Fraction(row[k]) for k in ("value", "U_minus", "U_plus"))
    verdicts = []
    if row["max"]:
        top = Fraction(row["max"])
        verdicts.append("accept" if v + hi <= top else "reject" if v - lo > top
                        else "indeterminate")
    if row["min"]:
        bottom = Fraction(row["min"])
        verdicts.append("accept" if v - lo >= bottom else "reject" if v + hi < bottom
                        else "indeterminate")
    if "reject" in verdicts:
        return "reject"
    return "accept" if set(verdicts) == {"accept"} else "indeterminate"


@pytest.mark.parametrize("row", _rows(), ids=lambda row: row["case"])
def test_golden_verdicts(row):
    value = float(row["value"]) if row["value"] else None
    expanded = ((float(row["U_minus"]), float(row["U_plus"])) if row["U_minus"] else None)
    limit = (None if not (row["min"] or row["max"]) else
             Limit(float(row["min"]) if row["min"] else None,
                   float(row["max"]) if row["max"] else None))
    assert _exact(row) == row["expected"]
    assert decide(value, expanded, limit) == row["expected"]


def test_the_golden_set_holds_every_verdict_and_cases_at_the_limit():
    rows = _rows()
    assert {r["expected"] for r in rows} == {"accept", "reject", "indeterminate",
                                            "not measured", "no limit"}
    at_limit = [r for r in rows if "at the" in r["case"]]
    assert len(at_limit) >= 5


def test_spec_file_limits(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text("[limits.bias_repeatability_dph]\nmax = 0.5\n"
                    "[limits.bias_temperature_sensitivity_dph_per_c]\nmin = -0.2\nmax = 0.2\n",
                    encoding="utf-8")
    limits = load_spec(spec, tuple(FIGURES))
    assert limits == {"bias_repeatability_dph": Limit(None, 0.5),
                      "bias_temperature_sensitivity_dph_per_c": Limit(-0.2, 0.2)}


@pytest.mark.parametrize(("text", "message"), [
    ("[limits.bias_stability]\nmax = 1\n", "no such figure"),
    ("[limits.bias_dph]\nmax = \"1\"\n", "must be a finite number"),
    ("[limits.bias_dph]\nlimit = 1\n", "takes min and/or max"),
    ("[limits.bias_dph]\nmin = 2\nmax = 1\n", "min 2 > max 1"),
    ("title = 'x'\n", r"no \[limits"),
    ("[limits\n", "not a TOML spec"),
])
def test_spec_errors_name_the_figure_and_the_fix(tmp_path, text, message):
    spec = tmp_path / "spec.toml"
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=message):
        load_spec(spec, tuple(FIGURES))
