"""Run many fuzz cases (issue 11) and print the counts: cases, clear errors, correct results.

    python bench/fuzz_report.py --cases 400

Each case is one random corruption (see ``tests/fuzzing.py``) of a valid CSV or Parquet
recording or of a valid model file, given to ``hrgtc compensate`` in-process. Anything
that is neither a clear error (exit 2, one line naming the file) nor a correct result is
listed with its corruption.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import warnings
from collections import Counter
from pathlib import Path

from hypothesis import HealthCheck, Phase, given, seed, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from fuzzing import (
    Fixture,
    csv_corruption,
    judge_data,
    judge_model,
    model_corruption,
    parquet_corruption,
    write_case,
)


def run_cases(kind, strategy, judge, name, fixture, args, counts, others) -> None:
    tally = counts.setdefault(kind, Counter())

    @seed(args.seed)
    @settings(max_examples=args.cases, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck), phases=[Phase.generate])
    @given(st.data())
    def case(data):
        content, what = data.draw(strategy())
        outcome = judge(fixture, write_case(fixture.folder, name, content))
        tally[outcome.split(":")[0]] += 1
        if outcome not in ("error", "correct"):
            others.append(f"{kind}: {what}: {outcome}")

    case()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cases", type=int, default=400, help="cases per kind of input")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    counts: dict[str, Counter] = {}
    others: list[str] = []
    with tempfile.TemporaryDirectory() as folder:
        fixture = Fixture(Path(folder))
        kinds = {
            "csv": (lambda: csv_corruption(fixture.csv_text), judge_data, "case.csv"),
            "parquet": (lambda: parquet_corruption(fixture), judge_data, "case.parquet"),
            "model": (lambda: model_corruption(fixture.model_text), judge_model, "case.json"),
        }
        for kind, (strategy, judge, name) in kinds.items():
            run_cases(kind, strategy, judge, name, fixture, args, counts, others)
    total = Counter()
    for kind, tally in counts.items():
        total.update(tally)
        print(f"{kind:8s} cases {sum(tally.values()):5d}  clear errors {tally['error']:5d}  "
              f"correct results {tally['correct']:5d}  anything else {tally['other']:3d}")
    print(f"{'all':8s} cases {sum(total.values()):5d}  clear errors {total['error']:5d}  "
          f"correct results {total['correct']:5d}  anything else {total['other']:3d}")
    for line in others:
        print("  " + line)


if __name__ == "__main__":
    main()
