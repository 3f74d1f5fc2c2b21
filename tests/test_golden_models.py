"""Golden model files of every released schema version still load and export the same C.

Truth: real files written by the commits named in their file names (see
``tests/data/golden-models/README.md``), and the outputs committed beside them
(:mod:`golden_models`): the C export and the parameter file, byte for byte, and the
file's parameters as today's code writes them.
"""

from __future__ import annotations

import json

import pytest

from golden_models import EXPORTS, expected_dir, export, golden_files, refusal, resaved
from hrgtc.model import load_model
from hrgtc.model_schema import SCHEMA_VERSION

FILES = golden_files()
IDS = [f"{p.parent.name}/{p.stem}" for p in FILES]


def test_every_released_schema_version_has_golden_files():
    versions = {json.loads(p.read_text())["schema_version"] for p in FILES}
    assert versions == set(range(1, SCHEMA_VERSION + 1))
    for path in FILES:  # each file sits in the folder of its version
        assert path.parent.name == f"v{json.loads(path.read_text())['schema_version']}"


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_golden_file_loads(path):
    document = json.loads(path.read_text())
    model = load_model(path)
    names = sorted(document.get("axes", {"": None}))
    assert sorted(model.names) == names
    assert model.unit == document["unit"]
    if names == [""]:
        assert load_model(path).drift.selected == tuple(document["drift"]["selected"])
    for name, axis in model.axes.items():
        part = document["axes"][name] if name else document
        assert list(axis.drift.selected) == part["drift"]["selected"]
        assert axis.drift.intercept_dph == part["drift"]["intercept_dph"]
        assert list(axis.thermometer.scaled_coefficients) == (
            part["thermometer"]["scaled_coefficients"])
        assert (axis.scale_factor is None) == (part.get("scale_factor") is None)
    assert (model.temperature_map is None) == (document.get("temperature_map") is None)


@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_golden_file_written_again_as_before(path):
    """Today's serialisation of the loaded file is the committed one, byte for byte."""
    expected = (expected_dir(path) / "model.json").read_text(encoding="utf-8")
    assert resaved(path) == expected


@pytest.mark.parametrize("kind", sorted(EXPORTS))
@pytest.mark.parametrize("path", FILES, ids=IDS)
def test_golden_file_exports_the_same_bytes(path, kind, tmp_path):
    expected = expected_dir(path) / kind
    code, output = export(path, kind, tmp_path / "out")
    if (expected / "refused.txt").exists():
        assert code != 0
        assert refusal(output, path) == (expected / "refused.txt").read_text(encoding="utf-8")
        return
    assert code == 0, output
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == sorted(p.name for p in expected.iterdir())
    for name in written:
        assert (tmp_path / "out" / name).read_bytes() == (expected / name).read_bytes(), name
