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


def written(folder: Path, name: str, profile: Any, seed: int,
            rate_hz: float) -> tuple[Path, Any]:
    """``profile`` simulated at ``rate_hz`` and written to ``folder/name`` in chunks of 1000
    rows (the format chosen by the suffix), beside the simulator's own recording of it."""
    from hrgtc import simulate

    path = folder / name
    simulate.simulate_to_file(profile, path, sample_rate_hz=rate_hz, seed=seed,
                              chunk_rows=1000)
    return path, simulate.simulate_run(profile, sample_rate_hz=rate_hz, seed=seed)


def read_back(path: Path, truth: Any, profile: Any, seed: int) -> Any:
    """hrgtc's reading of ``path``: the simulator's arrays bit for bit and its metadata
    (asserted); the recording returned."""
    import numpy as np

    from hrgtc.recording import read
    from hrgtc.simulate.campaign import run_metadata

    back = read(path)
    assert back.names == truth.names
    for name in truth.names:
        assert np.array_equal(back[name].view(np.int64), truth[name].view(np.int64)), name
    assert back.metadata == run_metadata(profile, sample_rate_hz=truth.sample_rate_hz,
                                         seed=seed)
    return back


@pytest.fixture(scope="session")
def simulated_file():
    return written


@pytest.fixture
def check_read_back():
    return read_back
