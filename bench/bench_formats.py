"""Reading a large TDMS and MDF4 file in chunks, beside the same data in Parquet.

Issue 30: "reading a 20 M-sample TDMS/MDF4 file runs in bounded memory (a stated multiple
of one chunk), its time reported beside reading the same Parquet". The same three columns
(``time_s``, ``freq_hz``, ``rate_dph``; 20 M rows, 5 ms apart) are written with each
format's library in segments of 1 M rows (npTDMS ``TdmsWriter``, asammdf ``MDF.append`` and
``extend``, pyarrow), then read by ``hrgtc.recording.iter_chunks`` in chunks of 250 000 rows
(``validate=False``: the reading alone) in a fresh process each. Memory is the process's
anonymous resident memory at its peak over the chunks (``peak_anon_mb``) beside one chunk of
the three float64 columns (``chunk_mb``): asammdf maps the file, whose pages count in the
high-water mark of the resident set (``vm_hwm_mb``) but are the kernel's page cache, given
back under pressure. ``above_baseline_chunks`` is the peak less the memory of the
interpreter and the libraries (``baseline_anon_mb``, measured before the first chunk), in
chunks: the stated multiple.

Writing (issue 30 item 5, the simulator's formats): 2 M rows of the same three columns
written by ``hrgtc.recording.RecordingWriter`` in chunks of 250 000 rows to Parquet, HDF5,
TDMS, MATLAB v5 and MDF4, each in a fresh process (``write_chunks_<format>``): its time, and
its anonymous resident memory at the peak over the chunks and the close, less that before the
first chunk (the writer open, the libraries imported), in chunks; ``peak_rss_mb`` is the
high-water mark of the resident set (the chunks being made and encoded included) and
``rss_above_baseline_chunks`` its rise over the writing, in chunks.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SEGMENT = 1_000_000
CHUNK = 250_000
PERIOD_S = 0.005

_READ = """
import json, sys, time
from hrgtc.recording import iter_chunks
import asammdf, nptdms, pyarrow.parquet  # the libraries' own memory: the baseline
def anon():
    for line in open('/proc/self/status'):
        if line.startswith('RssAnon'):
            return int(line.split()[1]) / 1024
baseline = anon()
peak, rows, start = baseline, 0, time.perf_counter()
chunks = iter_chunks(sys.argv[1], validate=False, chunk_rows=int(sys.argv[2]),
                     spike_filter='off')
for chunk in chunks:
    rows += len(chunk)
    peak = max(peak, anon())
seconds = time.perf_counter() - start
hwm = [int(l.split()[1]) / 1024 for l in open('/proc/self/status') if l.startswith('VmHWM')][0]
print(json.dumps({'rows': rows, 'seconds': seconds, 'peak_anon_mb': peak, 'vm_hwm_mb': hwm,
                  'baseline_anon_mb': baseline}))
"""


_WRITE = """
import json, sys, time
import numpy as np
from hrgtc.recording import Metadata, RecordingWriter
import asammdf, nptdms, scipy.io, h5py, pyarrow.parquet  # the libraries' own memory: the baseline
def anon():
    for line in open('/proc/self/status'):
        if line.startswith('RssAnon'):
            return int(line.split()[1]) / 1024
n, rows, period = int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
metadata = Metadata(sample_rate_hz=1.0 / period, unit='bench')
writer = RecordingWriter(sys.argv[1], metadata, ['time_s', 'freq_hz', 'rate_dph'], force=True)
def hwm():
    return [int(l.split()[1]) / 1024 for l in open('/proc/self/status') if l.startswith('VmHWM')][0]
baseline, baseline_hwm = anon(), hwm()
peak, start = baseline, time.perf_counter()
for first in range(0, n, rows):
    k = np.arange(first, min(first + rows, n), dtype=np.float64)
    writer.write({'time_s': k * period, 'freq_hz': 4425.0 + 1e-7 * k,
                  'rate_dph': 9.7 + np.sin(k * 1e-3)})
    del k
    peak = max(peak, anon())
writer.close()
peak = max(peak, anon())
seconds = time.perf_counter() - start
print(json.dumps({'seconds': seconds, 'peak_anon_mb': peak, 'vm_hwm_mb': hwm(),
                  'baseline_anon_mb': baseline, 'baseline_hwm_mb': baseline_hwm}))
