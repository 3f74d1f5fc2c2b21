"""The in-field update on an aged simulated unit (issue 29, item 4), as JSON lines.

    python bench/update_ageing.py [--days 8] [--fresh 3]

The paper-unit is calibrated in the chamber (the tests' campaign: seven 5 h soaks and a
cool-down at 2 Hz), then ages (+0.8 °/h offset, +0.015 °/h/°C slope: tests/field_ageing.py).
One field day (12 h still at 20, 5, -10, 30 °C, known input rate) updates the model; the
compensated residual (rms of 600 s means) of another day at other temperatures is compared
with the parent's and with models freshly calibrated on the aged unit (several chamber
campaigns: a fresh calibration is a random draw too). One line per field day, one per fresh
model, one summary line.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from campaign import SETPOINTS_C, make_campaign  # noqa: E402
from field_ageing import INPUT_RATE_DPH, aged_unit, field_profile  # noqa: E402

RATE_HZ = 2.0


def block_rms(model, recording, block_s=600.0):
    """rms of the compensated residual's ``block_s`` means: (rms, rms against the true law).

    The first is what a user sees (the held-out day's own noise included); the second is
    the model's error alone, against the simulator's bias law (``bias_dph``), the same
    held-out day's noise left out of every model's figure.
    """
    bias = model.drift.predict_recording(recording, model.thermometer)
    n = int(block_s * RATE_HZ)
    k = bias.size // n
    out = []
    for residual in (recording.rate_dph - INPUT_RATE_DPH - bias, recording["bias_dph"] - bias):
        out.append(float(np.sqrt(np.mean(residual[:k * n].reshape(k, n).mean(axis=1) ** 2))))
    return tuple(out)


def median_ratio_interval(a, b, draws=4000, seed=0):
    """Median(a) / median(b) and its 95 % bootstrap interval (a and b resampled apart)."""
    rng = np.random.default_rng(seed)
    a, b = np.asarray(a), np.asarray(b)
    ratios = [np.median(rng.choice(a, a.size)) / np.median(rng.choice(b, b.size))
              for _ in range(draws)]
    return (round(float(np.median(a) / np.median(b)), 3),
            [round(float(q), 3) for q in np.percentile(ratios, [2.5, 97.5])])


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--days", type=int, default=8)
    parser.add_argument("--fresh", type=int, default=3)
    args = parser.parse_args()
    from hrgtc.core.errors import UpdateRefusedError
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.simulate import simulate_files, simulate_run
    from hrgtc.simulate import standard_profiles as profiles
    from hrgtc.update import UpdateSettings

    known = UpdateSettings(input_rate_dph=INPUT_RATE_DPH)
    with tempfile.TemporaryDirectory() as folder:
        files = make_campaign(Path(folder) / "parent", "paper-unit", RATE_HZ)
        parent = calibrate(files.soaks, [files.cooldown]).model
        held_out = simulate_run(field_profile((0.0, 25.0, -15.0, 10.0), 4.0), aged_unit(),
                                sample_rate_hz=RATE_HZ, seed=9)
        old = block_rms(parent, held_out)
        fresh = []
        for k in range(args.fresh):
            where = Path(folder) / f"fresh{k}"
            seed = 21 + 10 * k
            soaks = simulate_files([profiles.soak(sp, 5.0) for sp in SETPOINTS_C],
                                   where / "soaks", "parquet", unit=aged_unit(),
                                   sample_rate_hz=RATE_HZ, seed=seed)
            cool = simulate_files([profiles.cooldown(20.0, -20.0, 5.0)], where / "cool",
                                  "parquet", unit=aged_unit(), sample_rate_hz=RATE_HZ,
                                  seed=seed + 1)
            model = calibrate([w.path for w in soaks], [cool[0].path]).model
            fresh.append(block_rms(model, held_out))
            print(json.dumps({"name": "update_ageing_fresh", "seed": seed,
                              "rms_dph": round(fresh[-1][0], 4),
                              "law_rms_dph": round(fresh[-1][1], 4)}), flush=True)
        new, refused = [], 0
        for seed in range(1, args.days + 1):
            day = simulate_run(field_profile(), aged_unit(), sample_rate_hz=RATE_HZ, seed=seed)
            start = time.perf_counter()
            try:
                result = parent.update(day, known)
            except UpdateRefusedError as exc:
                refused += 1
                new.append(old)
                print(json.dumps({"name": "update_ageing_day", "seed": seed,
                                  "refused": str(exc)}), flush=True)
                continue
            seconds = time.perf_counter() - start
            axis = result.axes[""]
            new.append(block_rms(result.model, held_out))
            print(json.dumps({
                "name": "update_ageing_day", "seed": seed, "n": len(day),
                "seconds": round(seconds, 3), "rms_dph": round(new[-1][0], 4),
                "law_rms_dph": round(new[-1][1], 4),
                "heldout_before_dph": round(axis.heldout_before_dph, 4),
                "heldout_after_dph": round(axis.heldout_after_dph, 4),
                "mahalanobis": round(axis.mahalanobis, 3),
                "jump_sigma": round(axis.jump_sigma, 3)}), flush=True)
        summary = {"name": "update_ageing", "days": len(new), "fresh": len(fresh),
                   "refused": refused}
        for k, key in enumerate(("rms", "law_rms")):
            ours, theirs = [v[k] for v in new], [v[k] for v in fresh]
            ratio, interval = median_ratio_interval(ours, theirs)
            summary |= {f"parent_{key}_dph": round(old[k], 4),
                        f"fresh_median_{key}_dph": round(float(np.median(theirs)), 4),
                        f"updated_median_{key}_dph": round(float(np.median(ours)), 4),
                        f"{key}_median_over_fresh_median": ratio,
                        f"{key}_median_over_fresh_median_ci95": interval,
                        f"{key}_days_below_parent": int(sum(v < old[k] for v in ours))}
        print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
