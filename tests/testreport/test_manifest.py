"""The campaign manifest: the Earth rate from latitude and axis, and errors that name the key."""

from __future__ import annotations

import math

import pytest

from hrgtc.core.errors import InputError
from hrgtc.testreport.manifest import EARTH_RATE_DPH, earth_rate_component_dph, load_campaign

MINIMAL = """[unit]
serial = "SN-1"
firmware = "1.0"
[site]
latitude_deg = 45.0
axis = "up"
[[runs]]
file = "run.csv"
role = "turn-on"
"""


def test_earth_rate_is_wgs84_and_projects_on_the_axis():
    # WGS 84: 7.292115e-5 rad/s = 15.041067 °/h
    assert EARTH_RATE_DPH == pytest.approx(15.041067, abs=1e-6)
    phi = math.radians(52.0)
    assert earth_rate_component_dph(52.0, (0.0, 0.0, 1.0)) == pytest.approx(
        EARTH_RATE_DPH * math.sin(phi))
    assert earth_rate_component_dph(52.0, (1.0, 0.0, 0.0)) == pytest.approx(
        EARTH_RATE_DPH * math.cos(phi))
    assert earth_rate_component_dph(52.0, (0.0, 1.0, 0.0)) == 0.0
    # the axis tilted 45° from north to up: a dot product with the Earth's rotation vector
    tilted = (math.sqrt(0.5), 0.0, math.sqrt(0.5))
    expected = EARTH_RATE_DPH * (math.cos(phi) + math.sin(phi)) * math.sqrt(0.5)
    assert earth_rate_component_dph(52.0, tilted) == pytest.approx(expected)


def test_minimal_manifest(tmp_path):
    (tmp_path / "run.csv").write_text("", encoding="utf-8")
    manifest = tmp_path / "campaign.toml"
    manifest.write_text(MINIMAL, encoding="utf-8")
    campaign = load_campaign(manifest)
    assert campaign.serial == "SN-1" and campaign.runs[0].path == tmp_path / "run.csv"
    assert campaign.earth_rate_dph == pytest.approx(EARTH_RATE_DPH * math.sqrt(0.5))
    assert campaign.settings.coverage_k == 2.0 and campaign.model is None


@pytest.mark.parametrize(("old", "new", "message"), [
    ('latitude_deg = 45.0', 'latitude_deg = 95.0', "latitude_deg = 95.0"),
    ('axis = "up"', 'axis = "sideways"', "give the sensitive axis"),
    ('axis = "up"', 'axis = [0, 0, 0]', "give the sensitive axis"),
    ('role = "turn-on"', 'role = "warm"', "the roles are"),
    ('file = "run.csv"', 'file = "missing.csv"', "does not exist"),
    ('serial = "SN-1"\n', '', "serial is missing"),
    ('[[runs]]', '[settings]\nblock = 60\n[[runs]]', "'block' is not a setting"),
    ('[[runs]]', '[settings]\nblock_s = -1\n[[runs]]', "block_s = -1"),
])
def test_errors_name_the_key_and_the_fix(tmp_path, old, new, message):
    (tmp_path / "run.csv").write_text("", encoding="utf-8")
    manifest = tmp_path / "campaign.toml"
    manifest.write_text(MINIMAL.replace(old, new), encoding="utf-8")
    with pytest.raises(InputError, match=message):
        load_campaign(manifest)
