"""Shared fixtures: simulated campaigns built once per test session.

Helpers (exact reference solvers, synthetic runs, campaigns) live beside the tests
in ``tests/`` and are importable by name (``pythonpath`` in pyproject.toml).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from filelock import FileLock
from hypothesis import settings

from campaign import Campaign, InstrumentCampaign, make_campaign, make_instrument_campaign

# The same examples on every run (CI must not flake); no example database between runs.
settings.register_profile("hrgtc", derandomize=True, database=None, deadline=None)
settings.load_profile("hrgtc")


@pytest.fixture(scope="session")
def campaign_factory(tmp_path_factory):
    """``campaign_factory(unit, sample_rate_hz=5.0, hours=5.0, seed=1)`` -> :class:`Campaign`.

    Each campaign is simulated once for the whole run: the pytest-xdist workers share a
    folder, and a file lock lets the first worker build it while the others wait for it.
    Tests only read the files.
    """
    shared = tmp_path_factory.getbasetemp().parent  # the same for every xdist worker

    def build(unit: str, sample_rate_hz: float = 5.0, hours: float = 5.0,
              seed: int = 1) -> Campaign:
        folder = shared / f"campaign-{unit}-{sample_rate_hz:g}hz-{hours:g}h-seed{seed}"
        done = folder / "campaign.json"
        with FileLock(str(folder) + ".lock"):
            if not done.exists():
                files = make_campaign(folder, unit, sample_rate_hz, hours, seed)
                done.write_text(json.dumps({
                    "soaks": [str(p) for p in files.soaks], "cooldown": str(files.cooldown),
                    "warmup": str(files.warmup)}))
        data = json.loads(done.read_text())
        return Campaign([Path(p) for p in data["soaks"]], Path(data["cooldown"]),
                        Path(data["warmup"]))

    return build


@pytest.fixture(scope="session")
def paper_campaign(campaign_factory) -> Campaign:
    """The paper-unit at 2 Hz (evaluation and report do not depend on the rate)."""
    return campaign_factory("paper-unit", sample_rate_hz=2.0)


@pytest.fixture(scope="session")
def imu_campaign(tmp_path_factory) -> InstrumentCampaign:
    """The three-axis ``imu-3`` at 1 Hz with rate tables, simulated once per session."""
    folder = tmp_path_factory.getbasetemp().parent / "campaign-imu-3-1hz"
    done = folder / "campaign.json"
    with FileLock(str(folder) + ".lock"):
        if not done.exists():
            files = make_instrument_campaign(folder)
            done.write_text(json.dumps({k: [str(p) for p in v] if isinstance(v, list)
                                        else str(v) for k, v in vars(files).items()}))
    data = json.loads(done.read_text())
    return InstrumentCampaign(**{k: [Path(p) for p in v] if isinstance(v, list) else Path(v)
                                 for k, v in data.items()})
