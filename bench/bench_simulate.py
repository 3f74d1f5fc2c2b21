"""Simulate a soak campaign to Parquet: 7 soaks x 5 h x 200 Hz = 25.2 M samples.

:func:`hrgtc.simulate.simulate_files` on the paper's campaign (set-points -20
... 40 °C, Table 1 of the paper), ``paper-unit``, written chunk by chunk to a
temporary directory. Reported: seconds, samples per second (targets >= 3 M/s),
peak RSS (target < 1 GB: memory must not grow with duration), and the bytes
written. ``quick`` simulates one 0.5 h soak.

Run alone with ``python bench/bench_simulate.py [--quick]`` or through ``bench/run.py``.
"""

from __future__ import annotations

import json
import resource
import sys
import tempfile
import time
from pathlib import Path

from hrgtc import simulate

SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)
RATE_HZ = 200.0
SEED = 20120515


def _peak_rss_mb() -> float:
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)


def run(quick: bool = False) -> list[dict]:
    """Time the campaign; one result dict."""
    runs = simulate.soak_campaign(SETPOINTS_C[:1] if quick else SETPOINTS_C, 0.5 if quick else 5.0)
    with tempfile.TemporaryDirectory(prefix="hrgtc-bench-") as directory:
        start = time.perf_counter()
        written = simulate.simulate_files(runs, directory, sample_rate_hz=RATE_HZ, seed=SEED)
        seconds = time.perf_counter() - start
        size = sum(Path(w.path).stat().st_size for w in written)
    n = sum(w.rows for w in written)
    return [
        {
            "name": "simulate_soaks_parquet",
            "n": n,
            "seconds": round(seconds, 3),
            "rate": round(n / seconds),
            "peak_rss_mb": _peak_rss_mb(),
            "files": len(written),
            "bytes": size,
            "target_rate": 3_000_000,
            "target_peak_rss_mb": 1024,
        }
    ]


if __name__ == "__main__":
    for line in run(quick="--quick" in sys.argv[1:]):
        print(json.dumps(line), flush=True)
