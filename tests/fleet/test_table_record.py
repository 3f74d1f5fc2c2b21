"""The fleet table from its record: the same Arrow schema and rows as before the record.

Truth: ``tests/data/fleet-table/table.json``, written by the commit before the record
(``make.py`` beside it, from the hand-written pyarrow ``SCHEMA``) for the outcomes of
``tests/fleet_outcomes.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import msgspec
import pyarrow as pa
import pytest

from fleet_outcomes import OUTCOMES
from hrgtc.core.errors import InputError
from hrgtc.fleet.results import (
    SCHEMA,
    FleetRowRecord,
    read_table,
    row_json_schema,
    table,
    write_table,
)
from hrgtc.fleet.tasks import UnitOutcome

TRUTH = json.loads((Path(__file__).parents[1] / "data" / "fleet-table" / "table.json")
                   .read_text(encoding="utf-8"))


def test_the_table_has_the_same_schema_and_rows_as_before():
    written = table(OUTCOMES)
    assert written.schema.to_string() == TRUTH["schema"]
    assert SCHEMA.to_string() == TRUTH["schema"]
    assert written.to_pylist() == TRUTH["rows"]


def test_the_table_round_trips_through_parquet(tmp_path):
    path = write_table(OUTCOMES, tmp_path / "fleet.parquet")
    assert read_table(path) == TRUTH["rows"]


def test_every_row_fits_the_records_json_schema():
    validator = jsonschema.Draft202012Validator(row_json_schema())
    for row in TRUTH["rows"]:
        validator.validate(row)
    assert list(row_json_schema()["properties"]) == SCHEMA.names


def test_a_row_that_does_not_fit_names_the_unit_and_the_column():
    bad = UnitOutcome(unit="u-009", status="ok", seconds=1.0,
                      row={"n_soaks": -1, "runs": ["a.parquet"]})
    with pytest.raises(InputError, match=r"unit 'u-009'.*`\$.n_soaks`"):
        table([bad])
    bad = UnitOutcome(unit="u-010", status="ok", seconds=1.0, row={"raw_10s_dph": ["x"]})
    with pytest.raises(InputError, match=r"unit 'u-010'.*`\$.raw_10s_dph\[0\]`"):
        table([bad])


def test_the_arrow_schema_is_the_records_fields():
    assert SCHEMA.names == [f.name for f in msgspec.structs.fields(FleetRowRecord)]
    assert all(field.nullable for field in SCHEMA)
    assert SCHEMA.field("error_row").type == pa.int64()
    assert SCHEMA.field("compensated_10s_dph").type == pa.list_(pa.float64())
