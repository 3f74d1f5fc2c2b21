"""Write ``tables.json``: the single-axis fleet tables as they were before the long form.

Run once, by the commit before the fleet tables became long-form (a row per unit × axis,
issue 28), to pin what a single-axis fleet's tables held:
``PYTHONPATH=src python tests/data/fleet-single-axis/make.py``. The fleet is that of
``tests/fleet/conftest.py`` (three units of seed 5 at 1 Hz and a fourth, ``s5-bad``, whose
first soak is corrupt); paths are written relative to the fleet's folder (``ROOT/...``),
the wall times left out. ``tests/fleet/test_long_form.py`` compares today's tables with it:
the same rows apart from the new ``axis`` column.
"""

import json
import shutil
import sys
import tempfile
from pathlib import Path

from hrgtc.fleet import calibrate_fleet, evaluate_fleet, simulate_fleet
from hrgtc.fleet.results import read_table
from hrgtc.settings.fleet import FleetCluster, FleetSimulation

SMALL = {"sample_rate_hz": 1.0, "soak_hours": 2.5, "ramp_hours": 2.0,
         "setpoints_c": (-20.0, 0.0, 10.0, 20.0, 40.0)}


def relative(value, root: str):
    """``value`` with the fleet folder ``root`` written ``ROOT`` (lists element-wise)."""
    if isinstance(value, str):
        return value.replace(root, "ROOT")
    if isinstance(value, list):
        return [relative(v, root) for v in value]
    return value


def rows(path: Path, root: str) -> list[dict]:
    return [{k: relative(v, root) for k, v in row.items() if k != "seconds"}
            for row in read_table(path)]


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        data = root / "data"
        simulate_fleet(data, FleetSimulation(units=3, seed=5, **SMALL),
                       cluster=FleetCluster(workers=0))
        bad = data / "s5-bad"
        shutil.copytree(data / "s5-u0000", bad)
        sorted((bad / "soaks").glob("*.parquet"))[0].write_bytes(
            b"PAR1 this is not a parquet file")
        sequential = FleetCluster(workers=0)
        calibrate_fleet(data, root / "models", cluster=sequential)
        evaluate_fleet(data, root / "models", cluster=sequential)
        document = {"calibrate": rows(root / "models" / "fleet.parquet", str(root)),
                    "evaluate": rows(root / "models" / "evaluation.parquet", str(root))}
    text = json.dumps(document, indent=1) + "\n"
    (Path(__file__).parent / "tables.json").write_text(text, encoding="utf-8")


if __name__ == "__main__":
    sys.exit(main())
