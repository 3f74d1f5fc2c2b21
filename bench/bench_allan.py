"""Overlapping Allan deviation (octave taus) of 25 M rate samples: hrgtc vs allantools.

Ours: :func:`hrgtc.evaluation.metrics.allan_deviation` (cumulative sum, then one cache-blocked
pass per τ). Reference: ``allantools.oadev(data, rate=fs, data_type="freq",
taus="octave")``, run in its own subprocess on the same deterministic data so
that its memory does not count against ours. Reported: seconds, samples per
second, peak RSS of each, speed ratio and the largest relative difference of
the deviations (the τ lists must be identical).

Run alone with ``python bench/bench_allan.py [--quick]`` or through ``bench/run.py``.
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

FULL_SAMPLES = 25_000_000
QUICK_SAMPLES = 1_000_000
SAMPLE_RATE_HZ = 200.0
SEED = 20120515


def _peak_rss_mb() -> float:
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, 1)


def gyro_rate(n: int) -> np.ndarray:
    """A gyro-like rate in °/h: offset, white noise (ARW 0.01 °/√h) and a rate random walk."""
    rng = np.random.default_rng(SEED)
    arw_per_sample = 0.01 * 60.0 * np.sqrt(SAMPLE_RATE_HZ)  # N [°/h·√s] · √fs
    rate = rng.standard_normal(n)
    rate *= arw_per_sample
    walk = rng.standard_normal(n)
    walk *= 0.05 / 60.0 / np.sqrt(SAMPLE_RATE_HZ)  # K = 0.05 °/h/√h
    np.cumsum(walk, out=walk)
    rate += walk
    rate += 12.0  # Earth-rate component and bias
    return rate


def _allantools_child(n: int) -> None:
    """Child process: allantools on the same data, JSON on stdout."""
    import allantools

    rate = gyro_rate(n)
    t0 = time.perf_counter()
    taus, dev, _, counts = allantools.oadev(
        rate, rate=SAMPLE_RATE_HZ, data_type="freq", taus="octave"
    )
    seconds = time.perf_counter() - t0
    out = {
        "taus_s": taus.tolist(),
        "deviation": dev.tolist(),
        "counts": np.asarray(counts).tolist(),
        "seconds": seconds,
        "peak_rss_mb": _peak_rss_mb(),
    }
    print(json.dumps(out))


def run(quick: bool = False) -> list[dict]:
    """One result: ours vs allantools on the same record."""
    from hrgtc.evaluation.metrics import allan_deviation

    n = QUICK_SAMPLES if quick else FULL_SAMPLES
    t0 = time.perf_counter()
    rate = gyro_rate(n)
    generate_seconds = time.perf_counter() - t0
    t0 = time.perf_counter()
    ours = allan_deviation(rate, SAMPLE_RATE_HZ, taus="octave", overlapping=True)
    seconds = time.perf_counter() - t0
    peak = _peak_rss_mb()
    del rate

    child = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--allantools-child", str(n)],
        capture_output=True,
        text=True,
        check=True,
    )
    ref = json.loads(child.stdout.strip().splitlines()[-1])
    same_taus = ref["taus_s"] == ours.taus_s.tolist() and ref["counts"] == ours.counts.tolist()
    rel = np.abs(ours.deviation / np.asarray(ref["deviation"]) - 1.0) if same_taus else [np.nan]
    return [
        {
            "name": "allan_oadev_octave",
            "n": n,
            "seconds": round(seconds, 3),
            "rate": round(n / seconds),
            "peak_rss_mb": peak,
            "n_taus": int(ours.taus_s.size),
            "generate_seconds": round(generate_seconds, 3),
            "allantools_seconds": round(ref["seconds"], 3),
            "allantools_rate": round(n / ref["seconds"]),
            "allantools_peak_rss_mb": ref["peak_rss_mb"],
            "speed_ratio": round(ref["seconds"] / seconds, 2),
            "same_taus": same_taus,
            "max_rel_diff": float(np.max(rel)),
        }
    ]


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--allantools-child":
        _allantools_child(int(sys.argv[2]))
    else:
        for line in run(quick="--quick" in sys.argv[1:]):
            print(json.dumps(line), flush=True)
