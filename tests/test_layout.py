"""The package layout stays true: the import-linter contracts of pyproject.toml hold.

The rules of the house (``docs/architecture.md``) are written once, as import-linter
contracts in ``[tool.importlinter]`` of ``pyproject.toml``, and ``make test`` runs
``lint-imports``. import-linter builds the graph of every import, including the ones
inside functions and under ``TYPE_CHECKING``, which the ast check this file held before
(module-level imports only, for the circles) missed. This file

- runs the contracts on ``src/hrgtc`` (so ``pytest`` alone checks them too),
- makes sure every top-level module or package is placed in the layers contract (import-linter
  itself says nothing about a module that no contract names),
- shows that the contracts can fail: an upward import, a lazy circle, an import of
  ``hrgtc.cli`` and numpy in the settings planted in a copy of the package are each reported.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SOURCE = ROOT / "src" / "hrgtc"
LINT_IMPORTS = Path(sys.executable).with_name("lint-imports")
PYPROJECT = ROOT / "pyproject.toml"
CONFIG = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["importlinter"]


def lint_imports(source_parent: Path) -> subprocess.CompletedProcess[str]:
    """Run ``lint-imports`` with pyproject's contracts on the ``hrgtc`` under ``source_parent``."""
    env = {**os.environ, "PYTHONPATH": str(source_parent)}
    assert LINT_IMPORTS.exists(), "import-linter is missing: pip install -e '.[test]'"
    return subprocess.run([str(LINT_IMPORTS), "--no-cache", "--no-logo", str(PYPROJECT)],
                          capture_output=True, text=True, env=env, cwd=source_parent, timeout=120)


def layered_modules() -> set[str]:
    (layers,) = [c["layers"] for c in CONFIG["contracts"]
                 if c["type"] == "layers" and "containers" not in c]
    names = set()
    for layer in layers:
        names.update(part.strip().strip("()") for part in re.split(r"[|:]", layer))
    return names


def test_the_contracts_hold():
    result = lint_imports(SOURCE.parent)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


def test_every_top_level_module_has_a_layer():
    top = {f"hrgtc.{p.stem}" for p in SOURCE.glob("*.py") if p.name != "__init__.py"}
    top |= {f"hrgtc.{p.parent.name}" for p in SOURCE.glob("*/__init__.py")}
    missing = sorted(top - layered_modules())
    assert not missing, (f"{missing}: not in the layers contract of pyproject.toml "
                         "([tool.importlinter]); add each to the layer it belongs to")


def test_at_most_eight_modules_at_the_top():
    """Issue 22: the top of the package shows the stages, not a flat list of modules."""
    modules = sorted(p.name for p in SOURCE.glob("*.py") if p.name != "__init__.py")
    assert len(modules) <= 8, modules


def test_the_package_root_imports_only_the_version():
    """``import hrgtc`` stays cheap: it loads ``hrgtc.core.meta`` (and its light package) and
    no stage."""
    code = "import sys, hrgtc; print(sorted(m for m in sys.modules if m.startswith('hrgtc')))"
    env = {**os.environ, "PYTHONPATH": str(SOURCE.parent)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         check=True, timeout=60).stdout
    assert out.strip() == "['hrgtc', 'hrgtc.core', 'hrgtc.core.meta']"


@pytest.mark.parametrize(("module", "text", "broken"), [
    # a lower stage reaching up, inside a function (the old ast test saw this one too)
    ("recording/_planted.py", "def f():\n    from hrgtc.report import build_report\n",
     "Stages import only downwards"),
    # a circle closed by a lazy import (the old test looked at module-level imports only)
    ("export/c/_planted.py", "def f():\n    from hrgtc.export.c import text\n",
     "No import circles"),
    # the library importing the command line
    ("evaluation/_planted.py", "from hrgtc.cli import options\n",
     "Nothing imports the command line"),
    # numpy in the settings, which hrgtc --help imports (lazily too)
    ("settings/_planted.py", "def f():\n    import numpy\n",
     "The settings import only the standard library"),
])
def test_the_contracts_catch_a_planted_import(tmp_path, module, text, broken):
    copy = tmp_path / "hrgtc"
    shutil.copytree(SOURCE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    target = copy / module
    target.write_text(text, encoding="utf-8")
    if module.startswith("export"):
        # close the circle: c/text (lazily) imports the planted module, which imports c/text
        c_text = copy / "export" / "c" / "text.py"
        c_text.write_text(c_text.read_text(encoding="utf-8")
                          + "\n\ndef _planted():\n    from hrgtc.export.c import _planted\n",
                          encoding="utf-8")
    result = lint_imports(tmp_path)
    assert result.returncode != 0
    assert re.search(rf"^{re.escape(broken)}.* BROKEN$", result.stdout, re.M), result.stdout
