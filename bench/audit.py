"""The reliability audit of issue 21: ≥ 600 corrupted recordings and ≥ 70 corrupted models.

    python bench/audit.py                 # everything (about half an hour on 2 cores)
    python bench/audit.py --sample 40     # every 15th case or so: a quick look
    python bench/audit.py --family "axis dropped" --command compensate

Each case of ``tests/corruptions.py`` (recordings) and ``tests/model_corruptions.py``
(models) is written into a temporary folder and run in-process through ``info``,
``compensate``, ``evaluate``, ``calibrate --thermometer sensor`` (recordings) or
``compensate``, ``evaluate``, ``export-c`` (C and ``--format params``) and ``report``
(models); ``tests/auditing.py`` sorts each outcome into clear error, accepted and correct,
misleading error, silent wrong (the documented undetectable ones counted apart) or
traceback. The counts are printed per command, then every outcome that is neither clear
nor correct with the engineer who owns its class.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from auditing import Audit
from corruptions import Material, recording_cases
from model_corruptions import model_cases


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sample", type=int, default=0,
                        help="run about this many cases, evenly spread (0: all)")
    parser.add_argument("--family", default="", help="only the cases of this family")
    parser.add_argument("--command", action="append", help="only this command (repeat)")
    parser.add_argument("--models-only", action="store_true")
    parser.add_argument("--recordings-only", action="store_true")
    args = parser.parse_args()
    cases = ([] if args.models_only else recording_cases()) + (
        [] if args.recordings_only else model_cases())
    print(f"corpus: {len(recording_cases())} recordings, {len(model_cases())} models")
    if args.family:
        cases = [c for c in cases if c.family == args.family]
    if args.sample and args.sample < len(cases):
        step = len(cases) / args.sample
        cases = [cases[int(i * step)] for i in range(args.sample)]
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="hrgtc-audit-") as folder:
        audit = Audit(Material(Path(folder) / "material"), Path(folder) / "work")
        for i, case in enumerate(cases, start=1):
            audit.run(case, args.command)
            if i % 25 == 0:
                print(f"  {i}/{len(cases)} cases, {time.perf_counter() - start:.0f} s",
                      file=sys.stderr)
        print(f"{len(cases)} cases in {time.perf_counter() - start:.0f} s")
        print(audit.render())
    return 0


if __name__ == "__main__":
    sys.exit(main())