"""
#: Rows written by the writing benchmark.
WRITE_ROWS = 2_000_000
#: The suffixes written (Parquet's beside the simulator's other formats).
WRITE_SUFFIXES = {"parquet": ".parquet", "h5": ".h5", "tdms": ".tdms", "mat": ".mat",
                  "mf4": ".mf4"}


def run_write(n: int = WRITE_ROWS) -> list[dict]:
    """``write_chunks_<format>`` of ``n`` rows in chunks of :data:`CHUNK` (fresh processes)."""
    results = []
    chunk_mb = CHUNK * 3 * 8 / 2**20
    with tempfile.TemporaryDirectory(prefix="hrgtc-bench-write-") as tmp:
        for fmt, suffix in WRITE_SUFFIXES.items():
            path = Path(tmp) / f"big{suffix}"
            out = subprocess.run([sys.executable, "-c", _WRITE, str(path), str(n), str(CHUNK),
                                  str(PERIOD_S)], check=True, capture_output=True, text=True)
            measured = json.loads(out.stdout.strip().splitlines()[-1])
            results.append({
                "name": f"write_chunks_{fmt}", "n": n, "seconds": round(measured["seconds"], 2),
                "rate": round(n / measured["seconds"]), "chunk_rows": CHUNK,
                "chunk_mb": round(chunk_mb, 1),
                "peak_anon_mb": round(measured["peak_anon_mb"], 1),
                "baseline_anon_mb": round(measured["baseline_anon_mb"], 1),
                "above_baseline_chunks": round(
                    (measured["peak_anon_mb"] - measured["baseline_anon_mb"]) / chunk_mb, 1),
                "peak_rss_mb": round(measured["vm_hwm_mb"], 1),
                "rss_above_baseline_chunks": round(
                    (measured["vm_hwm_mb"] - measured["baseline_hwm_mb"]) / chunk_mb, 1),
                "file_mb": round(path.stat().st_size / 2**20, 1)})
            path.unlink()
    return results


def _segment(start: int, stop: int) -> dict[str, np.ndarray]:
    k = np.arange(start, stop, dtype=np.float64)
    return {"time_s": k * PERIOD_S, "freq_hz": 4425.0 + 1e-7 * k,
            "rate_dph": 9.7 + np.sin(k * 1e-3)}


def write_all(folder: Path, n: int) -> dict[str, Path]:
    """The same columns as Parquet, TDMS and MDF4, written in segments."""
    import pyarrow as pa
    import pyarrow.parquet as pq
    from asammdf import MDF, Signal
    from nptdms import ChannelObject, GroupObject, RootObject, TdmsWriter

    paths = {"parquet": folder / "big.parquet", "tdms": folder / "big.tdms",
             "mdf": folder / "big.mf4"}
    timing = {"wf_start_time": np.datetime64("2024-01-01T00:00:00", "us"),
              "wf_increment": PERIOD_S, "wf_start_offset": 0.0}
    parquet = None
    with TdmsWriter(paths["tdms"]) as tdms, MDF(version="4.10") as mdf:
        for start in range(0, n, SEGMENT):
            part = _segment(start, min(start + SEGMENT, n))
            table = pa.table(part)
            if parquet is None:
                parquet = pq.ParquetWriter(paths["parquet"], table.schema)
            parquet.write_table(table)
            tdms.write_segment([RootObject({}), GroupObject("gyro"), *(
                ChannelObject("gyro", name, part[name], properties=timing)
                for name in ("freq_hz", "rate_dph"))])
            signals = [Signal(part[name], part["time_s"], name=name)
                       for name in ("freq_hz", "rate_dph")]
            if start == 0:
                mdf.append(signals)
            else:
                mdf.extend(0, [(part["time_s"], None), *((part[s.name], None) for s in signals)])
        mdf.save(paths["mdf"], overwrite=True)
    if parquet is not None:
        parquet.close()
    return paths


def run(quick: bool = False) -> list[dict]:
    n = 1_000_000 if quick else 20_000_000
    results = []
    with tempfile.TemporaryDirectory(prefix="hrgtc-bench-formats-") as tmp:
        start = time.perf_counter()
        paths = write_all(Path(tmp), n)
        written = time.perf_counter() - start
        chunk_mb = CHUNK * 3 * 8 / 2**20
        for fmt, path in paths.items():
            out = subprocess.run([sys.executable, "-c", _READ, str(path), str(CHUNK)],
                                 check=True, capture_output=True, text=True)
            measured = json.loads(out.stdout.strip().splitlines()[-1])
            assert measured["rows"] == n, (fmt, measured)
            results.append({
                "name": f"read_chunks_{fmt}", "n": n, "seconds": round(measured["seconds"], 2),
                "rate": round(n / measured["seconds"]), "chunk_rows": CHUNK,
                "chunk_mb": round(chunk_mb, 1),
                "peak_anon_mb": round(measured["peak_anon_mb"], 1),
                "baseline_anon_mb": round(measured["baseline_anon_mb"], 1),
                "above_baseline_chunks": round(
                    (measured["peak_anon_mb"] - measured["baseline_anon_mb"]) / chunk_mb, 1),
                "vm_hwm_mb": round(measured["vm_hwm_mb"], 1),
                "peak_rss_mb": round(measured["vm_hwm_mb"], 1),
                "file_mb": round(path.stat().st_size / 2**20, 1),
                "written_all_seconds": round(written, 1)})
    return results + run_write(WRITE_ROWS // 4 if quick else WRITE_ROWS)


if __name__ == "__main__":
    for result in run(quick="--quick" in sys.argv):
        print(json.dumps(result))
