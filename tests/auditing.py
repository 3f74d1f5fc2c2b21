"""Run corrupted inputs through the CLI and sort each outcome into one of five classes.

Issue 21, Deliver 7: the corpus of :mod:`corruptions` and :mod:`model_corruptions` goes
through ``info``, ``compensate``, ``evaluate``, ``calibrate --thermometer sensor``,
``export-c`` (C and ``--format params``) and ``report``, in-process. Each outcome is:

* ``clear``: exit 2, one ``error:`` line naming an input file and every string the case
  expects (column, row, the option of the fix);
* ``correct``: exit 0 on a case that must be accepted, with the undamaged file's result
  (compensated rates, bias stabilities, model coefficients, rows) where that is compared,
  and the expectation's strings in its output (a dropped row reported in the accounting);
* ``misleading``: an error that does not name what the case expects, or that refuses a
  valid file;
* ``silent``: exit 0 where an error was due, or a result that differs from the undamaged
  file's (``undetectable`` counts those the docs name as impossible to tell);
* ``traceback``: a Python traceback or an "internal error".

``bench/audit.py`` runs everything and prints the counts; ``tests/cli/test_fuzz.py`` runs
a small fixed sample in ``make test``.
"""

from __future__ import annotations

import json
import math
import shutil
import warnings
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
from typer.testing import CliRunner

from hrgtc.cli import app

from corruptions import MODEL_COMMANDS, RECORDING_COMMANDS, Case, Expect, Material

CLASSES = ("clear", "correct", "misleading", "silent", "traceback")
runner = CliRunner()


def argv(command: str, recording: Path, model: Path, out: Path) -> list[str]:
    """The command line of ``command`` on a recording and a model, writing into ``out``."""
    lines = {
        "info": ["info", recording, "--json"],
        "compensate": ["compensate", recording, "-m", model, "-o", out / "out.parquet",
                       "--json", "--force"],
        "evaluate": ["evaluate", recording, "-m", model, "--json"],
        "calibrate": ["calibrate", "--thermometer", "sensor", "--drift", recording, "-o",
                      out / "model.json", "--json", "--force"],
        "export-c": ["export-c", model, "-o", out / "c", "--json", "--force"],
        "export-params": ["export-c", model, "-o", out / "params", "--format", "params",
                          "--json", "--force"],
        "report": ["report", recording, "-m", model, "-o", out / "report.html", "--json",
                   "--force", "--max-points", "500"],
    }
    return [str(a) for a in lines[command]]


def _strip(value: Any) -> Any:
    """JSON without the names of files (they differ between a case and the undamaged one)."""
    if isinstance(value, dict):
        return {k: _strip(v) for k, v in value.items()
                if k not in ("file", "source", "output", "path", "created_utc", "provenance",
                             "inputs", "sha256", "model_sha256", "seconds", "written")}
    if isinstance(value, list):
        return [_strip(v) for v in value]
    return value


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=1e-9,
                                                                 abs_tol=1e-12)
    return a == b


def signature(command: str, stdout: str, out: Path) -> Any:
    """What must equal the undamaged file's result for a case that is to be read the same."""
    if command == "compensate":
        table = pq.read_table(out / "out.parquet")
        return {n: table.column(n).to_numpy() for n in table.column_names
                if n.startswith(("rate_comp_dph", "bias_model_dph", "in_range"))}
    if command == "info":
        data = json.loads(stdout)
        return {"rows": data.get("rows"), "columns": sorted(
            str(c.get("name") if isinstance(c, dict) else c) for c in data.get("columns", []))}
    if command == "evaluate":
        return _strip(json.loads(stdout))
    if command == "calibrate":
        data = json.loads((out / "model.json").read_text())
        return _strip({k: v for k, v in data.items() if k in ("drift", "axes")})
    return None


