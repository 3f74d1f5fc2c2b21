"""Tests of hrgtc.core.records: one typed record per result gives its JSON, checks and schema.

Truth: the golden model files of every schema version (written by earlier commits), the
JSON Schema validator (jsonschema, independent of msgspec) and round trips.
"""

from __future__ import annotations

import copy
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path

import jsonschema
import msgspec
import pytest

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.drift import DriftModel
from hrgtc.drift.scale_factor import ScaleFactorModel
from hrgtc.model_schema import MODEL_SCHEMA, axis_records, check_document
from hrgtc.thermometry import Thermometer
from hrgtc.thermometry.thermometer import ThermometerRecord

GOLDEN = Path(__file__).parents[1] / "data" / "golden-models"
V1 = GOLDEN / "v1" / "unit-resonator-48c2395.json"
IMU = GOLDEN / "v3" / "instrument-imu3-scale-factor-ee60050.json"


def _document(path=V1):
    return json.loads(path.read_text())


def test_a_statistic_that_is_not_finite_is_written_null_and_read_back_nan():
    data = _document()["thermometer"]
    thermometer = Thermometer.from_dict(data)
    nan = msgspec.structs.replace(msgspec.convert(thermometer, ThermometerRecord,
                                                  from_attributes=True), rsquared=math.nan)
    written = records.dump(nan, ThermometerRecord)
    assert written["rsquared"] is None
    again = Thermometer.from_dict(written)
    assert math.isnan(again.rsquared)
    assert again.coefficients == thermometer.coefficients
    # version 1 spelled it "NaN"; the record reads that too
    assert math.isnan(Thermometer.from_dict({**data, "rsquared": "NaN"}).rsquared)


def test_round_trips_are_exact_for_every_part():
    document = _document(IMU)["axes"]["x"]
    assert Thermometer.from_dict(document["thermometer"]).to_dict() == document["thermometer"]
    checked = axis_records(check_document(_document(IMU), "imu"))["x"]
    drift = records.built(checked.drift)  # converted once, the coefficients derived
    assert isinstance(drift, DriftModel)
    assert drift.to_dict()["coefficients"] == document["drift"]["coefficients"]
    assert drift.to_dict()["settings"] == document["drift"]["settings"]
    assert ScaleFactorModel.from_dict(document["scale_factor"]).to_dict() == (
        document["scale_factor"])


def test_source_is_written_only_for_a_sensor_thermometer():
    data = _document()["thermometer"]
    assert "source" not in Thermometer.from_dict(data).to_dict()
    sensor = Thermometer.from_dict({**data, "source": "sensor"}).to_dict()
    assert sensor["source"] == "sensor"


@pytest.mark.parametrize("part, change, place", [
    ("thermometer", {"order": 0}, r"Expected `int` >= 1 - at `\$.order`"),
    ("thermometer", {"scale_c": -1.0}, r"> 0.0 - at `\$.scale_c`"),
    ("thermometer", {"source": "chamber"}, r"at `\$.source`"),
    ("thermometer", {"temperature_range_c": [1.0]}, r"length 2, got 1 - at "
                                                    r"`\$.temperature_range_c`"),
])
def test_a_record_names_the_place_of_what_does_not_fit(part, change, place):
    data = {**_document()[part], **change}
    with pytest.raises(InputError, match=rf"not a valid thermometer record: .*{place}"):
        Thermometer.from_dict(data)


def test_a_nested_place_is_named_from_the_part():
    data = copy.deepcopy(_document()["drift"])
    data["settings"]["rate_tau_s"] = 0.0
    with pytest.raises(InputError, match=r"drift-model record: .* at `\$.settings.rate_tau_s`"):
        DriftModel.from_dict(data)


def test_the_schema_is_the_records():
    """Every record of the model file is in the schema with exactly its fields, and what
    it requires is what has no default."""
    definitions = MODEL_SCHEMA["$defs"]
    assert {"ThermometerRecord", "DriftModelRecord", "FeatureSettingsRecord",
            "ScaleFactorRecord", "TrainingStatisticsRecord", "AxisRecord"} <= set(definitions)
    for name, schema in definitions.items():
        record = next(r for r in _records() if r.__name__ == name)
        fields = msgspec.structs.fields(record)
        assert set(schema["properties"]) == {f.name for f in fields}, name
        required = {f.name for f in fields if f.required}
        assert set(schema.get("required", ())) == required, name


def _records():
    found, todo = [], [records.Record]
    while todo:
        for sub in todo.pop().__subclasses__():
            found.append(sub)
            todo.append(sub)
    return found


