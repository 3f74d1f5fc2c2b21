"""Tests of hrgtc.model_schema: model files are validated, never trusted (issue 11)."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.core.errors import ModelFileError
from hrgtc.model import SCHEMA_VERSION, AxisModel, Model, load_model, save_model
from hrgtc.model_schema import MODEL_SCHEMA, derived_coefficients

from synthetic import THERMOMETER, ramp_run


@pytest.fixture(scope="module")
def unit_model():
    return Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([ramp_run(seed=11, hours=3.0)],
            THERMOMETER)), unit="SN-1")


@pytest.fixture()
def document(unit_model):
    return json.loads(json.dumps(unit_model.to_dict()))


def _write(tmp_path, data, name="unit.json", text=None):
    path = tmp_path / name
    path.write_text(text if text is not None else json.dumps(data, allow_nan=True))
    return path


def test_the_schema_is_a_valid_json_schema():
    import jsonschema

    jsonschema.Draft202012Validator.check_schema(MODEL_SCHEMA)


def test_written_file_is_strict_json_and_loads_back(tmp_path, unit_model):
    model = Model.single(
        AxisModel(unit_model.thermometer, unit_model.drift), unit="SN-1",
            provenance={"note": math.nan})  # a statistic-like NaN anywhere
    path = save_model(model, tmp_path / "unit.json")
    text = path.read_text()

    def refuse(name):
        raise AssertionError(f"non-standard constant {name} in the model file")

    data = json.loads(text, parse_constant=refuse)
    assert data["schema_version"] == 2 and SCHEMA_VERSION == 3  # 3 only with axes or scale
    assert data["provenance"]["note"] is None
    again = load_model(path)
    assert again.sha256 == unit_model.sha256


@pytest.mark.parametrize("where, value, match", [
    (("drift", "scaled_coefficients", 0), math.nan, r"drift.scaled_coefficients\[0\]: 'NaN' does"),
    (("drift", "scaled_coefficients", 0), math.inf, r"drift.scaled_coefficients\[0\]: "
                                                      r"'Infinity' does not fit"),
    (("drift", "intercept_dph"), math.nan, r"drift.intercept_dph: 'NaN' does not fit: "
                                            r"Expected `float`"),
    (("thermometer", "scaled_coefficients", 1), math.nan,
     r"thermometer.scaled_coefficients\[1\]: 'NaN' does"),
    (("thermometer", "coefficients", 0), math.nan, r"thermometer.coefficients\[0\]: 'NaN' does"),
    (("drift", "settings", "scales", "f"), -1.0, r"drift.settings.scales.f: -1.0 does not fit: "
                                                    r"Expected `float` > 0.0"),
])
def test_non_finite_parameters_are_refused(tmp_path, document, where, value, match):
    # old files (version 1) were written with allow_nan: a bare NaN must be named, not used
    document["schema_version"] = 1
    target = document
    for key in where[:-1]:
        target = target[key]
    target[where[-1]] = value
    with pytest.raises(ModelFileError, match=match):
        load_model(_write(tmp_path, document))


def test_readable_coefficients_must_agree_with_the_scaled_ones(tmp_path, document):
    document["schema_version"] = 1  # a bare NaN: what older hrgtc wrote
    name = document["drift"]["selected"][0]
    document["drift"]["coefficients"][name] = math.nan
    with pytest.raises(ModelFileError, match=rf"drift.coefficients.{name}: 'NaN'"):
        load_model(_write(tmp_path, document))
    document["drift"]["coefficients"][name] = 1.5 * derived_coefficients(document["drift"])[name]
    with pytest.raises(ModelFileError, match=r"disagrees with .* derived from scaled_coeff"):
        load_model(_write(tmp_path, document))
    document["thermometer"]["coefficients"][3] *= 1.001
    document["drift"]["coefficients"] = derived_coefficients(document["drift"])
    with pytest.raises(ModelFileError, match=r"thermometer.coefficients\[3\].* disagrees"):
        load_model(_write(tmp_path, document))


def test_reversed_range_short_and_unknown_terms(tmp_path, document):
    good = json.dumps(document)
    bad = json.loads(good)
    bad["drift"]["ranges"]["f"] = bad["drift"]["ranges"]["f"][::-1]
    with pytest.raises(ModelFileError, match=r"drift.ranges.f: .* is reversed"):
        load_model(_write(tmp_path, bad))
    bad = json.loads(good)
    bad["drift"]["scaled_coefficients"] = bad["drift"]["scaled_coefficients"][:-1]
    with pytest.raises(ModelFileError, match=r"drift.scaled_coefficients: \d+ values for \d+"):
        load_model(_write(tmp_path, bad))
    bad = json.loads(good)
    bad["drift"]["selected"][0] = "q^2"
    with pytest.raises(ModelFileError, match=r"drift.selected: .*q"):
        load_model(_write(tmp_path, bad))
    bad = json.loads(good)
    bad["thermometer"]["temperature_range_c"] = [40.0, -20.0]
    with pytest.raises(ModelFileError, match=r"thermometer.temperature_range_c: .* ordered"):
        load_model(_write(tmp_path, bad))
    bad = json.loads(good)
    bad["thermometer"]["order"] = 5
    with pytest.raises(ModelFileError, match=r"thermometer.coefficients: 4 values .* order 5"):
        load_model(_write(tmp_path, bad))


def test_old_version_with_nan_statistics_still_loads(tmp_path, document, unit_model):
    document["schema_version"] = 1
    name = document["drift"]["selected"][0]
    document["drift"]["pvalues"][name] = math.nan
    document["drift"]["rsquared"] = math.nan
    path = _write(tmp_path, document)
    assert "NaN" in path.read_text()
    model = load_model(path)
    assert math.isnan(model.drift.pvalues[name])
    values = {"f": np.linspace(-10, 5, 7), "df": np.linspace(-1e-3, 1e-3, 7)}
    np.testing.assert_array_equal(model.drift.predict(values), unit_model.drift.predict(values))


def test_new_version_must_be_strict_json(tmp_path, document):
    document["drift"]["pvalues"][document["drift"]["selected"][0]] = math.nan
    with pytest.raises(ModelFileError, match=r"holds NaN or Infinity, which is not JSON"):
        load_model(_write(tmp_path, document))


def test_foreign_and_future_files_say_what_they_are(tmp_path, document):
    with pytest.raises(ModelFileError, match=r"not an hrgtc model file \(schema 'x.y'"):
        load_model(_write(tmp_path, {"schema": "x.y", "a": 1}))
    with pytest.raises(ModelFileError, match=r"not an hrgtc model file \(schema 'list'"):
        load_model(_write(tmp_path, [1, 2]))
    with pytest.raises(ModelFileError, match=r"version 9 is newer"):
        load_model(_write(tmp_path, {**document, "schema_version": 9}))


def test_a_model_that_cannot_be_valid_is_never_saved(tmp_path, unit_model):
    broken = Model.single(AxisModel(unit_model.thermometer, unit_model.drift.__class__(**{
        **{f: getattr(unit_model.drift, f) for f in unit_model.drift.__dataclass_fields__
           if f != "_terms"},
        "intercept_dph": math.nan})))
    with pytest.raises(ModelFileError, match=r"drift.intercept_dph: None does not fit: "
                                                    r"Expected `float`, got `null`"):
        save_model(broken, tmp_path / "unit.json")
    assert list(tmp_path.iterdir()) == []


def test_a_file_changed_after_writing_is_refused_unless_the_checksum_line_goes(tmp_path,
                                                                              unit_model):
    path = save_model(unit_model, tmp_path / "unit.json")
    data = json.loads(path.read_text())
    assert data["parameters_sha256"] == unit_model.sha256
    low, high = data["drift"]["ranges"]["f"]
    data["drift"]["ranges"]["f"] = [low, high + 0.5]  # still a valid model: wrong numbers
    edited = _write(tmp_path, data, "edited.json")
    with pytest.raises(ModelFileError, match=r"edited.json: model file was changed after it was "
                                             r"written"):
        load_model(edited)
    del data["parameters_sha256"]  # a deliberate edit
    assert load_model(_write(tmp_path, data, "deliberate.json")).drift.ranges["f"][1] == high + 0.5


def test_reference_frequency_must_match_the_thermometer(tmp_path, document):
    document["drift"]["settings"]["reference_freq_hz"] *= 1.5
    with pytest.raises(ModelFileError, match=r"reference_freq_hz: .* is not the thermometer's"):
        load_model(_write(tmp_path, document))


@pytest.mark.parametrize("variable", ["f", "df"])
def test_every_reversed_training_range_is_refused(tmp_path, document, variable):
    """Issue 21: a reversed range (a mutant that swapped the check passed every test that
    reversed only f); clipping to [high, low] would silently hold every sample at one edge."""
    low, high = document["drift"]["ranges"][variable]
    assert low < high
    document["drift"]["ranges"][variable] = [high, low]
    with pytest.raises(ModelFileError, match=rf"unit.json: model file is invalid at "
                                             rf"drift.ranges.{variable}: .* is reversed"):
        load_model(_write(tmp_path, document))
    document["drift"]["ranges"][variable] = [low, low]  # a single value is a range
    load_model(_write(tmp_path, document))


def test_a_reversed_scale_factor_range_is_refused(tmp_path, unit_model):
    from synthetic import scale_factor, with_scale_factor

    model = with_scale_factor(unit_model, scale_factor(unit_model.drift.settings.reference_freq_hz))
    data = json.loads(json.dumps(model.to_dict()))
    data["scale_factor"]["freq_range_hz"] = data["scale_factor"]["freq_range_hz"][::-1]
    with pytest.raises(ModelFileError, match=r"scale_factor.freq_range_hz: .* is reversed"):
        load_model(_write(tmp_path, data))


def test_terms_beyond_any_gyro_bias_are_refused_naming_the_term(tmp_path, document):
    """The bound is on each term's bias over the trained box of its variables."""
    from hrgtc.model_schema import BIAS_BOUND_DPH

    terms = document["drift"]["selected"]
    k = len(terms) - 1
    document["drift"]["scaled_coefficients"][k] = 2.0 * BIAS_BOUND_DPH
    document["drift"]["coefficients"] = derived_coefficients(document["drift"])
    with pytest.raises(ModelFileError, match=rf"drift.scaled_coefficients\[{k}\]: term "
                                             rf"{re.escape(terms[k])} gives a bias of"):
        load_model(_write(tmp_path, document))


