"""What burst handling costs: a duty-cycled recording against a continuous one of as many samples.

Issue 20's "Done when": burst handling costs < 10 % over a continuous file of the same
length. Two passes are timed on both recordings, alternated, each the median of
:data:`REPEATS`:

* ``compensate``: :class:`hrgtc.compensate.Compensator` (fused kernel) over the whole
  recording, the df/dt filter stepping over each sample's Δt and bridging the gaps
  (the default), and with ``gaps="split"`` (the filter restarted at each burst through
  the kernel's restart mask, reported beside it);
* ``calibrate_features``: the feature pass of calibration,
  :func:`hrgtc.drift.window_means` over the Eq. (21) candidates (the filter, the
  window means and the rate-filter checks), which is what a burst file changes in
  calibration (the regression runs on the window means).

Both recordings carry the same simulated values (a cool-down of the paper's unit at
50 Hz, logging a housing thermistor); the burst one gets the time axis of a logger that
records 5 s every 300 s (the PAN cold test's), so only the time steps differ: the ratio
isolates what gaps, per-step Δt and the burst checks cost. ``ratio`` is burst over
continuous seconds, the median of the alternated pairs (target <= 1.10);
``ratio_of_fastest`` compares the fastest of each, less sensitive to a shared machine;
``cpu_ratio`` and ``cpu_ratio_of_fastest`` are the same on the process's CPU time, which
does not count the time the process waits for a core (a loaded machine's wall-time
ratios of single pairs range from 0.3 to 7).
"""

from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

SAMPLE_RATE_HZ = 50.0
BURST_S, PERIOD_S = 5.0, 300.0
REPEATS = 7
TARGET = 1.10


def _model(folder: Path):
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.settings.calibration import CalibrationSettings
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    soaks = simulate_files([profiles.soak(t, 2.0) for t in (-20.0, 0.0, 20.0, 40.0)],
                           folder / "soaks", "parquet", sample_rate_hz=2.0, seed=1)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 2.0)], folder / "cal", "parquet",
                          sample_rate_hz=SAMPLE_RATE_HZ, seed=2)
    return calibrate([w.path for w in soaks], [cool[0].path],
                     settings=CalibrationSettings(drift_from_soaks=False)).model


def _recordings(samples: int):
    import numpy as np

    from hrgtc.recording import Recording
    from hrgtc.simulate import simulate_run
    from hrgtc.simulate import standard_profiles as profiles

    hours = samples / SAMPLE_RATE_HZ / 3600.0
    run = simulate_run(profiles.cooldown(20.0, -20.0, hours), sample_rate_hz=SAMPLE_RATE_HZ,
                       seed=3)
    n = min(samples, len(run))
    keep = [name for name in run.names if name in ("time_s", "freq_hz", "rate_dph", "housing_c")]
    continuous = Recording({k: np.ascontiguousarray(run[k][:n]) for k in keep}, run.metadata,
                           "continuous")
    per_burst = round(BURST_S * SAMPLE_RATE_HZ)
    index = np.arange(n)
    burst_time = (index // per_burst) * PERIOD_S + (index % per_burst) / SAMPLE_RATE_HZ
    bursts = continuous.with_columns(time_s=burst_time)
    return continuous, bursts


def _time(function, *args) -> tuple[float, float]:
    """Wall and CPU seconds of one call."""
    start, start_cpu = time.perf_counter(), time.process_time()
    function(*args)
    return time.perf_counter() - start, time.process_time() - start_cpu


def _compensate(model, recording, gaps):
    import warnings

    from hrgtc.compensate import Compensator

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # tau 10 s is shorter than the 300 s burst period
        Compensator(model, gaps=gaps).transform(recording)


def _features(model, recording):
    import warnings

    from hrgtc.drift import Windowing, window_means
    from hrgtc.drift.features import EQ21

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the burst run warns about tau (reported once)
        window_means([recording], model.drift.settings, EQ21, Windowing(BURST_S))


def _pairs(function, model, continuous, bursts, *extra) -> dict:
    """Alternated timings: median seconds of each, ratios (wall and CPU) of each pair and
    of the fastest of each."""
    seconds: dict[str, list[float]] = {"continuous": [], "bursts": []}
    cpu: dict[str, list[float]] = {"continuous": [], "bursts": []}
    ratios, cpu_ratios = [], []
    for recording in (continuous, bursts):  # untimed: the first full-size call paid the
        function(model, recording, *extra)  # page faults of its arrays (first pair 0.14-0.2)
    for k in range(REPEATS):
        order = [("continuous", continuous), ("bursts", bursts)]
        for name, recording in order if k % 2 == 0 else order[::-1]:
            wall, used = _time(function, model, recording, *extra)
            seconds[name].append(wall)
            cpu[name].append(used)
        ratios.append(seconds["bursts"][-1] / seconds["continuous"][-1])
        cpu_ratios.append(cpu["bursts"][-1] / cpu["continuous"][-1])
    return {
        "plain": statistics.median(seconds["continuous"]),
        "burst": statistics.median(seconds["bursts"]),
        "ratios": ratios,
        "best": min(seconds["bursts"]) / min(seconds["continuous"]),
        "cpu_ratio": statistics.median(cpu_ratios),
        "cpu_best": min(cpu["bursts"]) / min(cpu["continuous"]),
    }


def run(quick: bool = False) -> list[dict]:
    samples = 500_000 if quick else 5_000_000
    with tempfile.TemporaryDirectory() as folder:
        model = _model(Path(folder))
    continuous, bursts = _recordings(samples)
    _compensate(model, continuous.slice(0, 1000), "ignore")  # compile / load the kernel
    _features(model, continuous.slice(0, 20_000))
    results = []
    for name, function, extra in (("bursts_compensate", _compensate, ("ignore",)),
                                  ("bursts_compensate_split", _compensate, ("split",)),
                                  ("bursts_calibrate_features", _features, ())):
        timed = _pairs(function, model, continuous, bursts, *extra)
        plain, burst, ratios = timed["plain"], timed["burst"], timed["ratios"]
        results.append({
            "name": name, "n": len(bursts), "seconds": round(burst, 3),
            "rate": round(len(bursts) / burst), "continuous_seconds": round(plain, 3),
            "ratio": round(statistics.median(ratios), 3),
            "ratio_each_pair": [round(r, 3) for r in ratios], "target_ratio": TARGET,
            "ratio_of_fastest": round(timed["best"], 3),
            "cpu_ratio": round(timed["cpu_ratio"], 3),
            "cpu_ratio_of_fastest": round(timed["cpu_best"], 3),
            "bursts": len(bursts) // round(BURST_S * SAMPLE_RATE_HZ),
        })
    return results


if __name__ == "__main__":
    import json

    for line in run(quick=True):
        print(json.dumps(line))
