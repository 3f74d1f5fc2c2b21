"""Helpers of the tests of the file formats: the real sample files and ``hrgtc info``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

#: The real sample files, each folder with its licence and README (source and commit).
DATA = Path(__file__).parents[2] / "data" / "formats"


@pytest.fixture
def data() -> Path:
    return DATA


def info(path: Path, *args: str) -> tuple[int, dict[str, Any] | None, str]:
    """``hrgtc info PATH ARGS --json``: exit code, the JSON (None if none) and the output."""
    from hrgtc.cli import app

    result = CliRunner().invoke(app, ["info", str(path), *args, "--json"])
    text = result.stdout
    try:
        found = json.loads(text[text.index("{"):]) if "{" in text else None
    except ValueError:
        found = None
    return result.exit_code, found, result.output


@pytest.fixture
def run_info():
    return info
