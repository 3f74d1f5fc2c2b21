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
    return results


if __name__ == "__main__":
    for result in run(quick="--quick" in sys.argv):
        print(json.dumps(result))