@pytest.mark.parametrize("where, value", [
    (("thermometer", "order"), 13),
    (("thermometer", "n_points"), 1),
    (("drift", "window_s"), 0.0),
    (("drift", "candidates"), []),
    (("drift", "selected"), ["f**2"]),
    (("drift", "settings", "scales", "f"), 0.0),
    (("drift", "n_windows"), -1),
    (("training", "runs"), -2),
])
def test_schema_and_record_refuse_the_same_values(where, value):
    """Two independent validators (jsonschema on the generated schema, msgspec on the
    record) agree on each bound."""
    document = _document(GOLDEN / "v2" / "unit-g-d2-aux-ee60050.json")
    target = document
    for key in where[:-1]:
        target = target[key]
    target[where[-1]] = value
    error = jsonschema.exceptions.best_match(
        jsonschema.Draft202012Validator(MODEL_SCHEMA).iter_errors(document))
    assert error is not None and list(error.absolute_path)[:len(where)] == list(where)
    part = {"thermometer": Thermometer, "drift": DriftModel}.get(where[0])
    if part is None:
        from hrgtc.drift.training import TrainingStatistics

        part = TrainingStatistics
    # msgspec names a mapping's key as [...]: scales.f -> scales[...]
    place = ".".join(where[1:]).replace(".scales.f", ".scales[...]")
    with pytest.raises(InputError, match=re.escape(f"at `$.{place}")):
        part.from_dict(document[where[0]])


def _pairs():
    from hrgtc.drift.cross_validation import CrossValidation
    from hrgtc.drift.drift_model import DriftModelRecord
    from hrgtc.drift.features import FeatureSettings, FeatureSettingsRecord
    from hrgtc.drift.qr_accumulator import OLSResult
    from hrgtc.drift.scale_factor import ScaleFactorRecord, ScaleGroup
    from hrgtc.drift.stepwise import Step, StepwiseResult
    from hrgtc.drift.training import TrainingStatistics
    from hrgtc.model import AxisModel
    from hrgtc.model_schema import AxisRecord

    # (result, record, the result's fields a file does not hold)
    return [(Thermometer, ThermometerRecord, set()),
            (FeatureSettings, FeatureSettingsRecord, set()),
            (TrainingStatistics, TrainingStatistics, set()),
            (DriftModel, DriftModelRecord, {"_terms", "accounting"}),
            (ScaleFactorModel, ScaleFactorRecord, {"_terms"}),
            (ScaleGroup, ScaleGroup, set()),
            (Step, Step, set()),
            (StepwiseResult, StepwiseResult, set()),
            (OLSResult, OLSResult, set()),
            (CrossValidation, CrossValidation, {"sources"}),  # the keys of per_run_dph
            (AxisModel, AxisRecord, set())]  # one axis's parts (unit, provenance: the file's)


@pytest.mark.parametrize("result, record, left_out", _pairs(),
                         ids=[records.record_of(p[1]).__name__ for p in _pairs()])
def test_a_result_and_its_record_have_the_same_fields(result, record, left_out):
    """A field added to a result but not to its record would silently not be written."""
    import dataclasses

    fields = {f.name for f in dataclasses.fields(result)} - left_out
    written = {f.name for f in msgspec.structs.fields(records.record_of(record))} - {"kind"}
    assert fields == written



@dataclass(frozen=True)
class _Part(records.Written):
    constants = (("kind", "test.Part"),)
    file_names = (("low", "min"),)
    renamed = (("old_width", "width"),)
    required = ("width",)
    record_order = ("kind", "low", "area", "width")

    low: float
    width: records.Positive = 1.0

    @records.derived(default=0.0)
    def area(self) -> float:
        return self.low * self.width


@dataclass(frozen=True)
class _Tagged(records.Written):
    tag = ("kind", "tagged")
    value: int


@dataclass(frozen=True)
class _Holder(records.Written):
    part: _Tagged


def test_what_a_file_part_needs_beyond_its_fields_is_declared_beside_them():
    """records' class attributes: a constant written first, a key of another name, an old
    key, a field required though defaulted, a derived figure, the file's order, a tag."""
    record = records.record_of(_Part, "PartRecord", "A part.")
    assert record.__struct_fields__ == ("kind", "low", "area", "width")
    written = _Part(2.0, 3.0).to_dict()
    assert list(written.items()) == [("kind", "test.Part"), ("min", 2.0), ("area", 6.0),
                                     ("width", 3.0)]
    assert _Part.from_dict(written) == _Part(2.0, 3.0)  # area and kind not passed back
    assert _Part.from_dict({"kind": "test.Part", "min": 2.0, "old_width": 5.0}).width == 5.0
    with pytest.raises(InputError, match="width"):
        _Part.from_dict({"min": 2.0})  # required in the file
    with pytest.raises(InputError, match=r"\$.kind"):
        _Part.from_dict({**written, "kind": "test.Other"})
    schema = records.json_schema(_Part, "part", "https://hrgtc.invalid/part.json")
    assert schema["description"] == "A part."
    assert schema["properties"]["kind"] == {"enum": ["test.Part"], "default": "test.Part"}
    assert schema["required"] == ["min", "width"]
    assert _Holder(_Tagged(4)).to_dict() == {"part": {"kind": "tagged", "value": 4}}
    assert _Holder.from_dict({"part": {"kind": "tagged", "value": 4}}) == _Holder(_Tagged(4))
