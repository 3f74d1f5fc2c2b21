"""Golden model files of every released schema version, and what today's code makes of them.

``tests/data/golden-models/vN/*.json`` are real model files written by ``hrgtc calibrate``
of the commit named at the end of each file name (see the folder's README). Beside each
file, ``<name>.expected/`` holds what today's code gives for it: the C export
(``hrgtc export-c``), the parameter file (``--format params``), or the export's refusal
(``refused.txt``), and ``model.json``, the file's parameters as today's code writes them
(:func:`resaved`). :mod:`tests.test_golden_models` checks every file against them.

Regenerate the expected outputs (only after a deliberate change of the C export or of the
model file's serialisation, and say so in the commit)::

    PYTHONPATH=src python tests/golden_models.py
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

GOLDEN = Path(__file__).parent / "data" / "golden-models"
#: What each export writes: the --format value and the CLI's further options.
EXPORTS = {"c": ["--format", "c"], "params": ["--format", "params"]}


def golden_files() -> list[Path]:
    """Every golden model file, in version then name order."""
    return sorted(GOLDEN.glob("v*/*.json"))


def expected_dir(path: Path) -> Path:
    """The folder of today's expected outputs for a golden model file."""
    return path.with_suffix(".expected")


def resaved(path: Path) -> str:
    """The golden file loaded and written again by today's code, provenance left out."""
    from hrgtc.model import load_model
    from hrgtc.model_schema import parameters_sha256, strict

    document = strict(load_model(path).to_dict())
    document.pop("provenance", None)
    document["parameters_sha256"] = parameters_sha256(document)
    return json.dumps(document, indent=2, allow_nan=False) + "\n"


def export(path: Path, kind: str, folder: Path) -> tuple[int, str]:
    """Run ``hrgtc export-c`` of a golden file into ``folder``: (exit code, output)."""
    from typer.testing import CliRunner

    from hrgtc.cli import app

    result = CliRunner().invoke(app, ["export-c", str(path), "-o", str(folder),
                                      *EXPORTS[kind]], terminal_width=400)
    return result.exit_code, result.output


def refusal(output: str, path: Path) -> str:
    """An export's error message with the golden file's own path left out."""
    return " ".join(output.replace(str(path), path.name).split()) + "\n"


def regenerate() -> None:
    """Write every golden file's expected outputs with today's code."""
    for path in golden_files():
        target = expected_dir(path)
        shutil.rmtree(target, ignore_errors=True)
        target.mkdir()
        (target / "model.json").write_text(resaved(path), encoding="utf-8")
        for kind in EXPORTS:
            folder = target / kind
            code, output = export(path, kind, folder)
            if code != 0:
                folder.mkdir(exist_ok=True)
                (folder / "refused.txt").write_text(refusal(output, path), encoding="utf-8")
        print(f"wrote {target}")


if __name__ == "__main__":
    sys.exit(regenerate())
