"""Simulated campaigns shared by the test-report tests (built once per session;
tests/testreport_campaign.py writes them)."""

from __future__ import annotations

from pathlib import Path

import pytest

from testreport_campaign import write_campaign

GOLDEN_MODEL = (Path(__file__).parents[1] / "data" / "golden-models" / "v2"
                / "unit-resonator-254ab6c.json")  # a paper-unit model (tests/golden_models.py)


@pytest.fixture(scope="session")
def campaign(tmp_path_factory):
    """Turn-ons, soaks and a sweep of the paper-unit, with its model; no rate table."""
    return write_campaign(tmp_path_factory.mktemp("campaign"), model=GOLDEN_MODEL)


@pytest.fixture(scope="session")
def table_campaign(tmp_path_factory):
    """The same with a rate table of the imu-3's x axis (the unit with a scale-factor law)."""
    return write_campaign(tmp_path_factory.mktemp("table-campaign"), with_table=True)


@pytest.fixture(scope="session")
def report(campaign):
    from hrgtc.testreport import test_report

    return test_report(campaign.manifest)
