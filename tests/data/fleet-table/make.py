"""Write ``table.json``: the fleet table's Arrow schema and rows of some fixed outcomes.

Run once, by the commit before the fleet table's record (its hand-written pyarrow
``SCHEMA``), to pin the table: ``PYTHONPATH=src python tests/data/fleet-table/make.py``.
``tests/fleet/test_table_record.py`` compares today's table with it.
"""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parents[2]))

from fleet_outcomes import OUTCOMES
from hrgtc.fleet.results import table

written = table(OUTCOMES)
document = {"schema": written.schema.to_string(), "rows": written.to_pylist()}
text = json.dumps(document, indent=1) + "\n"
(Path(__file__).parent / "table.json").write_text(text, encoding="utf-8")
