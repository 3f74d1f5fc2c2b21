"""Calibrate a unit from 7 soaks + 2 ramps at 200 Hz (about 32 M samples).

Issue targets: under 60 s and under 1 GB peak RSS. The campaign is simulated
first (not timed); ``calibrate`` then runs in a fresh process so its peak RSS
is its own. It streams the drift runs chunk by chunk and reads one soak at a
time; the drift fit uses the cool-down, the warm-up and the soak transients,
and the housing baseline is a second pass over the same files.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from _child import measure

SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)


def _calibrate(soaks: list[str], drifts: list[str]) -> dict:
    from hrgtc.pipeline.calibration import calibrate

    result = calibrate(soaks, drifts)
    return {"selected": list(result.model.drift.selected),
            "n_samples_drift": result.model.drift.n_samples}


def run(quick: bool = False) -> list[dict]:
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    sample_rate_hz = 20.0 if quick else 200.0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        soaks = simulate_files([profiles.soak(t, 5.0) for t in SETPOINTS_C], folder / "soaks",
                               "parquet", sample_rate_hz=sample_rate_hz, seed=1)
        ramps = simulate_files([profiles.cooldown(20.0, -20.0, 5.0),
                                profiles.warmup(-20.0, 20.0, 5.0)], folder / "ramps",
                               "parquet", sample_rate_hz=sample_rate_hz, seed=2)
        n = sum(w.rows for w in soaks) + sum(w.rows for w in ramps)
        value, seconds, peak = measure(_calibrate, [w.path for w in soaks],
                                       [w.path for w in ramps])
    return [{"name": "calibrate_7soaks_2ramps", "n": n, "seconds": round(seconds, 3),
             "rate": round(n / seconds), "peak_rss_mb": peak, "target_seconds": 60,
             "target_peak_rss_mb": 1024, **value}]


if __name__ == "__main__":
    import json

    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
