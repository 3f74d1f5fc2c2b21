"""Write ``inputs.json``: the ``to_dict`` of the simulator's inputs (``tests/simulate_inputs.py``).

Run once, by the commit before their records, to pin the text:
``PYTHONPATH=src python tests/data/simulate-truth/make_inputs.py``. The test compares
today's text with it byte for byte (tests/simulate/test_input_records.py).
"""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[2]))

from simulate_inputs import documents

text = json.dumps(documents(), indent=1) + "\n"
(Path(__file__).parent / "inputs.json").write_text(text, encoding="utf-8")
