"""``calibrate`` on both cores gives the calibration it gives on one (hrgtc.core.forked).

The soaks' passes (and the drift fit's window pass over the runs) run in forked worker
processes when the files are large; here they are forced on a small campaign
(``HRGTC_PROCESSES``) and the whole result, its model file and the warnings, in their
order, are compared with the in-process run's. Each run starts from empty memos (the
files validated, the spike filter's pieces), as a fresh command does.

Truth: the same calibration in one process; a soak whose 10 s spike burst the reader
drops and counts (a warning said from the soak pass).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hrgtc.core import forked
from hrgtc.model import save_model
from hrgtc.pipeline.calibration import calibrate
from hrgtc.recording import ReadOptions, spikes, validated
from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles


@pytest.fixture(scope="module")
def campaign(tmp_path_factory) -> dict:
    folder = tmp_path_factory.mktemp("processes")
    soaks = simulate_files([profiles.soak(s, 4.0) for s in (-20.0, 0.0, 20.0, 40.0)],
                           folder / "soaks", "parquet", sample_rate_hz=2.0, seed=4)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 3.0)], folder / "cool", "parquet",
                          sample_rate_hz=2.0, seed=5)
    paths = [Path(w.path) for w in soaks]
    frame = pd.read_parquet(paths[1])  # a few lone spikes in one soak's rate
    rows = np.arange(5000, 5000 + 40 * 97, 97)
    frame.loc[rows, "rate_dph"] += 5000.0
    frame.to_parquet(paths[1])
    return {"soaks": paths, "cool": Path(cool[0].path), "folder": folder}


def _scrub(value: object) -> object:
    """``value`` without its creation times."""
    if isinstance(value, dict):
        return {k: _scrub(v) for k, v in value.items() if k != "created_utc"}
    if isinstance(value, list):
        return [_scrub(v) for v in value]
    return value


def _calibrated(campaign: dict, processes: str, monkeypatch) -> tuple[str, list]:
    monkeypatch.setenv(forked.ENVIRONMENT, processes)
    validated.forget()
    spikes._MEMO.clear()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = calibrate(campaign["soaks"], [campaign["cool"]],
                           read_options=ReadOptions().with_spike_default("drop"))
    model = campaign["folder"] / f"model-{processes}.json"
    save_model(result.model, model)
    document = json.loads(model.read_text(encoding="utf-8"))
    return (json.dumps(_scrub([result.to_dict(), document]), sort_keys=True, default=str),
            [(str(w.message), w.category, w.filename, w.lineno) for w in caught])


@pytest.mark.skipif(not forked.sys.platform.startswith("linux"), reason="fork: Linux only")
def test_calibrate_on_two_processes_equals_one(campaign, monkeypatch):
    one, said_one = _calibrated(campaign, "1", monkeypatch)
    two, said_two = _calibrated(campaign, "2", monkeypatch)
    assert two == one
    assert said_two == said_one
    assert any("spike" in text for text, *_ in said_one)  # said by a soak pass too
