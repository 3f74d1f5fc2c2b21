"""Term selection against a plain line, held out, on simulated bursts (issue 20, item 13).

A MEMS axis at rest cooling 25 -> 5 °C (cosine ramp) over 4 h at 10 Hz, its sensor as
thermometer, cut to 5 s bursts every 60 s (the simulation of tests/test_against_a_line.py,
with the random walk's step as a parameter). Bias [°/h] = 14400 + 36 (T − 15)
+ curve (T − 15)², white noise of 60 °/h per sample and a random walk of ``walk`` °/h per
sample. hrgtc (``drift.fit``, default guarded selection) and a numpy line ``a + b·T`` are
trained on the first 60 % of the time and held out on the rest; the figure is the spread
(ddof 1) of the held-out burst means after the df/dt filter's warm-up (the evaluation's
10 s bias stability of 5 s bursts). The line's interval is the χ² one of
:func:`hrgtc.evaluation.metrics.bias_stability_interval` (68.3 %).

For each (walk, curve) it counts the seeds where hrgtc lies above the line's interval
(worse), below it (better), and the worst ratio hrgtc / line::

    PYTHONPATH=src python bench/bench_selection.py [--seeds 12] [--jsonl out.jsonl]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings

import numpy as np

WALKS = (0.03, 0.1, 0.3)  # °/h per 10 Hz sample
CURVES = (0.0, 0.5)  # °/h/°C²
TRAINED = 0.6


def simulated_bursts(seed: int, curve: float, walk: float, hours: float = 4.0):
    """The bursts of tests/test_against_a_line.py with a random walk of ``walk`` per sample."""
    from hrgtc.recording import Metadata, Recording

    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 0.1)
    temperature = 25.0 - 20.0 * (1.0 - np.cos(np.pi * t / t[-1])) / 2.0
    bias = 14400.0 + 36.0 * (temperature - 15.0) + curve * (temperature - 15.0) ** 2
    rate = bias + 60.0 * rng.standard_normal(t.size) + np.cumsum(walk * rng.standard_normal(t.size))
    keep = np.mod(t - t[0], 60.0) < 5.0 - 1e-9
    columns = {"time_s": t, "freq_hz": temperature, "rate_dph": rate, "bias_dph": bias}
    return Recording({n: v[keep] for n, v in columns.items()},
                     Metadata(sample_rate_hz=10.0, unit="mems"), source=f"bursts-{seed}")


def _burst_means(time_s: np.ndarray, values: np.ndarray, from_s: float) -> np.ndarray:
    burst = np.r_[0, np.cumsum(np.diff(time_s) > 1.0)]
    means = np.bincount(burst, values) / np.bincount(burst)
    starts = time_s[np.r_[0, np.flatnonzero(np.diff(burst)) + 1]]
    return means[starts >= from_s]


def held_out(seed: int, curve: float, walk: float) -> dict:
    """hrgtc, the line, raw (held-out burst-mean spreads, °/h), N and hrgtc's terms."""
    from hrgtc import drift
    from hrgtc.recording import Recording
    from hrgtc.thermometry import identity

    thermometer = identity((-20.0, 50.0))
    run = simulated_bursts(seed, curve, walk)
    t = run.time_s
    cut = t[0] + TRAINED * (t[-1] - t[0])

    def part(mask):
        return Recording({n: run[n][mask] for n in run.names}, run.metadata, source="part")

    train, held = part(t < cut), part(t >= cut)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # beyond the trained temperatures, by design
        model = drift.fit([train], thermometer)
        predicted = model.predict_recording(held)
    from_s = held.time_s[0] + model.settings.warmup_s
    slope, intercept = np.polyfit(train["freq_hz"], train.rate_dph, 1)
    line = _burst_means(held.time_s, held.rate_dph - (intercept + slope * held["freq_hz"]), from_s)
    ours = _burst_means(held.time_s, held.rate_dph - predicted, from_s)
    raw = _burst_means(held.time_s, held.rate_dph, from_s)
    return {"seed": seed, "curve": curve, "walk": walk, "n": int(line.size),
            "line": float(np.std(line, ddof=1)), "hrgtc": float(np.std(ours, ddof=1)),
            "raw": float(np.std(raw, ddof=1)), "terms": list(model.selected),
            "dropped": list((model.pruning or {}).get("dropped", []))}


def main(argv: list[str] | None = None) -> int:
    from hrgtc.evaluation.metrics import bias_stability_interval

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=12)
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--walks", type=float, nargs="+", default=WALKS)
    parser.add_argument("--curves", type=float, nargs="+", default=CURVES)
    parser.add_argument("--jsonl", help="write every case as a JSON line")
    parser.add_argument("-v", "--verbose", action="store_true", help="print every case")
    args = parser.parse_args(argv)
    seeds = range(args.first_seed, args.first_seed + args.seeds)
    out = open(args.jsonl, "w", encoding="utf-8") if args.jsonl else None
    print(f"{'walk':>5} {'curve':>5} | {'worse':>5} {'within':>6} {'better':>6} | "
          f"{'worst ratio':>11} {'median ratio':>12} | above raw | terms beyond f")
    start = time.perf_counter()
    for walk in args.walks:
        for curve in args.curves:
            rows = []
            for seed in seeds:
                row = held_out(seed, curve, walk)
                low, high = bias_stability_interval(row["line"], row["n"])
                row["low"], row["high"] = low, high
                row["verdict"] = ("worse" if row["hrgtc"] > high else
                                  "better" if row["hrgtc"] < low else "within")
                rows.append(row)
                if out:
                    out.write(json.dumps(row) + "\n")
                if args.verbose:
                    print(f"    seed {seed:3d}: hrgtc {row['hrgtc']:7.2f} line {row['line']:7.2f}"
                          f" ({low:6.2f}-{high:6.2f}) raw {row['raw']:7.1f} {row['verdict']:6s}"
                          f" {','.join(row['terms'])}", flush=True)
            ratio = np.array([r["hrgtc"] / r["line"] for r in rows])
            count = {v: sum(r["verdict"] == v for r in rows) for v in ("worse", "within", "better")}
            above_raw = sum(r["hrgtc"] > r["raw"] for r in rows)
            richer = sum(bool(set(r["terms"]) - {"f"}) for r in rows)
            print(f"{walk:5.2f} {curve:5.1f} | {count['worse']:5d} {count['within']:6d} "
                  f"{count['better']:6d} | {ratio.max():11.2f} {np.median(ratio):12.2f} | "
                  f"{above_raw:9d} | {richer}/{len(rows)}", flush=True)
    if out:
        out.close()
    print(f"({time.perf_counter() - start:.0f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
