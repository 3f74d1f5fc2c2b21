"""Write ``units.json``: the simulator's ground truth of every standard unit (``to_dict``).

Run once, by the commit before the simulator's records (c8c688c), to pin the layout:
``PYTHONPATH=src python tests/data/simulate-truth/make.py``. The test compares today's
text with it byte for byte (tests/simulate/test_truth_records.py).
"""

import json
from pathlib import Path

from hrgtc.simulate import units

truth = {name: units.get(name).to_dict() for name in units.names()}
text = json.dumps(truth, indent=1) + "\n"
(Path(__file__).parent / "units.json").write_text(text, encoding="utf-8")