def same_signature(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and a and all(isinstance(v, np.ndarray) for v in a.values()):
        return (isinstance(b, dict) and a.keys() == b.keys() and all(
            v.shape == b[k].shape and np.allclose(v, b[k], rtol=1e-9, atol=1e-9, equal_nan=True)
            for k, v in a.items()))
    return _same(a, b)


@dataclass
class Outcome:
    """One case through one command."""

    case: Case
    command: str
    verdict: str
    undetectable: bool = False
    message: str = ""


def classify(expect: Expect, code: int, text: str, crashed: bool, inputs: Iterable[Path],
             same: bool | None, output: str = "") -> str:
    """One of :data:`CLASSES` for an outcome (see the module docstring). ``output``: what
    an accepted case printed (its ``--json`` and warnings), which must hold every string
    of a ``"correct"`` expectation's ``names`` (a drop it must report)."""
    if crashed or "Traceback" in text or "internal error" in text:
        return "traceback"
    if code == 0:
        if expect.outcome == "error":
            return "silent"
        if expect.compare and same is False:
            return "silent"
        if expect.outcome == "correct" and not all(n in output for n in expect.names):
            return "silent"  # accepted, but what it left out is not reported
        return "correct"
    # the error is judged; warnings the command printed before it (shown as on a terminal)
    # are not the error
    start = 0 if text.startswith("error:") else text.find("\nerror:") + 1
    if code != expect.code or not text[start:].startswith("error:"):
        return "misleading"
    text = text[start:]
    if expect.outcome == "correct":
        return "misleading"  # a valid file refused
    named = any(p.name in text for p in inputs)
    wanted = all(n.lower() in text.lower() for n in expect.names)
    return "clear" if named and wanted else "misleading"


@dataclass
class Audit:
    """Runs cases and keeps their outcomes."""

    material: Material
    work: Path
    outcomes: list[Outcome] = field(default_factory=list)
    _baseline: dict[tuple[str, str], Any] = field(default_factory=dict)

    def _invoke(self, args: list[str]) -> tuple[int, str, str, bool]:
        with warnings.catch_warnings():
            # every warning reaches the command's own once-per-cause printing, as on a
            # terminal (Python's registry would hide a repeat from an earlier case)
            warnings.simplefilter("always")
            result = runner.invoke(app, args)
        crashed = result.exception is not None and not isinstance(result.exception, SystemExit)
        return result.exit_code, result.stdout, result.stderr.strip(), crashed

    def baseline(self, command: str, axes: str) -> Any:
        key = (command, axes)
        if key not in self._baseline:
            out = self._fresh("baseline")
            code, stdout, stderr, _ = self._invoke(argv(
                command, self.material.run_path(axes), self.material.model_for(axes), out))
            if code != 0:
                raise RuntimeError(f"the undamaged files fail {command}: {stderr[:300]}")
            self._baseline[key] = signature(command, stdout, out)
        return self._baseline[key]

    def _fresh(self, name: str) -> Path:
        folder = self.work / name
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        return folder

    def run(self, case: Case, commands: Iterable[str] | None = None) -> list[Outcome]:
        """Every command of ``case`` (those it has an expectation for)."""
        folder = self._fresh("case")
        path = case.make(self.material, folder)
        if case.target == "recording":
            recording, model = path, self.material.model_for(case.axes)
            default = RECORDING_COMMANDS
        else:
            recording, model = self.material.run_path(case.axes), path
            default = MODEL_COMMANDS
        found = []
        for command in commands or default:
            expect = case.expected(command)
            if expect is None:
                continue
            out = self._fresh("out")
            code, stdout, stderr, crashed = self._invoke(argv(command, recording, model, out))
            same = None
            if code == 0 and expect.compare and expect.outcome != "error":
                try:
                    same = same_signature(signature(command, stdout, out),
                                          self.baseline(command, case.axes))
                except (OSError, ValueError, KeyError) as exc:
                    same, stderr = False, f"result unreadable: {exc}"
            verdict = classify(expect, code, stderr if code else "", crashed,
                               (recording, model), same, stdout + stderr)
            if expect.outcome == "error_or_same" and verdict == "misleading":
                verdict = "clear" if code == 2 and path.name in stderr else verdict
            outcome = Outcome(case, command, verdict,
                              undetectable=verdict == "silent" and not expect.detectable,
                              message=(stderr or stdout)[:240].replace("\n", " "))
            found.append(outcome)
        self.outcomes += found
        return found

    def counts(self) -> dict[str, Counter]:
        """Per command, the count of each class (and ``undetectable`` among ``silent``)."""
        table: dict[str, Counter] = {}
        for o in self.outcomes:
            row = table.setdefault(o.command, Counter({c: 0 for c in CLASSES}))
            row[o.verdict] += 1
            row["undetectable"] += o.undetectable
        return table

    def render(self) -> str:
        """The counts as a text table, then every outcome that is not clear or correct."""
        lines = [f"{'command':<15}" + "".join(f"{c:>12}" for c in CLASSES)
                 + f"{'(undetect.)':>13}"]
        for command, row in self.counts().items():
            lines.append(f"{command:<15}" + "".join(f"{row[c]:>12}" for c in CLASSES)
                         + f"{row['undetectable']:>13}")
        bad = [o for o in self.outcomes if o.verdict not in ("clear", "correct")]
        if bad:
            lines += ["", "not clear, not correct (owner | command | case | message):"]
            lines += [f"  {o.verdict:<10} {o.case.owner:<8} {o.command:<13} {o.case.name} | "
                      f"{o.message[:160]}" for o in bad]
        return "\n".join(lines)
