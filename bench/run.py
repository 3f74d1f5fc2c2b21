"""Run the benchmarks of bench/ and print one JSON line per result.

Usage::

    python bench/run.py                 # every bench/bench_*.py
    python bench/run.py stepwise        # bench/bench_stepwise.py only
    python bench/run.py --quick         # small sizes (each run() gets quick=True)

Every benchmark module exposes ``run(quick: bool = False) -> list[dict]``; each
dict has at least name, n, seconds, rate and peak_rss_mb. Each module runs in a
fresh Python subprocess, so ``peak_rss_mb`` (the process's own maximum resident
set size) belongs to that benchmark alone; a result that does not set it gets
the peak of its module's process. Lines are streamed as they come; a module
that fails is reported on stderr and makes the exit status 1. A last line,
``bench_wall``, gives the wall time of each module and of the whole run (issue 13:
``make bench`` under 10 minutes on the project's 2-core machine).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import resource
import subprocess
import sys
import time
from pathlib import Path

BENCH_DIR = Path(__file__).resolve().parent


def available() -> dict[str, Path]:
    """Benchmark names (``bench_<name>.py``) and their files, sorted by name."""
    return {p.stem.removeprefix("bench_"): p for p in sorted(BENCH_DIR.glob("bench_*.py"))}


def peak_rss_mb() -> float:
    """Peak resident set size of this process so far. [MB]"""
    kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB on Linux
    return round(kib / 1024.0, 1)


def _run_child(name: str, quick: bool) -> int:
    path = available()[name]
    sys.path.insert(0, str(BENCH_DIR))
    spec = importlib.util.spec_from_file_location(f"bench_{name}", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # so functions it hands to child processes pickle
    spec.loader.exec_module(module)
    for result in module.run(quick=quick):
        result.setdefault("peak_rss_mb", peak_rss_mb())
        print(json.dumps(result), flush=True)
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="benchmarks to run (default: all)")
    parser.add_argument("--quick", action="store_true", help="small sizes")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        return _run_child(args.child, args.quick)
    known = available()
    unknown = [n for n in args.names if n not in known]
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; available: {sorted(known)}")
    status = 0
    walls: dict[str, float] = {}
    start = time.perf_counter()
    for name in args.names or list(known):
        began = time.perf_counter()
        command = [sys.executable, str(Path(__file__).resolve()), "--child", name]
        with subprocess.Popen(command + (["--quick"] if args.quick else []),
                              stdout=subprocess.PIPE, text=True) as proc:
            assert proc.stdout is not None
            for line in proc.stdout:
                print(line.rstrip("\n"), flush=True)
        if proc.returncode != 0:
            print(f"benchmark {name!r} failed with exit status {proc.returncode}",
                  file=sys.stderr)
            status = 1
        walls[name] = round(time.perf_counter() - began, 1)
    total = time.perf_counter() - start
    print(json.dumps({"name": "bench_wall", "n": len(walls), "seconds": round(total, 1),
                      "rate": round(len(walls) / total, 4), "module_seconds": walls,
                      "target_seconds": 600, "quick": args.quick}), flush=True)
    return status


if __name__ == "__main__":
    sys.exit(main())
