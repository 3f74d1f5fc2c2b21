"""Do ``hrgtc calibrate``'s results stay the same? Hashes to compare before and after a change.

    python bench/check_calibrate_unchanged.py OUT_DIR [--full]

Runs ``hrgtc calibrate --json`` (as a fresh process, the hrgtc on the path of this
interpreter) on

* the quick demo campaign (``DemoSettings.quick()``: the soaks and the cool-down of
  ``bench/bench_commands.py``), and with ``--full`` the full one the benchmark times;
* each real recording of ``tests/real_corpus.py`` as its newcomer's run calls it (the
  column mapping and units, ``--holdout-fraction 0.4``);
* the PAN cold test as ``tests/test_against_a_line.py`` calls it;

and writes into ``OUT_DIR`` each case's ``--json`` document and model file with
``created_utc`` (and the temporary folder's name) taken out, plus ``hashes.json``: one
SHA-256 per case and file. Run it on the checkout before a change and after it, and
``diff -r`` the two folders: any difference is a changed figure to explain.
"""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
ROOT = BENCH.parent
HRGTC = str(Path(sys.executable).with_name("hrgtc"))
PAN = ROOT / "tests" / "data" / "pan-cold-test"
PAN_ARGS = (
    "--thermometer", "sensor", "--gaps", "bridge", "--time-unit", "ms", "--rate-unit", "radps",
    "--col", "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
    "rate_dph_z=gyroz rad/s,temperature_c=temp",
    "--temp-ref", str(PAN / "pan_etu_cold_handlog_2020-03-07.csv"),
    "--temp-ref-col", "time_s=Time,temperature_c=C1 (C)", "--temp-ref-start", "15:45",
    "--holdout-fraction", "0.4")


def _scrub(value: object, folder: str) -> object:
    """``value`` without ``created_utc`` keys, ``folder`` replaced by ``<tmp>``."""
    if isinstance(value, dict):
        return {k: _scrub(v, folder) for k, v in value.items() if k != "created_utc"}
    if isinstance(value, list):
        return [_scrub(v, folder) for v in value]
    if isinstance(value, str):
        return value.replace(folder, "<tmp>")
    return value


def _canonical(text: str, folder: str) -> str:
    return json.dumps(_scrub(json.loads(text), folder), indent=1, sort_keys=True) + "\n"


def calibrate(name: str, args: list[str], folder: Path, out: Path) -> dict[str, str]:
    """Run one case; write its scrubbed documents into ``out``; their hashes."""
    model = folder / f"{name}.model.json"
    result = subprocess.run([HRGTC, "calibrate", *args, "-o", str(model), "--force", "--json"],
                            capture_output=True, text=True, env={**os.environ, "COLUMNS": "200"})
    if result.returncode != 0:
        raise SystemExit(f"{name}: exit {result.returncode}\n{result.stdout}\n{result.stderr}")
    hashes = {}
    stdout = result.stdout[result.stdout.index("{"):]
    for kind, text in (("document", stdout), ("model", model.read_text(encoding="utf-8"))):
        canonical = _canonical(text, str(folder))
        (out / f"{name}.{kind}.json").write_text(canonical, encoding="utf-8")
        hashes[kind] = hashlib.sha256(canonical.encode()).hexdigest()
    print(name, hashes, flush=True)
    return hashes


def cases(folder: Path, full: bool) -> dict[str, list[str]]:
    """Each case's calibrate arguments (the demo campaigns are simulated into ``folder``)."""
    sys.path[:0] = [str(BENCH), str(ROOT / "tests")]
    from bench_commands import _campaign

    from real_corpus import CORPUS

    out = {}
    for label, quick in (("demo_quick", True), *((("demo_full", False),) if full else ())):
        soaks, cool = _campaign(folder / label, quick)
        out[label] = ["--soak", *soaks, "--drift", cool]
    for real in CORPUS:
        out[real.name] = ["--drift", str(real.unpacked(folder)), *real.args,
                          "--holdout-fraction", "0.4"]
    out["pan-cold-test"] = ["--drift", str(PAN / "pan_tvc_cold_2020-03-07.csv"), *PAN_ARGS]
    return out


def main(argv: list[str]) -> int:
    out = Path(argv[0])
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        hashes = {name: calibrate(name, args, folder, out)
                  for name, args in cases(folder, "--full" in argv).items()}
    (out / "hashes.json").write_text(json.dumps(hashes, indent=1, sort_keys=True) + "\n",
                                     encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
