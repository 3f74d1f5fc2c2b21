"""Do ``hrgtc compensate``'s outputs stay the same, byte for byte, before and after a change?

    python bench/check_compensate_unchanged.py BEFORE_SRC AFTER_SRC WORK_DIR [--rows N]

``BEFORE_SRC`` and ``AFTER_SRC`` are ``src`` folders (``git archive COMMIT src | tar -x -C
/tmp/before``); each ``hrgtc compensate`` runs as a fresh process on each, with the default
options and with ``--motion keep``, on

* the file ``bench/bench_commands.py`` times (a 14 h warm-up at 200 Hz, 10 M rows; ``--rows``
  takes its first N) and its model, made in ``WORK_DIR`` once (kept for the next call);
* a copy of its first 2 M rows with 8 handling bursts of 5 s (its metadata's input rate of
  10 °/h kept), so that some samples are flagged not at rest;
* each real recording of ``tests/real_corpus.py``, whole, with a model calibrated by
  ``BEFORE_SRC`` on its first 60 % (``--holdout-fraction 0.4``).

Prints one line per case: the exit codes, the first 16 hex digits of each output's SHA-256,
whether the outputs and the printed messages (their lines, in any order: the warnings of
the reading thread may come first or last) agree, and the samples flagged not at rest;
then ``ALL SAME`` or ``DIFFERENT`` (exit 1).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

BENCH = Path(__file__).resolve().parent
sys.path[:0] = [str(BENCH), str(BENCH.parent / "tests")]
PYTHON = sys.executable
ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}


def hrgtc(src: str, *args: object) -> tuple[int, str]:
    done = subprocess.run(
        ["env", f"PYTHONPATH={src}", PYTHON, "-c", "import sys; sys.argv[0] = 'hrgtc'; "
         "from hrgtc.cli import main; sys.exit(main())", *map(str, args)],
        capture_output=True, text=True, env=ENV)
    return done.returncode, done.stdout + done.stderr


def digest(path: Path) -> str | None:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16] if path.exists() else None


def not_at_rest(path: Path) -> dict[str, int]:
    table = pq.read_table(path)
    return {c: len(table) - int(np.count_nonzero(table.column(c).to_numpy()))
            for c in table.column_names if c.startswith("at_rest")}


def bench_file(work: Path, rows: int | None) -> tuple[Path, Path, Path]:
    """The bench line's model and run (made once), and the copy with handling."""
    from bench_compensate import _model
    from hrgtc.model import save_model
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    model, run = work / "unit.json", work / "run" / "warmup_-20C_to_20C.parquet"
    if not model.exists():
        save_model(_model(work, 200.0), str(model))
    if not run.exists():
        simulate_files([profiles.warmup(-20.0, 20.0, 14.0)], work / "run", "parquet",
                       sample_rate_hz=200.0, seed=3)
    whole = pq.read_table(run)
    if rows is not None:
        run = work / "run_head.parquet"
        pq.write_table(whole.slice(0, rows), run)
    head = whole.slice(0, 2_000_000)
    rate = head.column("rate_dph").to_numpy().copy()
    for k in range(8):  # 5 s of handling, up to 500 °/h
        start = 100_000 + k * 230_000
        rate[start:start + 1000] += 500.0 * np.sin(np.linspace(0.0, np.pi, 1000))
    handled = head.set_column(head.column_names.index("rate_dph"), "rate_dph", pa.array(rate))
    pq.write_table(handled.replace_schema_metadata(whole.schema.metadata), work / "handled.parquet")
    return model, run, work / "handled.parquet"


def main(before: str, after: str, work: Path, rows: int | None) -> bool:
    from real_corpus import CORPUS

    work.mkdir(parents=True, exist_ok=True)
    model, run, handled = bench_file(work, rows)
    cases = [("bench", run, model, ()), ("bench-handled", handled, model, ())]
    for real in CORPUS:
        path, fitted = real.unpacked(work), work / f"{real.name}.json"
        if not fitted.exists():
            code, text = hrgtc(before, "calibrate", "--drift", path, *real.args,
                               "--holdout-fraction", "0.4", "-o", fitted, "--force")
            if code:
                raise SystemExit(f"calibrate {real.name} failed: {text[-2000:]}")
        cases.append((real.name, path, fitted, real.args))
    same_all = True
    for name, path, fitted, args in cases:
        for extra in ((), ("--motion", "keep")):
            results = []
            for tag, src in (("before", before), ("after", after)):
                out = work / "out.parquet"  # one name: the messages name it, wrapped alike
                out.unlink(missing_ok=True)
                code, text = hrgtc(src, "compensate", path, "-m", fitted, *args, *extra, "-o",
                                   out, "--force")
                kept = work / f"{name}-{tag}{'-keep' if extra else ''}.parquet"
                if out.exists():
                    out.replace(kept)
                results.append((code, digest(kept) if code == 0 else None,
                                sorted(text.splitlines()), kept))
            (code0, sha0, text0, _), (code1, sha1, text1, out1) = results
            same = code0 == code1 and sha0 == sha1 and sha0 is not None
            same_all &= same
            flagged = not_at_rest(out1) if code1 == 0 else None
            print(f"{name:24s} {' '.join(extra) or 'default':14s} exit {code0}/{code1} "
                  f"sha {sha0} {sha1} same={same} messages_same={text0 == text1} "
                  f"not_at_rest={flagged}", flush=True)
    print("ALL SAME" if same_all else "DIFFERENT")
    return same_all


if __name__ == "__main__":
    argv = sys.argv[1:]
    head_rows = int(argv[argv.index("--rows") + 1]) if "--rows" in argv else None
    sys.exit(0 if main(argv[0], argv[1], Path(argv[2]), head_rows) else 1)
