"""Peak RSS of ``hrgtc evaluate`` against ``hrgtc compensate`` on a long run (issue 11).

Writes a synthetic run of ``--rows`` rows (Parquet) at the model's sample rate, then
runs each command in a fresh process and reports its peak resident set size
(``ru_maxrss`` of the child). ``--python-path`` runs another checkout's library (e.g.
the code before the streamed statistics) for a before/after comparison::

    python bench/evaluate_memory.py --model unit.json --rows 20000000
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def make_run(path: Path, model_path: Path, rows: int) -> None:
    from hrgtc.model import load_model
    from hrgtc.recording import Metadata, RecordingWriter

    model = load_model(model_path)
    fs = model.drift.settings.sample_rate_hz
    low, high = model.thermometer.temperature_range_c
    rng = np.random.default_rng(1)
    metadata = Metadata(sample_rate_hz=fs, unit="bench")
    chunk = 1 << 20
    with RecordingWriter(path, metadata, ["time_s", "freq_hz", "rate_dph"], force=True) as out:
        for start in range(0, rows, chunk):
            n = min(chunk, rows - start)
            k = np.arange(start, start + n)
            temperature = 0.5 * (low + high) + 0.4 * (high - low) * np.sin(k / (fs * 20_000))
            out.write({"time_s": k / fs,
                       "freq_hz": model.thermometer.frequency(temperature)
                       + rng.normal(0, 0.002, n),
                       "rate_dph": 10.0 + 0.05 * temperature + rng.normal(0, 2.0, n)})


#: Runs the CLI and writes the process's own peak RSS [kB] to the file in argv[1].
CHILD = """
import resource, sys
report = sys.argv.pop(1)
try:
    from hrgtc.cli import main
    main()
finally:
    with open(report, "w") as out:
        out.write(str(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss))
"""


def peak_rss_mb(arguments: list[str], env: dict[str, str], report: Path) -> tuple[float, float]:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", CHILD, str(report), *arguments], check=True, env=env,
                   stdout=subprocess.DEVNULL)
    return float(report.read_text()) / 1024.0, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--model", type=Path, required=True)
    parser.add_argument("--rows", type=int, default=20_000_000)
    parser.add_argument("--python-path", default="", help="PYTHONPATH of another checkout")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        run = Path(folder) / "run.parquet"
        make_run(run, args.model, args.rows)
        env = dict(os.environ)
        if args.python_path:
            env["PYTHONPATH"] = args.python_path
        report = Path(folder) / "rss.txt"
        rss, seconds = peak_rss_mb(["compensate", str(run), "-m", str(args.model),
                                    "-o", str(Path(folder) / "out.parquet"), "--json"], env,
                                   report)
        print(f"compensate: peak RSS {rss:.0f} MB, {seconds:.1f} s ({args.rows} rows)")
        rss, seconds = peak_rss_mb(["evaluate", str(run), "-m", str(args.model), "--json"], env,
                                   report)
        print(f"evaluate:   peak RSS {rss:.0f} MB, {seconds:.1f} s ({args.rows} rows)")


if __name__ == "__main__":
    main()
