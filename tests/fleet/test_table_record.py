"""The fleet's files from their records: the same table and truth text as before them.

Truth: ``tests/data/fleet-table/table.json``, written by the commit before the record
(``make.py`` beside it, from the hand-written pyarrow ``SCHEMA``) for the outcomes of
``tests/fleet_outcomes.py``; ``tests/data/fleet-truth/unit-K.json``, a population unit's
``truth.json`` as written before :class:`FleetTruthRecord` (``make.py`` beside them).
Since the long form (a row per unit × axis) the table has one more column, ``axis``,
second: the rows are those of the truth with it.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import jsonschema
import msgspec
import pyarrow as pa
import pytest

from fleet_outcomes import OUTCOMES
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.fleet.population import FleetTruthRecord, draw_unit, true_frequency_hz, truth
from hrgtc.fleet.results import (
    SCHEMA,
    FleetRowRecord,
    read_table,
    row_json_schema,
    table,
    write_table,
)
from hrgtc.fleet.tasks import UnitOutcome
from hrgtc.simulate.units import Unit

DATA = Path(__file__).parents[1] / "data"
TRUTH = json.loads((DATA / "fleet-table" / "table.json").read_text(encoding="utf-8"))


def _with_axis(row: dict, axis: str | None) -> dict:
    """A row of the truth with the long form's ``axis`` column, second."""
    unit, *rest = row.items()
    return dict([unit, ("axis", axis), *rest])


#: The truth's rows in the long form: outcomes without axes, one row each (axis None).
ROWS = [_with_axis(row, None) for row in TRUTH["rows"]]


def test_the_table_has_the_same_schema_and_rows_as_before_and_the_axis_column():
    written = table(OUTCOMES)
    assert SCHEMA.names.index("axis") == 1 and SCHEMA.field("axis").type == pa.string()
    without = SCHEMA.remove(SCHEMA.get_field_index("axis"))
    assert without.to_string() == TRUTH["schema"]
    assert written.schema.equals(SCHEMA)
    assert written.to_pylist() == ROWS


def test_an_outcome_of_axes_gives_a_row_per_axis_with_the_units_columns():
    ok = next(o for o in OUTCOMES if o.status == "ok")
    unit = {k: v for k, v in ok.row.items() if k in ("unit", "model_file")}
    figures = {k: v for k, v in ok.row.items() if k not in unit}
    single = dataclasses.replace(ok, row=unit, axes=({"axis": "", **figures},))
    (row,) = table([single]).to_pylist()
    assert row == {**next(r for r in ROWS if r["unit"] == ok.unit), "axis": ""}
    three = dataclasses.replace(ok, row=unit, axes=tuple(
        {"axis": axis, **figures, "f20_hz": 4431.0 + k} for k, axis in enumerate("xyz")))
    rows = table([*OUTCOMES, three]).to_pylist()
    assert [(r["unit"], r["axis"]) for r in rows] == [
        ("u-001", None), ("u-001", "x"), ("u-001", "y"), ("u-001", "z"), ("u-002", None),
        ("u-003", None)]
    assert [r["f20_hz"] for r in rows[1:4]] == [4431.0, 4432.0, 4433.0]
    assert all(r["model_file"] == "models/u-001.json" and r["seconds"] == 12.25
               for r in rows[1:4])
    assert UnitOutcome.from_dict(json.loads(json.dumps(three.to_dict()))) == three


def test_the_table_round_trips_through_parquet(tmp_path):
    path = write_table(OUTCOMES, tmp_path / "fleet.parquet")
    assert read_table(path) == ROWS


def test_every_row_fits_the_records_json_schema():
    validator = jsonschema.Draft202012Validator(row_json_schema())
    for row in ROWS:
        validator.validate(row)
        validator.validate({**row, "axis": "x"})
    assert list(row_json_schema()["properties"]) == SCHEMA.names


def test_a_row_that_does_not_fit_names_the_unit_and_the_column():
    bad = UnitOutcome(unit="u-009", status="ok", seconds=1.0,
                      row={"n_soaks": -1, "runs": ["a.parquet"]})
    with pytest.raises(InputError, match=r"unit 'u-009'.*`\$.n_soaks`"):
        table([bad])
    bad = UnitOutcome(unit="u-010", status="ok", seconds=1.0, row={"raw_10s_dph": ["x"]})
    with pytest.raises(InputError, match=r"unit 'u-010'.*`\$.raw_10s_dph\[0\]`"):
        table([bad])
    bad = UnitOutcome(unit="u-011", status="ok", seconds=1.0,
                      axes=({"axis": "x"}, {"axis": "y", "n_terms": -2}))
    with pytest.raises(InputError, match=r"unit 'u-011', axis 'y'.*`\$.n_terms`"):
        table([bad])


def test_the_arrow_schema_is_the_records_fields():
    assert SCHEMA.names == [f.name for f in msgspec.structs.fields(FleetRowRecord)]
    assert all(field.nullable for field in SCHEMA)
    assert SCHEMA.field("error_row").type == pa.int64()
    assert SCHEMA.field("compensated_10s_dph").type == pa.list_(pa.float64())


@pytest.mark.parametrize("k", range(3))
def test_a_population_units_truth_is_the_same_text_and_fits_its_schema(k):
    document = truth(*draw_unit(7, k))
    expected = (DATA / "fleet-truth" / f"unit-{k}.json").read_text(encoding="utf-8")
    assert json.dumps(document, indent=1) + "\n" == expected
    written = json.loads(expected)
    assert records.dump(None, FleetTruthRecord, **written) == written  # round trip
    schema = records.json_schema(FleetTruthRecord, "t", "https://hrgtc.invalid/t.json")
    jsonschema.Draft202012Validator(schema).validate(written)
    assert Unit.from_dict(written["unit"]).to_dict() == written["unit"]


def test_a_truth_that_does_not_fit_names_the_place():
    written = truth(*draw_unit(7, 0))
    bad = {**written, "draw": {**written["draw"], "f20_hz": -1.0}}
    with pytest.raises(InputError, match=r"fleet truth record: .* - at `\$.draw.f20_hz`"):
        true_frequency_hz(bad, 20.0)
    with pytest.raises(InputError, match=r"`\$.schema`"):
        true_frequency_hz({**written, "schema": "other"}, 20.0)
