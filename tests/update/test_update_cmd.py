"""``hrgtc update`` in-process: the lineage of the written file, the rollback round trip, the
original never touched, no overwrite without --force, refusals as exit 2 with the reason."""

from __future__ import annotations

import hashlib
import json

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app


def sha256(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args], terminal_width=200)


@pytest.fixture(scope="module")
def updated(parent_file, field_file, tmp_path_factory):
    """``hrgtc update parent field -o new --input-rate-dph 10`` once."""
    before = sha256(parent_file)
    output = tmp_path_factory.mktemp("updated") / "unit-2.json"
    result = invoke("update", parent_file, field_file, "-o", output, "--input-rate-dph", 10)
    assert result.exit_code == 0, result.output
    assert sha256(parent_file) == before  # the original never touched
    return output, result.output


def test_the_updated_file_carries_its_lineage(updated, parent_file, field_file):
    from hrgtc.model import load_model

    output, text = updated
    assert f"wrote {output}" in text and "rms after" in text
    model = load_model(output)  # the file passes every check of loading
    lineage = model.lineage
    assert lineage.parent_sha256 == sha256(parent_file)
    assert lineage.parent_parameters_sha256 == load_model(parent_file).sha256
    assert lineage.parent_path == str(parent_file) and lineage.parent_unit == "paper-unit"
    (data,) = lineage.data
    assert data.path == str(field_file) and data.sha256 == sha256(field_file)
    assert data.source == "motion" and len(data.intervals_s) >= 1
    (change,) = lineage.changes
    assert change.terms == ("const", "f")
    assert model.drift.intercept_dph == change.after[0]
    assert model.drift.coefficients["f"] == pytest.approx(change.after[1], rel=1e-12)
    assert lineage.settings["input_rate_dph"] == 10.0
    assert lineage.heldout_rms_after_dph < lineage.heldout_rms_before_dph
    document = json.loads(output.read_text())
    assert document["lineage"]["parent_sha256"] == sha256(parent_file)


def test_rollback_restores_the_parent_byte_for_byte(updated, parent_file, tmp_path):
    output, _ = updated
    restored = tmp_path / "restored.json"
    result = invoke("update", "--rollback", output, "-o", restored)
    assert result.exit_code == 0, result.output
    assert restored.read_bytes() == parent_file.read_bytes()
    again = invoke("update", "--rollback", output, "-o", restored)  # never without --force
    assert again.exit_code == 2 and "exists" in again.output
    assert invoke("update", "--rollback", output, "-o", restored, "--force").exit_code == 0
    assert restored.read_bytes() == parent_file.read_bytes()


def test_a_damaged_lineage_is_no_rollback(updated, tmp_path):
    output, _ = updated
    document = json.loads(output.read_text())
    content = document["lineage"]["parent_content"]
    document["lineage"]["parent_content"] = content[:-8] + "AAAAAAA="
    del document["parameters_sha256"]  # a deliberate edit
    damaged = tmp_path / "damaged.json"
    damaged.write_text(json.dumps(document))
    result = invoke("update", "--rollback", damaged, "-o", tmp_path / "out.json")
    assert result.exit_code == 2 and "no rollback" in result.output
    assert not (tmp_path / "out.json").exists()


def test_a_calibrated_model_has_nothing_to_roll_back_to(parent_file, tmp_path):
    result = invoke("update", "--rollback", parent_file, "-o", tmp_path / "out.json")
    assert result.exit_code == 2 and "not an updated model (no lineage)" in result.output


def test_the_output_is_never_an_input_nor_overwritten(parent_file, field_file, updated):
    output, _ = updated
    same = invoke("update", parent_file, field_file, "-o", parent_file, "--input-rate-dph", 10)
    assert same.exit_code == 2
    exists = invoke("update", parent_file, field_file, "-o", output, "--input-rate-dph", 10)
    assert exists.exit_code == 2 and "exists" in exists.output


