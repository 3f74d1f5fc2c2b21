"""The population prior's chamber-time saving: held-out units with 2, 3 and 7 soaks.

A prior is built from 32 simulated units calibrated with the paper's 7 soaks
(:mod:`hrgtc.fleet.population`, :func:`hrgtc.fleet.soak_savings.measure_prior`);
16 units that were not in it are calibrated from 2 soaks (-10, 30 °C) and 3
(-20, 10, 40 °C) with the prior and from 7 without. One line per number of
soaks: the max over units of the max |T(f_true(T)) - T| over -20...40 °C against
the unit's true law, its median, and the prior fit's largest 1-sigma band.
Issue targets: 3 soaks <= 0.02 °C, 2 soaks <= 0.05 °C. Soaks 5 h at 2 Hz
(``--quick``: 12 + 4 units, 3 h at 0.5 Hz).
"""

from __future__ import annotations

import sys
import time


def run(quick: bool = False) -> list[dict]:
    import numpy as np

    from hrgtc.fleet.soak_savings import measure_prior

    n_prior, n_held_out, rate_hz, hours = (12, 4, 0.5, 3.0) if quick else (32, 16, 2.0, 5.0)
    start = time.perf_counter()
    result = measure_prior(n_prior, n_held_out, seed=1, sample_rate_hz=rate_hz,
                           soak_hours=hours)
    seconds = time.perf_counter() - start
    targets = {2: 0.05, 3: 0.02, 7: None}
    lines = []
    for n_soaks, errors in sorted(result["max_error_c"].items()):
        e = np.array(errors)
        band = result["band_c"].get(n_soaks)
        lines.append({
            "name": f"prior_{n_soaks}_soaks", "n": n_held_out, "n_prior_units": n_prior,
            "soaks": n_soaks, "chamber_hours": n_soaks * hours,
            "max_error_c": round(float(e.max()), 4),
            "median_error_c": round(float(np.median(e)), 4),
            "max_band_1sigma_c": None if band is None else round(float(max(band)), 4),
            "target_c": targets[n_soaks], "sample_rate_hz": rate_hz, "soak_hours": hours,
            "seconds": round(seconds, 2), "rate": round(n_held_out / seconds, 3),
        })
    return lines


if __name__ == "__main__":
    import json

    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
