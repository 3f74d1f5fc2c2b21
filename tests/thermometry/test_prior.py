"""Tests of hrgtc.thermometry.prior: the Gaussian population prior of the thermometer."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial import Polynomial

from hrgtc.core.errors import InputError
from hrgtc.thermometry import fit
from hrgtc.thermometry.prior import (
    ThermometerPrior,
    fit_with_prior,
    load_prior,
    relative_coefficients,
    save_prior,
)

SETPOINTS = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0])
# Eq. (18) of [1], ascending powers of T
EQ18 = (4424.900952381, 0.371555556, -0.000970238, 1.5278e-05)


def population(n: int, seed: int, spread: float = 0.03, independent: float = 0.01):
    """Exact cubic laws: f20 +- 18 Hz, relative law x (1 +- spread), curvature +- independent."""
    rng = np.random.default_rng(seed)
    law = Polynomial(EQ18)
    rel = law(Polynomial([20.0, 1.0])).coef
    rel = rel[1:] / rel[0]
    laws = []
    for _ in range(n):
        s = 1 + spread * rng.standard_normal()
        r = np.array([1.0, s * rel[0], s * rel[1] * (1 + independent * rng.standard_normal()),
                      s * rel[2] * (1 + independent * rng.standard_normal())])
        f20 = 4432.07 + 18.0 * rng.standard_normal()
        laws.append(f20 * Polynomial(r)(Polynomial([-20.0, 1.0])))
    return laws


def test_relative_coefficients_are_basis_independent():
    th = fit(SETPOINTS, Polynomial(EQ18)(SETPOINTS))
    a0, b = relative_coefficients(th, 10.0, 30.0)
    assert a0 == pytest.approx(Polynomial(EQ18)(10.0), rel=1e-12)
    z = np.linspace(-1, 1, 7)
    assert np.allclose(a0 * (1 + Polynomial([0.0, *b])(z)), Polynomial(EQ18)(10 + 30 * z),
                       rtol=1e-12)


def test_prior_with_two_and_three_soaks_recovers_held_out_units():
    laws = population(30, seed=3)
    prior = ThermometerPrior.from_thermometers([fit(SETPOINTS, law(SETPOINTS)) for law in laws])
    grid = np.linspace(-20, 40, 241)
    for law in population(5, seed=99):
        for soaks, limit in (([-20.0, 40.0], 0.05), ([-20.0, 10.0, 40.0], 0.02)):
            t = np.array(soaks)
            result = fit_with_prior(t, law(t), prior, 1e-4)
            error = result.thermometer.temperature(law(grid), warn=False) - grid
            assert np.max(np.abs(error)) < limit
            assert result.thermometer.temperature_range_c == (-20.0, 40.0)
            # the 1-sigma band covers the error within a few sigma
            assert np.all(np.abs(error) < 4 * result.temperature_std_c(grid) + 1e-3)


def test_many_points_and_a_weak_prior_give_least_squares():
    law = population(1, seed=5)[0]
    laws = population(30, seed=4, spread=0.5, independent=0.5)
    prior = ThermometerPrior.from_thermometers([fit(SETPOINTS, x(SETPOINTS)) for x in laws])
    t = np.linspace(-20, 40, 13)
    result = fit_with_prior(t, law(t), prior, 1e-6)
    assert np.allclose(result.thermometer.coefficients, law.coef, rtol=1e-6)


def test_prior_file_round_trip(tmp_path):
    laws = population(8, seed=1)
    prior = ThermometerPrior.from_thermometers([fit(SETPOINTS, x(SETPOINTS)) for x in laws],
                                               [f"u{k}" for k in range(8)])
    path = save_prior(prior, tmp_path / "prior.json")
    assert load_prior(path) == prior
    assert "prior of 8 units" in prior.summary().text()
    with pytest.raises(InputError, match="not an hrgtc prior file"):
        (tmp_path / "other.json").write_text('{"schema": "hrgtc.model"}')
        load_prior(tmp_path / "other.json")


def test_refuses_a_unit_of_another_kind():
    laws = population(10, seed=2)
    prior = ThermometerPrior.from_thermometers([fit(SETPOINTS, x(SETPOINTS)) for x in laws])
    t = np.array([-20.0, 40.0])
    smaller = Polynomial(np.array(EQ18) * 5700 / 4432)  # another shell: ~5.7 kHz
    with pytest.raises(InputError, match="differ in kind"):
        fit_with_prior(t, smaller(t), prior)
    steeper = Polynomial([EQ18[0], 1.5 * EQ18[1], EQ18[2], EQ18[3]])  # TCF 50 % higher
    with pytest.raises(InputError, match="differs in kind"):
        fit_with_prior(t, steeper(t), prior)
    with pytest.raises(InputError, match="outside the prior's range"):
        fit_with_prior(np.array([-40.0, 20.0]), laws[0](np.array([-40.0, 20.0])), prior)
    with pytest.raises(InputError, match="at least 2"):
        fit_with_prior(np.array([20.0]), laws[0](np.array([20.0])), prior)
    with pytest.raises(InputError, match="order 3 but order 2"):
        fit_with_prior(t, laws[0](t), prior, order=2)


def test_too_few_units_for_a_prior():
    th = fit(SETPOINTS, Polynomial(EQ18)(SETPOINTS))
    with pytest.raises(InputError, match="at least 5 calibrated units"):
        ThermometerPrior.from_thermometers([th, th])
