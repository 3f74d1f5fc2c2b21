"""Write ``unit-K.json``: a population unit's ``truth.json`` as ``hrgtc fleet simulate``
writes it (seed 7, units 0-2).

Run once, by the commit before the fleet truth's record, to pin the text:
``PYTHONPATH=src python tests/data/fleet-truth/make.py``. The test compares today's text
with it byte for byte (tests/fleet/test_table_record.py).
"""

import json
from pathlib import Path

from hrgtc.fleet.population import draw_unit, truth

for k in range(3):
    text = json.dumps(truth(*draw_unit(7, k)), indent=1) + "\n"
    (Path(__file__).parent / f"unit-{k}.json").write_text(text, encoding="utf-8")
