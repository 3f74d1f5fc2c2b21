"""Records of the results beside the model's parts: the model file's own fields, the
temperature map, the thermometer prior, plateaus and settling fits, the paper's
reproduction and a fleet unit's outcome.

Truth: the golden model files (written by earlier commits: their plateaus and temperature
map must come back byte for byte), the layouts these results had before their records
(written out here as literals), round trips, and the JSON Schema validator (jsonschema,
independent of msgspec) on what each record writes.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from hrgtc.core import records
from hrgtc.core.errors import InputError, RecordingError
from hrgtc.fleet.tasks import ErrorRecord, UnitOutcome, UnitOutcomeRecord, failed
from hrgtc.model import Model, load_model
from hrgtc.model_schema import FileRecord, axis_parts
from hrgtc.thermometry import fit, paper
from hrgtc.thermometry.paper import ReproductionRecord
from hrgtc.thermometry.plateaus import Plateau
from hrgtc.thermometry.prior import (
    PRIOR_JSON_SCHEMA,
    PriorFitRecord,
    ThermometerPrior,
    ThermometerPriorRecord,
    fit_with_prior,
)
from hrgtc.thermometry.reference import TemperatureMap, TemperatureMapRecord
from hrgtc.thermometry.settling import TransientFit

GOLDEN = sorted((Path(__file__).parents[1] / "data" / "golden-models").glob("v*/*.json"))
IDS = [f"{p.parent.name}/{p.stem}" for p in GOLDEN]
EQ18 = np.polynomial.Polynomial.fit(paper.TABLE1_TEMPERATURE_C, paper.TABLE1_FREQUENCY_HZ, 3)
SETPOINTS_C = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0])


def _valid(document, record, title="t"):
    """``document`` fits the record's generated JSON Schema (checked by jsonschema)."""
    schema = records.json_schema(record, title, "https://hrgtc.invalid/schema/test.json")
    jsonschema.Draft202012Validator(schema).validate(document)


def _prior() -> ThermometerPrior:
    rng = np.random.default_rng(1)
    fits = [fit(SETPOINTS_C, EQ18(SETPOINTS_C) * (1 + 1e-3 * rng.standard_normal())
                + 1e-3 * rng.standard_normal(7)) for _ in range(8)]
    return ThermometerPrior.from_thermometers(fits, [f"u{k}" for k in range(8)])


# -- the golden files' parts come back byte for byte ------------------------------------
@pytest.mark.parametrize("path", GOLDEN, ids=IDS)
def test_golden_plateaus_and_map_round_trip_exactly(path):
    document = json.loads(path.read_text())
    for part in axis_parts(document).values():
        for plateau in part.get("plateaus", ()):
            again = Plateau.from_dict(plateau)
            assert json.dumps(again.to_dict()) == json.dumps(plateau)
            _valid(plateau, Plateau)
            if plateau["fit"] is not None:
                assert again.fit == TransientFit.from_dict(plateau["fit"])
    if document.get("temperature_map") is not None:
        tm = document["temperature_map"]
        assert json.dumps(TemperatureMap.from_dict(tm).to_dict()) == json.dumps(tm)
        _valid(tm, TemperatureMapRecord)


@pytest.mark.parametrize("path", GOLDEN, ids=IDS)
def test_model_file_fields_come_from_the_file_record(path):
    document = json.loads(path.read_text())
    model = load_model(path)
    written = model.to_dict()
    # the file's own fields in FileRecord's order, one axis at the place of axes
    own = [k for k in written if k in FileRecord.__struct_fields__]
    assert own == [k for k in FileRecord.__struct_fields__ if k in own]
    assert ("axes" in written) == ("axes" in document)
    assert list(written)[-1] == ("temperature_map" if "temperature_map" in document
                                 else "provenance")
    assert written["provenance"] == document["provenance"]
    again = Model.from_dict(written)
    assert again.to_dict() == written


