"""The published JSON Schemas stay as they are unless a change is meant.

Each schema hrgtc publishes (the model file's, the ``--json`` documents of calibrate and
evaluate, an evaluation, a thermometer prior, a scale-factor model, a fleet table's row)
is generated from the results' declarations (:mod:`hrgtc.core.records`); a change to a
result's fields changes it. The SHA-256 of each one's canonical JSON is pinned here: a
change that is meant updates the figure, with its reason in the commit message.

Last change (issue 28, item 2: the results declare their records): the ``description``
of six definitions generated from their results (``StepwiseRecord``, ``StepRecord``,
``OLSResultRecord``, ``CrossValidationRecord``, ``ScaleGroupRecord``,
``TrainingStatisticsRecord``) is now "The record of :class:`X` (its ``to_dict``,
``from_dict``)."; every type, bound, default, required field and definition name is
as before.
"""

from __future__ import annotations

import hashlib
import json

import pytest

from hrgtc.drift.scale_factor import SCALE_FACTOR_JSON_SCHEMA
from hrgtc.evaluation.evaluation_result import evaluation_json_schema
from hrgtc.fleet.results import row_json_schema
from hrgtc.model_schema import MODEL_SCHEMA
from hrgtc.pipeline.documents import calibrate_json_schema, evaluate_json_schema
from hrgtc.thermometry.prior import PRIOR_JSON_SCHEMA

SCHEMAS = {
    "model": lambda: MODEL_SCHEMA,
    "calibrate": calibrate_json_schema,
    "evaluate": evaluate_json_schema,
    "evaluation": evaluation_json_schema,
    "prior": lambda: PRIOR_JSON_SCHEMA,
    "scale_factor": lambda: SCALE_FACTOR_JSON_SCHEMA,
    "fleet_row": row_json_schema,
}
PINNED = {
    # model: + the optional settings gradient_saturation_c and play_width_c of the history
    # variables gsat and play (docs/history.md; written only by a model that uses them)
    "model": "34703cb6dae23cb34419db6c7d4c688640f5d5dcf26642b5ff145bbd6246da3f",
    "calibrate": "3feb7ee4e3340125520d501187eb664dde638b270a4dd9000fff8bdb33f09204",
    "evaluate": "c9c03afd3898465a481e56641354e86ba22feaf297a02471b1fba15aaa65c9c5",
    "evaluation": "8fba06d9309193c8af030c809a9c2a9999b7e8b5de117708bd08fdd25f789419",
    "prior": "37d07ada9724ef0a0054dd0c4e422175b9bc2e07827abf95271859b30f091fe4",
    "scale_factor": "a67300581f757b5e8dd1ea8f80429bd0a7760d8d7c5e2e244ff4f338e675a520",
    "fleet_row": "26424be7a0dcfd1d8078c13b2647b627a8505b383929104570880e3c58bc29b6",
}


@pytest.mark.parametrize("name", SCHEMAS)
def test_a_published_schema_is_unchanged(name):
    text = json.dumps(SCHEMAS[name](), sort_keys=True, ensure_ascii=False)
    assert hashlib.sha256(text.encode("utf-8")).hexdigest() == PINNED[name]
