"""The fleet's files from their records: the same table and truth text as before them.

Truth: ``tests/data/fleet-table/table.json``, written by the commit before the record
(``make.py`` beside it, from the hand-written pyarrow ``SCHEMA``) for the outcomes of
``tests/fleet_outcomes.py``; ``tests/data/fleet-truth/unit-K.json``, a population unit's
``truth.json`` as written before :class:`FleetTruthRecord` (``make.py`` beside them).
"""

from __future__ import annotations

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