def test_a_thermometer_beyond_any_hrg_frequency_is_refused(tmp_path, document):
    """An absurd but consistent thermometer coefficient (its raw form derived from it, the
    hash line removed): F(T) of 1e300 Hz is no resonator."""
    from hrgtc.thermometry.thermometer import _scaled_to_raw_matrix

    therm = document["thermometer"]
    therm["scaled_coefficients"][1] = 1e300
    matrix = _scaled_to_raw_matrix(therm["order"], therm["centre_c"], therm["scale_c"])
    therm["coefficients"] = [float(sum(float(m) * a for m, a in
                                       zip(row, therm["scaled_coefficients"], strict=True)))
                             for row in matrix]
    with pytest.raises(ModelFileError, match=r"thermometer.scaled_coefficients: F\(T\) over the "
                                             r"calibrated .* outside any HRG's resonator"):
        load_model(_write(tmp_path, document))


# -- issue 27's audit: keys written twice or unknown, sections missing ---------------------------
def test_a_key_written_twice_is_refused_naming_it_and_its_line(tmp_path, document):
    """The last of two values won (another JSON reader takes the first): accepted silently."""
    text = json.dumps(document, indent=1)
    at = text.index('"drift": {') + len('"drift": {')
    text = text[:at] + '\n "intercept_dph": 99.0,' + text[at:]
    path = _write(tmp_path, None, text=text)
    line = text[:text.index('"intercept_dph"', at + 30)].count("\n") + 1
    with pytest.raises(ModelFileError) as raised:
        load_model(path)
    assert str(raised.value).startswith(
        f"{path}: the key 'intercept_dph' is written twice in one object (again on line "
        f"{line}): JSON readers disagree on which value counts")


@pytest.mark.parametrize(("where", "key"), [((), "units"), (("drift",), "intercept"),
                                            (("thermometer",), "scale"),
                                            (("drift", "settings"), "tau")])
def test_an_unknown_key_is_refused_naming_it_and_its_place(tmp_path, document, where, key):
    node = document
    for part in where:
        node = node[part]
    node[key] = 1.0
    shown = ".".join(where) or "(top level)"
    with pytest.raises(ModelFileError, match=rf"unit.json: model file is invalid at "
                                             rf"{re.escape(shown)}: unknown key '{key}' "):
        load_model(_write(tmp_path, document))


def test_free_objects_keep_any_key(tmp_path, document):
    document["provenance"] = {"anything": {"nested": 1}}
    assert load_model(_write(tmp_path, document)).unit == "SN-1"


@pytest.mark.parametrize("section", ["drift", "thermometer"])
def test_a_missing_section_is_named(tmp_path, document, section):
    """It was "invalid at (top level): {'schema': ..." quoting the document, not the key."""
    del document[section]
    with pytest.raises(ModelFileError, match=rf"at \(top level\): the required section "
                                             rf"'{section}' is missing"):
        load_model(_write(tmp_path, document))
