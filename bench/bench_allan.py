"""Overlapping Allan deviation, octave τ at 10^7 and 10^8 samples and all τ: hrgtc vs allantools.

Ours: :func:`hrgtc.evaluation.allan.allan_deviation` (octave τ: the C module
``_allan_octave``; every τ: the fused numba kernels; no phase array either way).
Reference: ``allantools.oadev(data, rate=fs, data_type="freq", taus="octave")`` (and
``taus="all"`` on records of 1, 2 and 4·10^4 samples, N/2 τ each).
Each side runs in its own freshly spawned process (``_child.measure``) on the
same deterministic data, generated there in chunks so that the generation adds
no second copy; both are measured in the same run. Reported per size: seconds
and samples per second of each, ``speed_ratio`` (allantools / ours), peak RSS
and extra memory (peak RSS minus the input's size) of each, the kernels'
first-call time in the child (the numba kernels' loading of their cached compilation; a
fresh environment compiles for ~10 s) and the largest relative difference of the
deviations (the τ lists and term counts must be identical).

Run alone with ``python bench/bench_allan.py [--quick]`` or through ``bench/run.py``.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from _child import measure

FULL_SIZES = (10_000_000, 100_000_000)
QUICK_SIZES = (1_000_000,)
ALL_SIZES = (10_000, 20_000, 40_000)  # every τ: N/2 of them, O(N²) work
QUICK_ALL_SIZES = (4_000,)
SAMPLE_RATE_HZ = 200.0
SEED = 20120515
_CHUNK = 1 << 20


def gyro_rate(n: int) -> np.ndarray:
    """A gyro-like rate in °/h: offset, white noise (ARW 0.01 °/√h) and a rate random walk.

    Filled chunk by chunk, so that generating it needs no memory beyond the result.
    """
    white = np.random.default_rng(SEED)
    steps = np.random.default_rng(SEED + 1)
    arw_per_sample = 0.01 * 60.0 * np.sqrt(SAMPLE_RATE_HZ)  # N [°/h·√s] · √fs
    rrw_per_sample = 0.05 / 60.0 / np.sqrt(SAMPLE_RATE_HZ)  # K = 0.05 °/h/√h
    rate = np.empty(n)
    walk = 0.0
    for start in range(0, n, _CHUNK):
        part = rate[start : start + _CHUNK]
        step = steps.standard_normal(part.size)
        step *= rrw_per_sample
        np.cumsum(step, out=step)
        step += walk
        walk = float(step[-1])
        part[:] = white.standard_normal(part.size)
        part *= arw_per_sample
        part += step
        part += 12.0  # Earth-rate component and bias
    return rate


def _ours(n: int, taus: str = "octave", repeats: int = 1) -> dict:
    from hrgtc.evaluation.allan import allan_deviation

    t0 = time.perf_counter()
    allan_deviation(gyro_rate(1000), SAMPLE_RATE_HZ, taus=taus)  # load (or compile) kernels
    first_call = time.perf_counter() - t0
    rate = gyro_rate(n)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = allan_deviation(rate, SAMPLE_RATE_HZ, taus=taus, overlapping=True)
        times.append(time.perf_counter() - t0)
    seconds = float(np.median(times))
    return {"taus_s": result.taus_s.tolist(), "deviation": result.deviation.tolist(),
            "counts": result.counts.tolist(), "seconds": seconds, "first_call": first_call}


def _allantools(n: int, taus: str = "octave", repeats: int = 1) -> dict:
    import allantools

    rate = gyro_rate(n)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        found, dev, _, counts = allantools.oadev(
            rate, rate=SAMPLE_RATE_HZ, data_type="freq", taus=taus
        )
        times.append(time.perf_counter() - t0)
    seconds = float(np.median(times))
    return {"taus_s": found.tolist(), "deviation": dev.tolist(),
            "counts": np.asarray(counts).astype(int).tolist(), "seconds": seconds}


def _line(name: str, n: int, taus: str, repeats: int = 1) -> dict:
    """Ours and allantools on the same record with ``taus``, each in a fresh process
    (the median of ``repeats`` calls there)."""
    input_mb = n * 8 / 2**20
    ours, _, peak = measure(_ours, n, taus, repeats)
    ref, _, ref_peak = measure(_allantools, n, taus, repeats)
    same_taus = ref["taus_s"] == ours["taus_s"] and ref["counts"] == ours["counts"]
    rel = (np.abs(np.asarray(ours["deviation"]) / np.asarray(ref["deviation"]) - 1.0)
           if same_taus else [np.nan])
    return {
        "name": name,
        "n": n,
        "seconds": round(ours["seconds"], 3),
        "rate": round(n / ours["seconds"]),
        "peak_rss_mb": peak,
        "extra_mb": round(peak - input_mb, 1),
        "input_mb": round(input_mb, 1),
        "n_taus": len(ours["taus_s"]),
        "first_call_seconds": round(ours["first_call"], 3),
        "allantools_seconds": round(ref["seconds"], 3),
        "allantools_rate": round(n / ref["seconds"]),
        "allantools_peak_rss_mb": ref_peak,
        "allantools_extra_mb": round(ref_peak - input_mb, 1),
        "repeats": repeats,
        "speed_ratio": round(ref["seconds"] / ours["seconds"], 2),
        "same_taus": same_taus,
        "max_rel_diff": float(np.max(rel)),
    }


def run(quick: bool = False) -> list[dict]:
    """One result per size and τ spacing: ours vs allantools on the same record.

    Octave τ at 10^7 and 10^8 samples; every τ (``taus="all"``, O(N²)) on records
    short enough for allantools to finish in seconds.
    """
    results = [_line("allan_oadev_octave", n, "octave", repeats=3 if n <= 10**7 else 1)
               for n in (QUICK_SIZES if quick else FULL_SIZES)]
    results += [_line("allan_oadev_all_taus", n, "all", repeats=5)
                for n in (QUICK_ALL_SIZES if quick else ALL_SIZES)]
    return results


if __name__ == "__main__":
    for line in run(quick="--quick" in sys.argv[1:]):
        print(json.dumps(line), flush=True)
