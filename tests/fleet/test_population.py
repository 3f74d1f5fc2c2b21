"""Tests of hrgtc.fleet.population: the simulated population and its documented spread."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.fleet.population import (
    AXES,
    F20_HZ,
    SPREAD,
    draw_instrument,
    draw_unit,
    draw_units,
    relative_law,
    true_frequency_hz,
    truth,
)
from hrgtc.simulate.laws import table1_frequency_law


def test_relative_law_is_eq18_around_20c():
    law = table1_frequency_law()
    r = relative_law()
    f20 = law.frequency_hz(np.array(20.0))
    t = np.linspace(-20, 40, 7)
    x = t - 20.0
    assert np.allclose(f20 * (1 + r[0] * x + r[1] * x**2 + r[2] * x**3), law.frequency_hz(t),
                       rtol=1e-13)


def test_draws_are_reproducible_and_independent_of_the_fleet_size():
    a, draw_a = draw_unit(7, 3)
    units = draw_units(5, 7)
    assert units[3][0] == a and units[3][1] == draw_a
    assert a.name == "s7-u0003"
    assert draw_unit(8, 3)[0] != a


def test_spread_is_the_documented_one():
    draws = [d for _, d in draw_units(400, 11)]
    f20 = np.array([d["f20_hz"] for d in draws])
    scale = np.array([d["tc_scale"] for d in draws])
    assert f20.mean() == pytest.approx(F20_HZ, abs=3.0)
    assert f20.std() == pytest.approx(SPREAD["f20_hz"], rel=0.15)
    assert scale.std() == pytest.approx(SPREAD["tc_scale"], rel=0.15)
    unit, draw = draw_unit(11, 0)
    record = truth(unit, draw)
    assert float(true_frequency_hz(record, 20.0)) == pytest.approx(draw["f20_hz"], rel=1e-12)


def test_an_instruments_axes_are_drawn_units_in_one_housing():
    instrument, draws = draw_instrument(7, 3)
    assert instrument.name == "s7-u0003" and instrument.axis_names == AXES
    assert draw_instrument(7, 3, 2)[0].axes["y"] == instrument.axes["y"]  # axis j alone
    housing = {u.thermal.tau_housing_s for u in instrument.axes.values()}
    resonators = {u.thermal.tau_resonator_s for u in instrument.axes.values()}
    assert len(housing) == 1 and len(resonators) == 3
    # each axis is drawn as a unit is, from its own seed: other laws than unit 3's
    unit, _ = draw_unit(7, 3)
    f20 = {axis: draws[axis]["f20_hz"] for axis in AXES}
    assert len({*f20.values(), unit.frequency_law.frequency_hz(np.array(20.0)).item()}) == 4
    for axis, gyro in instrument.axes.items():
        record = truth(gyro, draws[axis])
        assert record["unit"]["name"] == f"s7-u0003:{axis}"
        assert float(true_frequency_hz(record, 20.0)) == pytest.approx(f20[axis], rel=1e-12)
    spread = np.array([d["f20_hz"] for k in range(60) for d in draw_instrument(11, k)[1].values()])
    assert spread.std() == pytest.approx(SPREAD["f20_hz"], rel=0.2)
    with pytest.raises(InputError, match="1 to 3 axes"):
        draw_instrument(7, 3, 4)
