"""The evaluation's results as records: each document equals the hand-written one it
replaced (:mod:`tests.legacy_documents`, key for key and in order), validates against its
record's JSON Schema (jsonschema, independent of msgspec) and, where the result reads one
back, round-trips.

Truth: the hand-written documents of the commit before the records, and the JSON Schema
validator.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math

import jsonschema
import msgspec
import numpy as np
import pytest
from tests import legacy_documents as legacy
from tests.bursts import cut_bursts

from hrgtc import recording
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.evaluation import Evaluation, evaluate
from hrgtc.evaluation.burst_allan import BurstAllanRecord, BurstAllanResult, burst_mean_allan
from hrgtc.evaluation.evaluation_result import EvaluationRecord, evaluation_json_schema
from hrgtc.evaluation.heating_cooling import DirectionStats, DirectionStatsRecord
from hrgtc.evaluation.metrics import ResidualRecord, ResidualResult, residual_against_truth
from hrgtc.pipeline.calibration import calibrate
from hrgtc.settings.compensation import EvaluationSettings

pytestmark = pytest.mark.filterwarnings("ignore::hrgtc.core.errors.RateFilterWarning")


def same(document, reference):
    """Equal after a JSON round trip, with the same keys in the same order at every depth."""
    assert json.dumps(document, allow_nan=False) == json.dumps(legacy.strict(reference),
                                                               allow_nan=False)


@pytest.fixture(scope="module")
def evaluations(paper_campaign):
    files = paper_campaign
    model = calibrate(files.soaks, [files.cooldown]).model
    whole = evaluate(model, files.warmup, max_points=300).axis
    run = cut_bursts(recording.read(files.warmup), burst_s=60.0, period_s=600.0)
    bursts = evaluate(model, run, settings=EvaluationSettings(deviation="mdev")).axis
    return {"whole": whole, "bursts": bursts}


def _residual():
    rng = np.random.default_rng(3)
    truth = np.cumsum(rng.normal(size=4000)) * 0.01
    return residual_against_truth(bias_model_dph=truth + rng.normal(size=4000),
                                  true_bias_dph=truth, sample_rate_hz=10.0,
                                  taus_s=(1.0, 10.0, 1000.0))


def _bursts():
    rng = np.random.default_rng(5)
    starts = np.arange(40) * 300.0
    starts[20:] += 300.0  # a missing burst: two runs
    return burst_mean_allan(rng.normal(size=40), np.full(40, 5.0), starts)


def _directions():
    return [DirectionStats(10.0, {"heating": 12, "cooling": 2},
                           {"heating": 0.5, "cooling": float("nan")},
                           {"heating": 0.25, "cooling": float("nan")},
                           {"heating": 0.1, "cooling": 0.2}, partial_blocks=3),
            DirectionStats(10.0, {"heating": 0, "cooling": 0},
                           {"heating": float("nan"), "cooling": float("nan")},
                           {"heating": float("nan"), "cooling": float("nan")},
                           reason="the run is shorter than a block")]


def test_evaluation_documents_are_the_hand_written_ones(evaluations):
    for result in evaluations.values():
        same(result.to_dict(), legacy.evaluation(result))
    bursts = evaluations["bursts"]
    assert bursts.burst_allan and bursts.directions is not None
    assert bursts.ranges is not None and bursts.accounting is not None


def test_part_documents_are_the_hand_written_ones():
    result = _residual()
    same(result.to_dict(), legacy.residual(result))
    result = _bursts()
    assert result.runs == 2
    same(result.to_dict(), legacy.burst_allan(result))
    for stats in _directions():
        same(stats.to_dict(), legacy.directions(stats))


def _valid(document, record, title):
    schema = records.json_schema(record, title, "https://hrgtc.invalid/schema/test.json")
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(json.loads(json.dumps(document, allow_nan=False)), schema)
    return schema


def test_evaluation_documents_validate_against_their_schema(evaluations):
    schema = evaluation_json_schema()
    jsonschema.Draft202012Validator.check_schema(schema)
    for result in evaluations.values():
        document = json.loads(json.dumps(result.to_dict(), allow_nan=False))
        jsonschema.validate(document, schema)
    # the schema holds the records of its parts, and refuses what they refuse
    assert {"NoiseTermsRecord", "BurstAllanRecord", "DirectionStatsRecord",
            "DeviationCurveRecord", "RangeReportRecord", "AccountingRecord"} <= set(
        schema["$defs"])
    broken = copy.deepcopy(document)
    broken["out_of_range_fraction"] = 1.5
    with pytest.raises(jsonschema.ValidationError, match=r"1\.5"):
        jsonschema.validate(broken, schema)
    broken = copy.deepcopy(document)
    broken["allan_burst_means"]["raw"]["counts"][0] = -1
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(broken, schema)
    del broken["allan_burst_means"]
    with pytest.raises(jsonschema.ValidationError, match="allan_burst_means"):
        jsonschema.validate(broken, schema)


def test_parts_validate_and_round_trip():
    residual = _residual()
    document = residual.to_dict()
    _valid(document, ResidualRecord, "residual")
    assert math.isnan(residual.bias_stability_dph[1000.0])  # written null, read back NaN
    back = ResidualResult.from_dict(json.loads(json.dumps(document)))
    assert back.to_dict() == document and back.n_samples == residual.n_samples
    assert math.isnan(back.bias_stability_dph[1000.0])

    bursts = _bursts()
    document = bursts.to_dict()
    _valid(document, BurstAllanRecord, "burst means")
    back = BurstAllanResult.from_dict(json.loads(json.dumps(document)))
    assert back.to_dict() == document
    np.testing.assert_array_equal(back.deviation, bursts.deviation)
    assert back.counts.dtype.kind == "i"
    with pytest.raises(InputError, match=r"burst-allan-result record: .*`\$.runs`"):
        BurstAllanResult.from_dict({**document, "runs": 0})

    for stats in _directions():
        _valid(stats.to_dict(), DirectionStatsRecord, "directions")


#: Evaluation field -> where its document holds it (None: not in the document).
EVALUATION_PLACES = {"noise": "allan", "allan": "allan_curve",
                     "bias_stability_blocks": "bias_stability_n",
                     "burst_allan": "allan_burst_means", "directions": "heating_cooling",
                     "source": None, "unit": None, "input_rate_dph": None, "block_s": None,
                     "blocks": None}


@pytest.mark.parametrize("result, record, places", [
    (ResidualResult, ResidualRecord, {}),
    (BurstAllanResult, BurstAllanRecord, {}),
    (Evaluation, EvaluationRecord, EVALUATION_PLACES),
], ids=["residual", "burst-means", "evaluation"])
def test_every_field_of_a_result_has_its_place_in_the_record(result, record, places):
    """A field added to a result but not to its record would silently not be written."""
    fields = {places.get(f.name, f.name) for f in dataclasses.fields(result)} - {None}
    written = {f.name for f in msgspec.structs.fields(record)}
    derived = {"bias_stability_10s_dph", "improvement_10s", "prediction_std_dph"}
    assert fields == written - (derived if result is Evaluation else set())
