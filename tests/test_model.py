"""Tests of hrgtc.model: the versioned model file."""

from __future__ import annotations

import json

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.core.errors import ModelFileError, OutputExistsError
from hrgtc.model import SCHEMA_VERSION, AxisModel, Model, load_model, provenance, save_model

from synthetic import THERMOMETER, ramp_run


@pytest.fixture(scope="module")
def unit_model():
    return Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([ramp_run(seed=11, hours=3.0)],
            THERMOMETER)), unit="SN-001")


def test_round_trip_is_exact(tmp_path, unit_model):
    path = save_model(unit_model, tmp_path / "unit.json")
    again = load_model(path)
    assert again.thermometer == unit_model.thermometer
    assert again.drift.selected == unit_model.drift.selected
    values = {"f": np.linspace(-10, 5, 7), "df": np.linspace(-1e-3, 1e-3, 7)}
    np.testing.assert_array_equal(again.drift.predict(values), unit_model.drift.predict(values))
    assert again.unit == "SN-001"


def test_never_overwrites_without_force(tmp_path, unit_model):
    path = save_model(unit_model, tmp_path / "unit.json")
    before = path.read_text()
    with pytest.raises(OutputExistsError, match=r"unit.json exists; pass --force"):
        save_model(unit_model, path)
    assert path.read_text() == before
    save_model(unit_model, path, force=True)
    assert list(tmp_path.iterdir()) == [path]  # no temporary file left behind


def test_foreign_corrupt_and_newer_files(tmp_path, unit_model):
    foreign = tmp_path / "foreign.json"
    foreign.write_text(json.dumps({"hello": "world"}))
    with pytest.raises(ModelFileError, match=r"foreign.json: not an hrgtc model file"):
        load_model(foreign)
    garbage = tmp_path / "garbage.json"
    garbage.write_text("{not json")
    with pytest.raises(ModelFileError, match=r"garbage.json: not a JSON document \(line 1"):
        load_model(garbage)
    data = unit_model.to_dict()
    newer = tmp_path / "newer.json"
    newer.write_text(json.dumps({**data, "schema_version": SCHEMA_VERSION + 1}))
    with pytest.raises(ModelFileError, match=rf"version {SCHEMA_VERSION + 1} is newer than .* "
                       rf"\({SCHEMA_VERSION}\); upgrade"):
        load_model(newer)
    broken = tmp_path / "broken.json"
    del data["drift"]["selected"]
    broken.write_text(json.dumps(data))
    with pytest.raises(ModelFileError, match=r"broken.json: model file is invalid at drift: "
                       r"Object missing required field `selected`"):
        load_model(broken)
    with pytest.raises(ModelFileError, match="no such model file"):
        load_model(tmp_path / "missing.json")


def test_provenance_hashes_inputs(tmp_path):
    data = tmp_path / "run.csv"
    data.write_bytes(b"abc")
    record = provenance({"drift": [str(data)]}, {"window_s": 10})
    # SHA-256 of b"abc" (FIPS 180-2, appendix B.1)
    assert record["inputs"][0]["sha256"] == (
        "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
    )
    assert record["settings"] == {"window_s": 10}


def test_written_file_has_ordinary_permissions(tmp_path, unit_model):
    import os

    old = os.umask(0o022)
    try:
        path = save_model(unit_model, tmp_path / "unit.json")
    finally:
        os.umask(old)
    assert path.stat().st_mode & 0o777 == 0o644


def test_round_trip_of_a_model_with_d2_g_and_an_extra_channel(tmp_path):
    # issue 12: the second rate filter, the gradient and --aux channels pass the schema and
    # the integrity checks and come back exactly
    from synthetic import LAGGED_TERMS, lagged_model, lagged_run

    model = lagged_model()
    assert set(model.drift.selected) == set(LAGGED_TERMS)
    again = load_model(save_model(model, tmp_path / "unit.json"))
    assert again.drift.settings == model.drift.settings
    assert again.drift.settings.aux_columns == {"drive": "drive_v"}
    assert again.drift.settings.rate_tau2_s == 120.0
    run = lagged_run(seed=9, start_c=25.0, end_c=-25.0, hours=1.0)
    np.testing.assert_array_equal(again.drift.predict_recording(run, THERMOMETER),
                                  model.drift.predict_recording(run, THERMOMETER))
    text = json.loads((tmp_path / "unit.json").read_text())
    text["drift"]["settings"]["aux_columns"] = {"drive": 3}
    (tmp_path / "bad.json").write_text(json.dumps(text))
    with pytest.raises(ModelFileError, match="aux_columns"):
        load_model(tmp_path / "bad.json")
