"""Compensation throughput, each figure beside its alternative measured in the same run.

* in memory: the fused kernel (``engine="fused"``) against the numpy reference
  engine on the same recording (``ratio_vs_numpy_engine``, target >= 3), and
  against one bare numpy pass ``rate - bias`` over the same arrays (a floor no
  compensation reaches: it writes one column where compensation writes four);
* streaming: 100 000-row chunks against the batch call;
* file to file: ``compensate_file`` (validation, atomic write, fsync) against
  :func:`plain_script`, a plain pyarrow + numpy script that reads the same
  columns with ``ParquetFile.iter_batches``, computes the same outputs with the
  same kernel and writes them with ``ParquetWriter`` (``bench/plain_compensate.py``;
  ratio target <= 1), each in
  a fresh process, alternated, the median of the pairs. The script leaves its
  output in the page cache, while ``compensate_file`` validates every sample,
  writes page checksums and waits for its fsync before the atomic rename; so the
  seconds of an fsync after the script are measured too and
  ``ratio_vs_plain_script_then_fsync`` compares like with like (hrgtc over script
  + fsync, per pair). ``ratio_vs_plain_script`` is the stricter figure. Peak RSS
  on a file 4x shorter shows memory does not grow with the file;
* compile time of the kernel on first call, with an empty and a warm cache.

The model is calibrated on a small simulated campaign (not timed); its runs log a housing
thermistor, so the drift model's candidates are the gradient terms (``g = housing_c - T(f)``,
:data:`hrgtc.pipeline.calibration.GRADIENT_TERMS`), which the fused kernel computes. The run to
compensate is a simulated warm-up, 14 h at 200 Hz (10 M samples).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from _child import measure
from plain_compensate import plain_script

SETPOINTS_C = (-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0)
FILE_PAIRS = 7
MEMORY_REPEATS = 3


def _model(folder: Path, sample_rate_hz: float):
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.settings.calibration import CalibrationSettings
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    soaks = simulate_files([profiles.soak(t, 5.0) for t in SETPOINTS_C], folder / "soaks",
                           "parquet", sample_rate_hz=5.0, seed=1)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 5.0)], folder / "cal", "parquet",
                          sample_rate_hz=sample_rate_hz, seed=2)
    return calibrate([w.path for w in soaks], [cool[0].path],
                     settings=CalibrationSettings(drift_from_soaks=False)).model


def _warm(model_path: str) -> None:
    """Import everything and load the compiled kernel (not timed)."""
    import numpy as np

    from hrgtc.compensate import compensate
    from hrgtc.model import load_model
    from hrgtc.recording import Metadata, Recording

    model = load_model(model_path)
    f = np.full(16, model.thermometer.frequency(20.0))
    compensate(model, Recording({"time_s": np.arange(16.0) / model.drift.settings.sample_rate_hz,
                                 "freq_hz": f, "rate_dph": np.zeros(16),
                                 "housing_c": np.full(16, 20.0)},
                                Metadata(sample_rate_hz=model.drift.settings.sample_rate_hz)))


def _hrgtc_file(model_path: str, source: str, output: str,
                motion: str = "exclude") -> tuple[int, float, float, float]:
    """Rows, wall seconds and CPU seconds (all threads) of ``compensate_file`` (fsync in);
    ``motion="exclude"`` (the default) includes the pass that finds the samples not at rest
    for the ``at_rest`` flags, ``"keep"`` leaves it out, as the plain script does."""
    from hrgtc.compensate import compensate_file
    from hrgtc.model import load_model
    from hrgtc.recording import ReadOptions

    _warm(model_path)
    start, cpu = time.perf_counter(), time.process_time()
    rows = compensate_file(source, output, load_model(model_path),
                           read_options=ReadOptions(motion=motion)).rows
    return rows, time.perf_counter() - start, time.process_time() - cpu, 0.0


def _hrgtc_file_motion_keep(model_path: str, source: str,
                             output: str) -> tuple[int, float, float, float]:
    """:func:`_hrgtc_file` without the motion pass (a module-level function: it is pickled
    into the measuring process)."""
    return _hrgtc_file(model_path, source, output, motion="keep")


def _plain_file(model_path: str, source: str, output: str) -> tuple[int, float, float, float]:
    """Rows, wall and CPU seconds of :func:`plain_script`, then seconds of an fsync after it.

    The script leaves its output in the page cache; the fsync (not part of its time)
    shows what making it durable, as ``compensate_file`` does, would add.
    """
    _warm(model_path)
    start, cpu = time.perf_counter(), time.process_time()
    rows = plain_script(model_path, source, output)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    start = time.perf_counter()
    fd = os.open(output, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    return rows, seconds, cpu, time.perf_counter() - start


def _first_call(model_path: str, cache_dir: str) -> float:
    """Seconds of the first compensation in a fresh process (import of numba included)."""
    os.environ["NUMBA_CACHE_DIR"] = cache_dir
    import numpy as np

    from hrgtc.compensate import compensate
    from hrgtc.model import load_model
    from hrgtc.recording import Metadata, Recording

    model = load_model(model_path)
    rate = model.drift.settings.sample_rate_hz
    recording = Recording({"time_s": np.arange(16.0) / rate,
                           "freq_hz": np.full(16, model.thermometer.frequency(20.0)),
                           "rate_dph": np.zeros(16), "housing_c": np.full(16, 20.0)},
                          Metadata(sample_rate_hz=rate))
    start = time.perf_counter()
    compensate(model, recording)
    return time.perf_counter() - start


def _file_pairs(model_path: str, source: str, folder: Path) -> tuple[dict, dict]:
    """Alternate hrgtc and the plain script; medians of seconds, ratio of each pair."""
    runs: dict[str, list[tuple[float, float, float]]] = {"hrgtc": [], "plain": [], "keep": []}
    fsyncs = []
    ratios, durable_ratios = [], []
    rows = 0
    for k in range(FILE_PAIRS):
        pair = {}
        order = (("hrgtc", _hrgtc_file), ("plain", _plain_file),
                 ("keep", _hrgtc_file_motion_keep))
        for name, function in order if k % 2 == 0 else order[::-1]:
            output = folder / f"{name}.parquet"
            output.unlink(missing_ok=True)
            os.sync()  # no write-back of an earlier run during this one
            (rows, seconds, cpu, fsync), _, peak = measure(function, model_path, source,
                                                           str(output))
            runs[name].append((seconds, peak, cpu))
            if name == "plain":
                fsyncs.append(fsync)
            pair[name] = seconds
        ratios.append(pair["hrgtc"] / pair["plain"])
        durable_ratios.append(pair["hrgtc"] / (pair["plain"] + fsyncs[-1]))
        for name in runs:
            (folder / f"{name}.parquet").unlink(missing_ok=True)
    hrgtc = statistics.median(s for s, _, _ in runs["hrgtc"])
    plain = statistics.median(s for s, _, _ in runs["plain"])
    keep = statistics.median(s for s, _, _ in runs["keep"])
    return (
        {"name": "compensate_file_to_file_parquet", "n": rows, "seconds": round(hrgtc, 3),
         "rate": round(rows / hrgtc), "peak_rss_mb": max(p for _, p, _ in runs["hrgtc"]),
         "cpu_seconds": round(statistics.median(c for _, _, c in runs["hrgtc"]), 3),
         "plain_script_seconds": round(plain, 3), "plain_script_rate": round(rows / plain),
         "plain_script_peak_rss_mb": max(p for _, p, _ in runs["plain"]),
         "plain_script_cpu_seconds": round(statistics.median(c for _, _, c in runs["plain"]),
                                           3),
         "plain_script_then_fsync_seconds": round(statistics.median(fsyncs), 3),
         "ratio_vs_plain_script": round(statistics.median(ratios), 3),
         "motion_keep_seconds": round(keep, 3),
         "ratio_motion_keep_vs_plain_script": round(keep / plain, 3),
         "ratio_each_pair": [round(r, 3) for r in ratios], "target_ratio": 1.0,
         "ratio_vs_plain_script_then_fsync": round(statistics.median(durable_ratios), 3),
         "target_rate": 3_000_000},
        {"seconds_each": [round(s, 3) for s, _, _ in runs["hrgtc"]],
         "plain_seconds_each": [round(s, 3) for s, _, _ in runs["plain"]]},
    )


def run(quick: bool = False) -> list[dict]:
    import numpy as np

    from hrgtc.compensate import Compensator, compensate
    from hrgtc.model import save_model
    from hrgtc.recording import concatenate, read
    from hrgtc.simulate import simulate_files
    from hrgtc.simulate import standard_profiles as profiles

    sample_rate_hz = 20.0 if quick else 200.0
    hours = 1.0 if quick else 14.0  # 14 h at 200 Hz: 10 M samples
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        model = _model(folder, sample_rate_hz)
        model_path = str(folder / "unit.json")
        save_model(model, model_path)
        cold, _, _ = measure(_first_call, model_path, str(folder / "numba-cache"))
        warm, _, _ = measure(_first_call, model_path, str(folder / "numba-cache"))
        out.append({"name": "compensate_kernel_first_call", "n": 16, "seconds": round(cold, 3),
                    "rate": round(16 / cold), "compile_seconds_empty_cache": round(cold, 3),
                    "seconds_warm_cache": round(warm, 3)})
        run_files = [simulate_files([profiles.warmup(-20.0, 20.0, h)], folder / name, "parquet",
                                    sample_rate_hz=sample_rate_hz, seed=3)[0]
                     for name, h in (("short", max(hours / 4, 1.0)), ("run", hours))]
        recording = read(run_files[1].path)
        n = len(recording)
        compensate(model, recording.slice(0, 1000))  # load the kernel
        fused_times, numpy_times, pass_times, fused_cpu, numpy_cpu = [], [], [], [], []
        for _ in range(MEMORY_REPEATS):  # alternated: a busy neighbour slows both alike
            start, cpu = time.perf_counter(), time.process_time()
            batch = compensate(model, recording)
            fused_times.append(time.perf_counter() - start)
            fused_cpu.append(time.process_time() - cpu)
            start, cpu = time.perf_counter(), time.process_time()
            reference = compensate(model, recording, engine="numpy")
            numpy_times.append(time.perf_counter() - start)
            numpy_cpu.append(time.process_time() - cpu)
            start = time.perf_counter()
            difference = recording.rate_dph - batch["bias_model_dph"]
            pass_times.append(time.perf_counter() - start)
        del difference
        fused, numpy_engine, bare = (float(np.median(t))
                                     for t in (fused_times, numpy_times, pass_times))
        ratios = [b / a for a, b in zip(fused_times, numpy_times, strict=True)]
        out.append({
            "name": "compensate_in_memory", "n": n, "seconds": round(fused, 3),
            "rate": round(n / fused), "numpy_engine_seconds": round(numpy_engine, 3),
            "numpy_engine_rate": round(n / numpy_engine),
            "ratio_vs_numpy_engine": round(float(np.median(ratios)), 2),
            "ratio_each_pair": [round(r, 2) for r in ratios], "target_ratio": 3.0,
            "cpu_seconds": round(float(np.median(fused_cpu)), 3),
            "numpy_engine_cpu_seconds": round(float(np.median(numpy_cpu)), 3),
            "numpy_pass_seconds": round(bare, 4), "numpy_pass_rate": round(n / bare),
            "ratio_vs_numpy_pass": round(bare / fused, 3),
            "max_abs_diff_vs_numpy_engine_dph": float(np.max(np.abs(
                batch["rate_comp_dph"] - reference["rate_comp_dph"]))),
            "max_abs_diff_vs_numpy_engine_c": float(np.nanmax(np.abs(
                batch["resonator_c_est"] - reference["resonator_c_est"]))),
            "target_rate": 20_000_000})
        del reference
        start = time.perf_counter()
        compensator = Compensator(model)
        parts = [compensator.transform(recording.slice(a, a + 100_000))
                 for a in range(0, n, 100_000)]
        seconds = time.perf_counter() - start
        streamed = concatenate(parts)
        diff = float(np.max(np.abs(streamed["rate_comp_dph"] - batch["rate_comp_dph"])))
        out.append({"name": "compensate_streaming_100k_chunks", "n": n,
                    "seconds": round(seconds, 3), "rate": round(n / seconds),
                    "batch_seconds": round(fused, 3),
                    "ratio_vs_batch": round(fused / seconds, 3),
                    "max_abs_diff_vs_batch_dph": diff})
        del batch, streamed, parts, recording
        line, _ = _file_pairs(model_path, run_files[1].path, folder)
        (short_rows, _, _, _), _, short_peak = measure(_hrgtc_file, model_path, run_files[0].path,
                                                 str(folder / "short.parquet"))
        line.update({"peak_rss_mb_4x_shorter_file": short_peak, "rows_4x_shorter_file":
                     short_rows})
        out.append(line)
    return out


if __name__ == "__main__":
    import json

    for result in run(quick="--quick" in sys.argv):
        print(json.dumps(result))
