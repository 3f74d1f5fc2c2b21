"""Compensation throughput: in memory, file to file, and streaming vs batch.

Issue targets: >= 20 M samples/s in memory, >= 3 M samples/s file to file
(Parquet in, Parquet out). The model is calibrated on a small simulated
campaign (not timed); the run to compensate is a simulated warm-up.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from _child import measure

SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)


def _model(folder: Path, rate_hz: float):
    from hrgtc.calibration import calibrate
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    soaks = simulate_files([profiles.soak(t, 5.0) for t in SETPOINTS_C], folder / "soaks",
                           "parquet", rate_hz=5.0, seed=1)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 5.0)], folder / "cal", "parquet",
                          rate_hz=rate_hz, seed=2)
    return calibrate([w.path for w in soaks], [cool[0].path], drift_from_soaks=False).model


def _file_to_file(model_path: str, source: str, output: str) -> int:
    from hrgtc.compensate import compensate_file
    from hrgtc.model import load_model

    return compensate_file(source, output, load_model(model_path)).rows


def run(quick: bool = False) -> list[dict]:
    import numpy as np

    from hrgtc.compensate import Compensator, compensate
    from hrgtc.model import save_model
    from hrgtc.recording import concatenate, read
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    rate_hz = 20.0 if quick else 200.0
    hours = 1.0 if quick else 14.0  # 14 h at 200 Hz: 10 M samples
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        model = _model(folder, rate_hz)
        model_path = folder / "unit.json"
        save_model(model, model_path)
        run_file = simulate_files([profiles.warmup(-20.0, 20.0, hours)], folder / "run",
                                  "parquet", rate_hz=rate_hz, seed=3)[0]
        recording = read(run_file.path)
        n = len(recording)
        compensate(recording.slice(0, 1000), model)  # warm caches
        times = []
        for _ in range(3):
            start = time.perf_counter()
            batch = compensate(recording, model)
            times.append(time.perf_counter() - start)
        seconds = float(np.median(times))
        out.append({"name": "compensate_in_memory", "n": n, "seconds": round(seconds, 3),
                    "rate": round(n / seconds), "target_rate": 20_000_000})
        start = time.perf_counter()
        compensator = Compensator(model)
        parts = [compensator.process(recording.slice(a, a + 100_000))
                 for a in range(0, n, 100_000)]
        seconds = time.perf_counter() - start
        streamed = concatenate(parts)
        diff = float(np.max(np.abs(streamed["rate_comp_dph"] - batch["rate_comp_dph"])))
        out.append({"name": "compensate_streaming_100k_chunks", "n": n,
                    "seconds": round(seconds, 3), "rate": round(n / seconds),
                    "max_abs_diff_vs_batch_dph": diff})
        del batch, streamed, parts, recording
        rows, seconds, peak = measure(_file_to_file, str(model_path), run_file.path,
                                      str(folder / "out.parquet"))
        out.append({"name": "compensate_file_to_file_parquet", "n": rows,
                    "seconds": round(seconds, 3), "rate": round(rows / seconds),
                    "peak_rss_mb": peak, "target_rate": 3_000_000})
    return out


if __name__ == "__main__":
    import json

    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
