"""Named simulated units (hrgtc.simulate.units): the three-axis imu-3, the scale-factor
law on units, JSON round trips, and the checks of MultiAxisUnit."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.simulate import units
from hrgtc.simulate.thermal import ThermalNetwork

EARTH_RATE_DPH = 15.0410686  # 360° per sidereal day, IERS


@pytest.mark.parametrize("name", ["paper-unit", "unit-b", "imu-3"])
def test_units_round_trip_through_json(name):
    unit = units.get(name)
    again = units.unit_from_dict(json.loads(json.dumps(unit.to_dict())))
    assert again == unit
    assert again.to_dict() == unit.to_dict()


def test_paper_unit_and_unit_b_have_no_scale_factor_law():
    for name in ("paper-unit", "unit-b"):
        unit = units.get(name)
        assert unit.scale_factor_law is None
        assert "scale_factor_law" not in unit.to_dict()  # their recordings' metadata unchanged


def test_imu3_axes_are_different_resonators_in_one_housing():
    imu = units.get("imu-3")
    assert isinstance(imu, units.MultiAxisUnit) and imu.axis_names == ("x", "y", "z")
    freqs = [gyro.frequency_law.frequency_hz(np.array(20.0)) for gyro in imu.axes.values()]
    assert min(abs(a - b) for a, b in [(freqs[0], freqs[1]), (freqs[1], freqs[2]),
                                       (freqs[0], freqs[2])]) > 500.0  # different shells
    assert len({g.thermal.tau_housing_s for g in imu.axes.values()}) == 1
    assert len({g.thermal.tau_resonator_s for g in imu.axes.values()}) == 3
    assert len({g.bias_law for g in imu.axes.values()}) == 3
    span = np.linspace(-20.0, 60.0, 81)
    for gyro in imu.axes.values():
        ppm = gyro.scale_factor_law.ppm(span)
        assert 200.0 < np.ptp(ppm) < 1000.0  # several hundred ppm over -20...60 °C
    # Level at 40° N, x north, y east, z up: the horizontal and vertical components.
    rates = imu.input_rate_dph
    assert math.hypot(rates["x"], rates["z"]) == pytest.approx(EARTH_RATE_DPH, rel=1e-6)
    assert rates["y"] == 0.0
    assert math.degrees(math.atan2(rates["z"], rates["x"])) == pytest.approx(40.0)
    assert "axis y" in imu.summary().text() and "scale factor" in imu.summary().text()


def test_multi_axis_unit_checks():
    imu = units.get("imu-3")
    x = imu.axes["x"]
    other_housing = replace(x, thermal=ThermalNetwork(900.0, 2400.0))
    with pytest.raises(InputError, match="share one housing but have tau_housing_s"):
        units.MultiAxisUnit("u", "", {"x": x, "y": other_housing})
    with pytest.raises(InputError, match="axis name 'x_1' must be a letter"):
        units.MultiAxisUnit("u", "", {"x_1": x})
    with pytest.raises(InputError, match="must be finite rates of axes"):
        units.MultiAxisUnit("u", "", {"x": x}, input_rate_dph={"q": 1.0})
    with pytest.raises(InputError, match="needs at least one axis"):
        units.MultiAxisUnit("u", "", {})
    assert units.MultiAxisUnit("u", "", {"a": x}).input_rate_dph == {"a": 0.0}