def test_a_refusal_is_exit_2_naming_the_file_and_the_reason(parent_file, tmp_path):
    from hrgtc.simulate import simulate_files

    from field_ageing import field_profile

    other = simulate_files([field_profile()], tmp_path / "unit-b.parquet", unit="unit-b",
                           sample_rate_hz=2.0, seed=7)[0].path
    result = invoke("update", parent_file, other, "-o", tmp_path / "new.json",
                    "--input-rate-dph", 10)
    assert result.exit_code == 2
    assert f"{other}: recorded by unit 'unit-b'" in " ".join(result.output.split())
    assert not (tmp_path / "new.json").exists()


def test_still_intervals_and_json(parent_file, field_file, tmp_path):
    output = tmp_path / "new.json"
    result = invoke("update", parent_file, field_file, "-o", output, "--input-rate-dph", 10,
                    "--still", "3600:10800", "--still", "14400:21600", "--still",
                    "25200:32400", "--json")
    assert result.exit_code == 0, result.output
    document = json.loads(result.output)
    assert document["applied"] and document["output"] == str(output)
    names = {f["name"] for s in document["summary"]["sections"] for f in s["figures"]}
    assert {"after.const", "heldout_after_dph"} <= names
    bad = invoke("update", parent_file, field_file, "-o", tmp_path / "x.json", "--still", "5")
    assert bad.exit_code == 2 and "is not START:END" in bad.output


def test_a_recording_without_still_periods_writes_nothing(parent_file, tmp_path):
    """Motion throughout: exit 0, the summary says nothing changed, no file written."""
    import numpy as np

    from hrgtc.recording import Recording, write
    from hrgtc.simulate import simulate_run

    from field_ageing import aged_unit, field_profile

    run = simulate_run(field_profile(hold_h=1.0), aged_unit(), sample_rate_hz=2.0, seed=4)
    columns = {k: np.array(run[k]) for k in run.names}
    columns["rate_dph"] = columns["rate_dph"] + 72_000.0 * np.sin(columns["time_s"] / 5.0)
    shaken = Recording(columns, run.metadata)
    path = write(shaken, tmp_path / "moving.parquet")
    output = tmp_path / "new.json"
    result = invoke("update", parent_file, path, "-o", output, "--input-rate-dph", 10)
    assert result.exit_code == 0, result.output
    assert "no still period" in result.output and "not written" in result.output
    assert not output.exists()


def test_the_published_schema_takes_an_updated_file(updated):
    """The lineage is part of the model file's JSON Schema (jsonschema, Draft 2020-12): the
    updated file validates, and a lineage with a misspelt key or a bad hash does not."""
    import jsonschema

    from hrgtc.model_schema import MODEL_SCHEMA

    output, _ = updated
    document = json.loads(output.read_text())
    jsonschema.validate(document, MODEL_SCHEMA)
    document["lineage"]["parent_sha256"] = "not a hash"
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(document, MODEL_SCHEMA)


def test_an_edited_lineage_is_refused_on_loading(updated, tmp_path):
    """The lineage is hashed with the parameters: an edit of it is a damaged file."""
    from hrgtc.core.errors import ModelFileError
    from hrgtc.model import load_model

    output, _ = updated
    document = json.loads(output.read_text())
    document["lineage"]["parent_path"] = "elsewhere.json"
    edited = tmp_path / "edited.json"
    edited.write_text(json.dumps(document))
    with pytest.raises(ModelFileError, match="changed after it was written"):
        load_model(edited)


def test_files_of_every_schema_version_load_without_a_lineage():
    """The lineage is optional: every golden model file (versions 1 to 3, written before it
    existed) loads, has none, and writes none."""
    from golden_models import golden_files
    from hrgtc.model import load_model

    paths = golden_files()
    assert len(paths) >= 3
    for path in paths:
        model = load_model(path)
        assert model.lineage is None and "lineage" not in model.to_dict(), path
