"""A triad's offsets from |Ω| (issue 29, item 4): are the stated intervals honest? JSON lines.

    python bench/update_triad.py [--seeds 12]

The three-axis ``imu-3`` is calibrated in the chamber (seven 5 h soaks and a cool-down at
1 Hz, the tests' instrument campaign without its rate tables), then its offsets age by
+0.9, -0.7, +0.6 °/h (tests/field_ageing.py). For each seed, a field day: still at 20 °C
for 3 h in each of four orientations (level, on its side about x, on its end about y,
upside down), the Earth rate in the rates, the input rate unknown. The update's offsets
are compared with what the data call for (each intercept plus the mean of true minus
modelled bias over the still periods): one line per seed and axis would be long, so one
line per seed (the three errors in σ of the posterior) and a summary line with the share
of errors within 1, 2 and 3 σ (a Gaussian: 68 %, 95 %, 99.7 %), the median error in °/h
and the seconds per update.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import tempfile
import time
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from campaign import make_instrument_campaign  # noqa: E402
from field_ageing import at_rest_in, target_offsets  # noqa: E402

ORIENTATIONS = (0, 1, 2, 3)


def main() -> None:
    from hrgtc.pipeline.calibration import calibrate

    parser = argparse.ArgumentParser()
    parser.add_argument("--seeds", type=int, default=12)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        files = make_instrument_campaign(Path(tmp))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = calibrate(files.soaks, [files.cooldown]).model
    errors, sigmas, seconds = [], [], []
    for seed in range(1, args.seeds + 1):
        recording, still = at_rest_in(ORIENTATIONS, seed=seed)
        start = time.perf_counter()
        triad = model.update(recording, still_s=still).triad
        seconds.append(time.perf_counter() - start)
        target = target_offsets(model, recording, still)
        line = {"name": "update_triad_seed", "seed": seed,
                "condition": round(triad.condition, 2)}
        for k, axis in enumerate(triad.axes):
            sigma = math.sqrt(triad.covariance_after[k, k])
            error = triad.after[k] - target[axis]
            errors.append(error)
            sigmas.append(sigma)
            line[f"error_{axis}_dph"] = round(error, 4)
            line[f"sigma_{axis}_dph"] = round(sigma, 4)
        print(json.dumps(line), flush=True)
    z = [abs(e) / s for e, s in zip(errors, sigmas, strict=True)]
    print(json.dumps({
        "name": "update_triad", "n": len(z), "orientations": len(ORIENTATIONS),
        "within_1sigma": round(sum(v <= 1.0 for v in z) / len(z), 3),
        "within_2sigma": round(sum(v <= 2.0 for v in z) / len(z), 3),
        "within_3sigma": round(sum(v <= 3.0 for v in z) / len(z), 3),
        "max_z": round(max(z), 2),
        "median_abs_error_dph": round(statistics.median(abs(e) for e in errors), 4),
        "median_sigma_dph": round(statistics.median(sigmas), 4),
        "seconds_per_update_median": round(statistics.median(seconds), 3)}), flush=True)


if __name__ == "__main__":
    main()
