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
    bias = model.drift.predict_recording(recording, model.thermometer)
    residual = recording.rate_dph - INPUT_RATE_DPH - bias
    n = int(block_s * RATE_HZ)
    k = residual.size // n
    return float(np.sqrt(np.mean(residual[:k * n].reshape(k, n).mean(axis=1) ** 2)))


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--days", type=int, default=8)
    parser.add_argument("--fresh", type=int, default=3)
    args = parser.parse_args()
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
                              "rms_dph": round(fresh[-1], 4)}), flush=True)
        new = []
        for seed in range(1, args.days + 1):
            day = simulate_run(field_profile(), aged_unit(), sample_rate_hz=RATE_HZ, seed=seed)
            start = time.perf_counter()
            result = parent.update(day, known)
            seconds = time.perf_counter() - start
            axis = result.axes[""]
            new.append(block_rms(result.model, held_out))
            print(json.dumps({
                "name": "update_ageing_day", "seed": seed, "n": len(day),
                "seconds": round(seconds, 3), "rms_dph": round(new[-1], 4),
                "heldout_before_dph": round(axis.heldout_before_dph, 4),
                "heldout_after_dph": round(axis.heldout_after_dph, 4),
                "mahalanobis": round(axis.mahalanobis, 3),
                "jump_sigma": round(axis.jump_sigma, 3)}), flush=True)
        print(json.dumps({
            "name": "update_ageing", "parent_rms_dph": round(old, 4),
            "fresh_rms_dph": [round(v, 4) for v in fresh],
            "updated_median_rms_dph": round(float(np.median(new)), 4),
            "median_over_fresh_median": round(float(np.median(new) / np.median(fresh)), 3),
            "days_below_parent": int(sum(v < old for v in new)), "days": len(new)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
