"""Held-out ratio to the numpy line of the corpus files, for the guarded selection and for
term sets forced on every axis (issue 27 item 4: which terms carry over on one real run).

The path of tests/test_real_corpus.py (calibrate on the first 60 % of the time, compensate
the rest, the held-out still periods' 60 s means less each period's mean) with the terms
the guarded selection keeps, then with each ``--terms`` set put in their place (the model
is refitted with those terms, the rest unchanged)::

    PYTHONPATH=src python bench/bench_corpus_terms.py vn100 --terms f f,df f,f^2 f,f^2,f^3
    PYTHONPATH=src python bench/bench_corpus_terms.py --json   # every file, guarded terms

A ratio below 1 is better than the line; the bound is the 95 % χ² interval's upper end of
:func:`real_corpus.ratio_bound`.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import warnings
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1] / "tests"


def run(real, path: Path, directory: Path, terms: tuple[str, ...] | None) -> dict:
    """Per axis: the ratio, its bound and the terms of the model (``terms``: forced)."""
    import pyarrow.parquet as pq
    from typer.testing import CliRunner

    import hrgtc.drift.fit_stages as fit_stages
    from hrgtc.cli import app

    from real_corpus import line_figures, ratio_bound, split_s

    guard = fit_stages.guard_selection

    def forced(*args, **kwargs):
        _, record = guard(*args, **kwargs)
        return terms, record

    fit_stages.guard_selection = guard if terms is None else forced
    model, output = directory / "model.json", directory / "held.parquet"
    reading = real.read(path)
    cut = split_s(reading)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # beyond the trained temperatures, by design
            for args in (["calibrate", "--drift", path, *real.args, "--holdout-fraction",
                          "0.4", "-o", model, "--force"],
                         ["compensate", path, "--model", model, *real.args, "--start",
                          f"{cut:.6f}", "-o", output, "--force"]):
                result = CliRunner().invoke(app, [str(a) for a in args])
                if result.exit_code != 0:
                    raise RuntimeError(result.output)
    finally:
        fit_stages.guard_selection = guard
    document = json.loads(model.read_text())
    table = pq.read_table(output)
    time_s = table.column("time_s").to_numpy() - reading.origin_s
    compensated = {a: table.column(f"rate_comp_dph_{a}").to_numpy() for a in "xyz"}
    figures = line_figures(reading, real.still, time_s, compensated)
    return {axis: {"ratio": f["ratio"], "bound": ratio_bound(f),
                   "terms": document["axes"][axis]["drift"]["selected"]}
            for axis, f in figures.items()}


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(TESTS))
    from real_corpus import CORPUS

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", nargs="?", default="",
                        help="start of a corpus file's name (vn100, tofupilot, cats; "
                             "default: every file)")
    parser.add_argument("--terms", nargs="*", default=[],
                        help="term sets to force, comma-separated (f,f^2,df)")
    parser.add_argument("--json", action="store_true",
                        help="one JSON line per file and term set instead of the text")
    args = parser.parse_args(argv)
    for real in (r for r in CORPUS if r.name.startswith(args.file)):
        with tempfile.TemporaryDirectory() as directory:
            path = real.unpacked(Path(directory))
            for terms in [None, *(tuple(t.split(",")) for t in args.terms)]:
                label = "guarded" if terms is None else ",".join(terms)
                rows = run(real, path, Path(directory), terms)
                if args.json:
                    print(json.dumps({"file": real.name, "terms": label, "axes": {
                        axis: {"ratio": round(row["ratio"], 4), "bound": round(row["bound"], 4),
                               "terms": list(row["terms"])} for axis, row in rows.items()}}),
                          flush=True)
                    continue
                for axis, row in rows.items():
                    print(f"{real.name} {label:>24} {axis}: {row['ratio']:.3f} "
                          f"(bound {row['bound']:.3f}) {','.join(row['terms'])}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
