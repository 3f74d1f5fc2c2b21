"""Start-up time of the ``hrgtc`` command: ``--help``, ``--version`` and each command's ``--help``.

The target (issue 9): every ``--help`` returns in under 1 s on this project's
2-core machine. Each figure is the median of several runs of a fresh process,
beside two references measured in the same run: a bare ``python -c pass`` (the
interpreter's own floor) and ``python -c "import hrgtc.pipeline.calibration, hrgtc.report,
hrgtc.simulate"`` (what every start cost when the commands imported the library
eagerly).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

COMMANDS = ("paper", "simulate", "info", "calibrate", "compensate", "evaluate", "report", "fleet",
            "export-c", "demo")


def _hrgtc() -> str:
    return str(Path(sys.executable).with_name("hrgtc"))


def _median_seconds(argv: list[str], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def run(quick: bool = False) -> list[dict]:
    repeat = 3  # median of 3 fresh processes per figure (7 took minutes of make bench)
    floor = _median_seconds([sys.executable, "-c", "pass"], repeat)
    eager = _median_seconds(
        [sys.executable, "-c", "import hrgtc.pipeline.calibration, hrgtc.report, hrgtc.simulate"],
        repeat)
    out = []
    cases = [["--help"], ["--version"], *([c, "--help"] for c in COMMANDS)]
    for args in cases:
        seconds = _median_seconds([_hrgtc(), *args], repeat)
        out.append({
            "name": "cli_start " + " ".join(args), "n": repeat, "seconds": round(seconds, 3),
            "rate": round(1.0 / seconds, 2), "target_seconds": 1.0,
            "python_bare_seconds": round(floor, 3), "eager_import_seconds": round(eager, 3),
            "ratio_to_eager_import": round(seconds / eager, 3),
        })
    return out


if __name__ == "__main__":
    import json

    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
