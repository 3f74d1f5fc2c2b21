"""The fleet table from its record: the same Arrow schema and rows as before the record.

Truth: ``tests/data/fleet-table/table.json``, written by the commit before the record
(``make.py`` beside it, from the hand-written pyarrow ``SCHEMA``) for the outcomes of
``tests/fleet_outcomes.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

from fleet_outcomes import OUTCOMES
from hrgtc.fleet.results import SCHEMA, read_table, table, write_table

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
