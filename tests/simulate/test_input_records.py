"""The simulator's inputs through their records: the same JSON text as before them.

Truth: ``tests/data/simulate-truth/inputs.json``, written by the commit before the
records (``make_inputs.py`` beside it) from ``tests/simulate_inputs.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import simulate_inputs

TRUTH = Path(__file__).parents[1] / "data" / "simulate-truth" / "inputs.json"


def test_every_input_writes_the_same_text_as_before():
    expected = TRUTH.read_text(encoding="utf-8")
    assert json.dumps(simulate_inputs.documents(), indent=1) + "\n" == expected
