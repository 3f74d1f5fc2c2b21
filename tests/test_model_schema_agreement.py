"""The published JSON Schema and the loader agree on every model file.

The loader validates a model file once, with msgspec against the records the schema is
generated from (``model_schema.check_schema``); ``jsonschema`` is not used on loading.
Here ``jsonschema`` (Draft 2020-12, independent of msgspec) judges the published
:data:`~hrgtc.model_schema.MODEL_SCHEMA`, and both must accept and refuse alike: every
golden model file as written, and three of them (one axis with a resonator thermometer,
version 1; one with a sensor thermometer; several axes with a temperature map) with each
value (of a list, the first item) replaced by a wrong one (a string, null, a negative
number, zero, an empty list or object, in turn) or deleted, one place at a time.
"""

from __future__ import annotations

import copy
from pathlib import Path

import jsonschema
import pytest

from hrgtc.core.errors import ModelFileError
from hrgtc.model_schema import MODEL_SCHEMA, check_schema, parse_model_json, unknown_key

GOLDEN = sorted((Path(__file__).parent / "data" / "golden-models").glob("v*/*.json"))
#: What each value is replaced by (deleting it is the last change).
WRONG = ("x", None, -1, 0, [], {})
VALIDATOR = jsonschema.Draft202012Validator(MODEL_SCHEMA)


def _by_jsonschema(document) -> bool:
    """The published schema accepts the document (and it holds no key the schema lacks)."""
    if next(VALIDATOR.iter_errors(document), None) is not None:
        return False
    return unknown_key(document, MODEL_SCHEMA, ()) is None


def _by_loader(document) -> bool:
    try:
        check_schema(document, "model.json")
    except ModelFileError:
        return False
    return True


def _places(value, where=()):
    """Every place of a document, leaves and containers (not inside the free provenance;
    of a list, its first item: the others are alike)."""
    if isinstance(value, dict):
        for key, item in value.items():
            yield (*where, key)
            if key != "provenance":
                yield from _places(item, (*where, key))
    elif isinstance(value, list) and value:
        yield (*where, 0)
        yield from _places(value[0], (*where, 0))


def _changed(document, place, wrong):
    changed = copy.deepcopy(document)
    target = changed
    for key in place[:-1]:
        target = target[key]
    if wrong is _changed:
        del target[place[-1]]
    else:
        target[place[-1]] = wrong
    return changed


@pytest.mark.parametrize("path", GOLDEN, ids=[f"{p.parent.name}/{p.stem}" for p in GOLDEN])
def test_both_accept_every_golden_file(path):
    document, _ = parse_model_json(path.read_text(encoding="utf-8"))
    assert _by_jsonschema(document) and _by_loader(document)


SWEPT = [p for p in GOLDEN if p.stem in ("unit-resonator-48c2395",
                                         "unit-sensor-thermometer-ee60050",
                                         "instrument-pan-sensor-temp-map-ee60050")]


@pytest.mark.parametrize("path", SWEPT, ids=[p.stem for p in SWEPT])
def test_the_schema_and_the_loader_refuse_alike(path):
    document, _ = parse_model_json(path.read_text(encoding="utf-8"))
    changes = (*WRONG, _changed)
    disagree, refused = [], 0
    for k, place in enumerate(_places(document)):
        wrong = changes[k % len(changes)]
        if wrong is _changed and isinstance(place[-1], int):
            wrong = None  # a list's item is not deleted: the next one takes its place
        changed = _changed(document, place, wrong)
        schema, loader = _by_jsonschema(changed), _by_loader(changed)
        refused += not schema
        if schema != loader:
            shown = "deleted" if wrong is _changed else repr(wrong)
            disagree.append(f"{'.'.join(map(str, place))} = {shown}: jsonschema "
                            f"{'accepts' if schema else 'refuses'}, the loader "
                            f"{'accepts' if loader else 'refuses'}")
    assert not disagree, disagree[:20]
    assert refused > 50  # the changes are wrong enough to be refused, most of them
