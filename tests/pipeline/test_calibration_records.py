"""The calibration's and the instrument's ``--json`` documents as records: each equals the
hand-written one it replaced (:mod:`tests.legacy_documents`, key for key and in order) and
validates against its JSON Schema (jsonschema, independent of msgspec).

Truth: the hand-written documents of the commit before the records, and the JSON Schema
validator.
"""

from __future__ import annotations

import copy
import dataclasses
import json

import jsonschema
import pytest
from tests import legacy_documents as legacy

from hrgtc.evaluation import evaluate
from hrgtc.pipeline.calibration import RateTables, calibrate
from hrgtc.pipeline.documents import calibrate_json_schema, evaluate_json_schema

# the imu campaign's 4 rate-table temperatures leave a term out; not what these tests are about
pytestmark = pytest.mark.filterwarnings("ignore::hrgtc.core.errors.HrgtcWarning")


def same(document, reference):
    """Equal after a JSON round trip, with the same keys in the same order at every depth."""
    assert json.dumps(document, allow_nan=False) == json.dumps(legacy.strict(reference),
                                                               allow_nan=False)


@pytest.fixture(scope="module")
def single(paper_campaign):
    files = paper_campaign
    return calibrate(files.soaks, [files.cooldown], [files.warmup])


@pytest.fixture(scope="module")
def imu(imu_campaign):
    files = imu_campaign
    return calibrate(files.soaks, [files.cooldown], [files.warmup],
                     rate_tables=RateTables([files.rate_table], [files.rate_table_heldout]))


def _mapped(calibration):
    """``calibration`` as if calibrated with ``--temp-ref`` (a temperature map)."""
    mapped = {"scale_c_per_count": 0.01, "offset_c": -40.0, "count_bits": None, "lag_s": 2.0,
              "residual_rms_c": 0.05, "residual_max_c": None, "points": 12,
              "count_range": [1000.0, 9000.0], "reference": "ref.csv", "probe": "PT100"}
    return dataclasses.replace(
        calibration, model=dataclasses.replace(calibration.model, temperature_map=mapped))


def test_single_axis_documents_are_the_hand_written_ones(single, paper_campaign):
    assert single.model.is_single_axis and single.validation
    for calibration in (single, _mapped(single)):
        same(calibration.to_dict(), legacy.instrument_document(calibration))
    result = single.axes[""]
    same(result.to_dict(), legacy.calibration(result))
    evaluation = evaluate(single.model, paper_campaign.warmup)
    same(evaluation.to_dict(), legacy.instrument_evaluation(evaluation))


def test_instrument_documents_are_the_hand_written_ones(imu, imu_campaign):
    assert imu.scale_checks and not imu.model.is_single_axis
    for calibration in (imu, _mapped(imu)):
        same(calibration.to_dict(), legacy.instrument_document(calibration))
    for check in imu.scale_checks:
        same(check.to_dict(), legacy.scale_check(check))
    evaluation = evaluate(imu.model, imu_campaign.rate_table_heldout)
    assert evaluation.scale_checks
    same(evaluation.to_dict(), legacy.instrument_evaluation(evaluation))


def _checked(document, schema):
    document = json.loads(json.dumps(document, allow_nan=False))
    jsonschema.validate(document, schema)
    return document


def test_documents_validate_against_their_schemas(single, imu, imu_campaign):
    schema = calibrate_json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    for calibration in (single, _mapped(single), imu, _mapped(imu)):
        _checked(calibration.to_dict(), schema)
    assert "temperature_map" not in single.to_dict()
    assert _mapped(single).to_dict()["temperature_map"]["probe"] == "PT100"  # kept as is
    document = _checked(imu.to_dict(), schema)
    assert "validation" not in document  # only a single axis has it at the top
    assert {"ScaleFactorRecord", "StepRecord", "EvaluationRecord", "Table1Row"} <= set(
        schema["$defs"])
    broken = copy.deepcopy(document)
    broken["axes"]["x"]["drift"]["n_windows"] = -1
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, schema)
    broken = copy.deepcopy(document)
    del broken["axes"]["y"]["thermometer"]["table"]
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, schema)

    schema = evaluate_json_schema()
    evaluation = evaluate(imu.model, imu_campaign.warmup)
    document = _checked(evaluation.to_dict(), schema)
    assert [row["axis"] for row in document["summary"]] == ["x", "y", "z"]
    _checked(single.validation[0].to_dict(), schema)
    broken = copy.deepcopy(document)
    broken["summary"][0]["out_of_range_fraction"] = -0.1
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, schema)