def test_a_model_file_head_is_checked_by_its_record():
    with pytest.raises(InputError, match=r"at `\$.schema_version`"):
        records.load({"schema": "hrgtc.model", "schema_version": 0}, FileRecord, "model file")


# -- temperature map ----------------------------------------------------------------
def test_temperature_map_layout_and_unknown_keys():
    tm = TemperatureMap(0.005, 24.0, 16, 120.0, 0.2, math.nan, 25, (-2400.0, math.nan),
                        "log.csv", {"from_a_newer_version": [1, 2]})
    written = tm.to_dict()
    assert list(written.items()) == [  # the layout before the record
        ("scale_c_per_count", 0.005), ("offset_c", 24.0), ("count_bits", 16), ("lag_s", 120.0),
        ("residual_rms_c", 0.2), ("residual_max_c", None), ("points", 25),
        ("count_range", [-2400.0, None]), ("reference", "log.csv"),
        ("from_a_newer_version", [1, 2])]
    again = TemperatureMap.from_dict(json.loads(json.dumps(written)))
    assert again.to_dict() == written
    assert math.isnan(again.residual_max_c) and again.extra == {"from_a_newer_version": [1, 2]}
    bare = TemperatureMap.from_dict({"scale_c_per_count": 0.1, "offset_c": -3.0})
    assert bare == TemperatureMap(0.1, -3.0)


@pytest.mark.parametrize(("change", "message"), [
    ({"count_bits": 8}, r"at `\$.count_bits`"),
    ({"points": -1}, r"at `\$.points`"),
    ({"scale_c_per_count": 0.0}, "a finite scale other than 0"),
    ({"offset_c": "warm"}, r"at `\$.offset_c`"),
])
def test_temperature_map_refusals_name_the_place(change, message):
    with pytest.raises(InputError, match=message):
        TemperatureMap.from_dict({"scale_c_per_count": 0.1, "offset_c": -3.0, **change})


# -- thermometer prior --------------------------------------------------------------
def test_prior_file_layout_round_trip_and_schema():
    prior = _prior()
    written = prior.to_dict()
    assert list(written) == [  # the prior file's keys before the record, in order
        "schema", "schema_version", "order", "centre_c", "scale_c", "temperature_range_c",
        "basis", "mean", "covariance", "nominal_freq_hz", "nominal_freq_std_hz",
        "point_std_hz", "n_units", "units"]
    assert written["schema"] == "hrgtc.thermometer-prior" and written["n_units"] == 8
    assert written["covariance"] == [list(r) for r in prior.covariance]
    assert ThermometerPrior.from_dict(json.loads(json.dumps(written))) == prior
    jsonschema.Draft202012Validator(PRIOR_JSON_SCHEMA).validate(written)
    _valid(written, ThermometerPriorRecord)
    with pytest.raises(InputError, match=r"prior\.json: prior file is corrupt.*`\$.scale_c`"):
        ThermometerPrior.from_dict({**written, "scale_c": 0.0}, source="prior.json")
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate({**written, "scale_c": 0.0}, PRIOR_JSON_SCHEMA)


def test_prior_fit_document():
    prior = _prior()
    t = np.array([-20.0, 40.0])
    result = fit_with_prior(t, EQ18(t), prior, 1e-4)
    written = result.to_dict()
    assert list(written) == ["prior_units", "temperatures_c", "frequencies_hz", "point_std_hz",
                             "max_sigma", "max_temperature_std_c", "temperature_band"]
    assert written["prior_units"] == 8
    assert written["temperatures_c"] == [-20.0, 40.0]
    assert written["max_temperature_std_c"] == result.max_temperature_std_c
    assert written["temperature_band"] == result.band(13)
    _valid(written, PriorFitRecord)


# -- plateaus and settling fits -----------------------------------------------------------
def _plateau() -> Plateau:
    settling = TransientFit("one exponential", 4421.05, 1e-4, (3000.0,), (1.0,), (0.5,), 100.0,
                            18000.0, 300, 2e-4, -512.5, True)
    return Plateau(-10.0, 4421.04, 3e-4, 3600, 14400.0, 18000.0, 0.002, True, 4421.05, 1e-4,
                   "transient fit", 0.01, 0.37, 100.0, settling, "soak.csv")


def test_plateau_round_trip_and_statistics_that_are_not_finite():
    plateau = _plateau()
    written = plateau.to_dict()
    assert list(written) == [f.name for f in dataclasses.fields(Plateau)]
    assert list(written["fit"]) == [f.name for f in dataclasses.fields(TransientFit)]
    assert Plateau.from_dict(json.loads(json.dumps(written))) == plateau
    _valid(written, Plateau)
    unsettled = dataclasses.replace(plateau, residual_unsettled_c=math.nan, source=None,
                                    fit=dataclasses.replace(plateau.fit, aic=-math.inf,
                                                            tau_s=(math.nan,)))
    written = unsettled.to_dict()
    assert written["residual_unsettled_c"] is None and written["fit"]["aic"] is None
    assert written["fit"]["tau_s"] == [None]
    again = Plateau.from_dict(json.loads(json.dumps(written)))
    assert math.isnan(again.residual_unsettled_c) and math.isnan(again.fit.aic)  # null: NaN
    assert again.to_dict() == written
    with pytest.raises(InputError, match=r"plateau record.*`\$.n_samples`"):
        Plateau.from_dict({**plateau.to_dict(), "n_samples": -1})
    with pytest.raises(InputError, match=r"transient-fit record.*`\$.n_blocks`"):
        TransientFit.from_dict({**plateau.fit.to_dict(), "n_blocks": 1.5})
    _valid(plateau.fit.to_dict(), TransientFit)


# -- the paper's reproduction -----------------------------------------------------------
def test_paper_document_layout():
    result = paper.reproduce()
    written = result.to_dict()
    assert list(written) == ["eq18", "table2"]
    assert written["eq18"] == {
        "coefficients_high_first": list(result.coefficients_high_first),
        "rounded_high_first": list(result.rounded_high_first),
        "published_high_first": list(paper.EQ18_PRINTED_HIGH_FIRST)}
    assert [list(row) for row in written["table2"]] == [
        ["frequency_hz", "actual_c", "published_c", "computed_c"]] * 7
    assert [row["published_c"] for row in written["table2"]] == list(
        paper.TABLE2_CALCULATED_C)
    assert [row["computed_c"] for row in written["table2"]] == list(result.table2_computed_c)
    _valid(written, ReproductionRecord)


# -- a fleet unit's outcome -----------------------------------------------------------------
def test_unit_outcome_round_trip_with_and_without_a_traceback():
    ok = UnitOutcome("u1", "ok", {"unit": "u1", "n_soaks": 7, "f20_hz": 4432.07}, None, 1.5, 1.2)
    assert list(ok.to_dict()) == ["unit", "status", "row", "error", "seconds", "cpu_seconds"]
    assert UnitOutcome.from_dict(json.loads(json.dumps(ok.to_dict()))) == ok
    for exc in (RecordingError("soak.csv: column 'freq_hz' row 12 is not a number"),
                ZeroDivisionError("division by zero")):
        try:
            raise exc
        except Exception as caught:
            bad = failed("u2", caught, ("soak.csv",), 0.0)
        written = bad.to_dict()
        _valid(written, UnitOutcomeRecord)
        _valid(written["error"], ErrorRecord)
        assert UnitOutcome.from_dict(json.loads(json.dumps(written))) == bad
    assert ("traceback" in written["error"]) and written["error"]["type"] == "ZeroDivisionError"
    first = failed("u2", RecordingError("soak.csv: column 'freq_hz' row 12 is bad"),
                   ("soak.csv",), 0.0).error
    assert first == {"type": "RecordingError", "message": first["message"], "file": "soak.csv",
                     "column": "freq_hz", "row": 12}
    with pytest.raises(InputError, match=r"`\$.status`"):
        UnitOutcome.from_dict({**ok.to_dict(), "status": "done"})
