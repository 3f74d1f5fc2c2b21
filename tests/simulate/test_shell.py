"""Tests of hrgtc.simulate.shell: shape integrals, natural frequency, temperature coefficient.

Independent truths: exact rational values of I(n) (substitution u = 1 + cos(phi)
turns I(n) into the polynomial integral of (2 - u)^(n-2) u^(-n-2) over [1, 2]),
mpmath quadrature of the integrands exactly as printed in Eq. (12) of [1], Eq. (14)
of [1] written out by hand, central finite differences, and exact scaling laws.

[1] Wang et al., Sensors 12(5), 6434-6446, 2012, doi:10.3390/s120506434
"""

from __future__ import annotations

import doctest
import json
import math
from fractions import Fraction
from functools import lru_cache

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import hrgtc.simulate.shell as shell_module
from hrgtc.core.errors import InputError
from hrgtc.simulate.shell import (
    DEFAULT_RADIUS_M,
    DEFAULT_SHELL,
    DEFAULT_THICKNESS_M,
    FUSED_QUARTZ,
    Material,
    Shell,
    frequency_temperature_coefficient,
    natural_frequency,
    shape_integral_i,
    shape_integral_j,
)


@lru_cache
def _mp_i(n: int) -> mpmath.mpf:
    """I(n) by mpmath, integrand as printed in Eq. (12) of [1]."""
    with mpmath.workdps(30):
        return mpmath.quad(
            lambda p: mpmath.sin(p) ** -3 * mpmath.tan(p / 2) ** (2 * n), [0, mpmath.pi / 2]
        )


@lru_cache
def _mp_j(n: int) -> mpmath.mpf:
    """J(n) by mpmath, integrand as printed in Eq. (12) of [1]."""
    with mpmath.workdps(30):
        return mpmath.quad(
            lambda p: (
                ((n + mpmath.cos(p)) ** 2 + 2 * mpmath.sin(p) ** 2)
                * mpmath.sin(p)
                * mpmath.tan(p / 2) ** (2 * n)
            ),
            [0, mpmath.pi / 2],
        )


def _exact_i(n: int) -> Fraction:
    """I(n) = integral_1^2 (2 - u)^(n-2) u^(-n-2) du, expanded binomially, exactly."""
    total = Fraction(0)
    for k in range(n - 1):  # (2 - u)^(n-2) = sum_k C(n-2, k) 2^(n-2-k) (-u)^k
        coef = Fraction(math.comb(n - 2, k) * 2 ** (n - 2 - k) * (-1) ** k)
        power = k - n - 2  # u^power, power <= -4 < -1
        total += coef * (Fraction(2) ** (power + 1) - 1) / (power + 1)
    return total


# --------------------------------------------------------------------------- I(n), J(n)


def test_i2_is_seven_twenty_fourths():
    # I(2) = 7/24 exactly (DESIGN.md; substitution u = 1 + cos(phi))
    assert _exact_i(2) == Fraction(7, 24)
    assert abs(shape_integral_i(2) - 7 / 24) < 1e-12
    assert shell_module.I(2) == shape_integral_i(2)


def test_j2_matches_mpmath_and_published_value():
    value = shape_integral_j(2)
    assert value == pytest.approx(float(_mp_j(2)), rel=1e-12)
    assert abs(value - 1.529610) < 1e-6  # DESIGN.md: J ≈ 1.52961
    assert shell_module.J(2) == value


@pytest.mark.parametrize("n", [3, 4, 6])
def test_shape_integrals_higher_modes(n):
    assert shape_integral_i(n) == pytest.approx(float(_mp_i(n)), rel=1e-12)
    assert shape_integral_i(n) == pytest.approx(float(_exact_i(n)), rel=1e-12)
    assert shape_integral_j(n) == pytest.approx(float(_mp_j(n)), rel=1e-12)


def test_i3_exact():
    assert _exact_i(3) == Fraction(17, 96)
    assert abs(shape_integral_i(3) - 17 / 96) < 1e-12


# --------------------------------------------------------------------------- frequency


def _eq14_hz(r, h, e, mu, rho):
    """Eq. (14) of [1] as printed (angular), divided by 2 pi, with mpmath I and J."""
    i2, j2 = float(_mp_i(2)), float(_mp_j(2))
    return 2 * h / r**2 * math.sqrt(3 * e / ((1 + mu) * rho) * i2 / j2) / (2 * math.pi)


def test_natural_frequency_matches_eq14():
    args = (15e-3, 0.78e-3, 72e9, 0.17, 2200.0)
    assert natural_frequency(*args) == pytest.approx(_eq14_hz(*args), rel=1e-12)
    assert isinstance(natural_frequency(*args), float)


def test_documented_fused_quartz_shell_near_4_4_khz():
    # DESIGN.md: r = 15 mm, h ≈ 0.78 mm sits near 4425 Hz; Table 1 of [1]: 4416.97-4439.20 Hz
    f = natural_frequency(
        15e-3,
        0.78e-3,
        FUSED_QUARTZ.youngs_modulus_pa,
        FUSED_QUARTZ.poisson,
        FUSED_QUARTZ.density_kg_m3,
    )
    assert 4300.0 < f < 4500.0
    assert DEFAULT_RADIUS_M == 15e-3 and DEFAULT_THICKNESS_M == 0.78e-3
    assert DEFAULT_SHELL.frequency_hz(FUSED_QUARTZ.reference_temperature_c) == pytest.approx(
        f, rel=1e-15
    )
    assert DEFAULT_SHELL.frequency_hz() == DEFAULT_SHELL.frequency_hz(20.0)


def test_scaling_laws_exact():
    base = natural_frequency(15e-3, 0.78e-3, 72e9, 0.17, 2200.0)
    scale = np.array([0.5, 2.0, 3.0, 10.0])
    np.testing.assert_allclose(
        natural_frequency(15e-3, 0.78e-3 * scale, 72e9, 0.17, 2200.0), base * scale, rtol=1e-14
    )
    np.testing.assert_allclose(
        natural_frequency(15e-3 * scale, 0.78e-3, 72e9, 0.17, 2200.0), base / scale**2, rtol=1e-14
    )
    np.testing.assert_allclose(
        natural_frequency(15e-3, 0.78e-3, 72e9 * scale, 0.17, 2200.0),
        base * np.sqrt(scale),
        rtol=1e-14,
    )
    np.testing.assert_allclose(
        natural_frequency(15e-3, 0.78e-3, 72e9, 0.17, 2200.0 * scale),
        base / np.sqrt(scale),
        rtol=1e-14,
    )


@settings(max_examples=40, deadline=None)
@given(
    r=st.floats(1e-3, 1.0),
    h_over_r=st.floats(1e-3, 0.2),
    e=st.floats(1e9, 1e12),
    mu=st.floats(0.0, 0.49),
    rho=st.floats(500.0, 20000.0),
    k=st.floats(0.1, 10.0),
)
def test_scaling_laws_property(r, h_over_r, e, mu, rho, k):
    h = h_over_r * r
    f = natural_frequency(r, h, e, mu, rho)
    assert f == pytest.approx(_eq14_hz(r, h, e, mu, rho), rel=1e-12)
    # Scaling the whole shell by k scales the frequency by 1/k (h/r^2).
    assert natural_frequency(k * r, k * h, e, mu, rho) == pytest.approx(f / k, rel=1e-13)


def test_broadcasting_shapes():
    r = np.array([[14e-3], [15e-3], [16e-3]])
    h = np.array([0.7e-3, 0.75e-3, 0.78e-3, 0.8e-3])
    out = natural_frequency(r, h, 72e9, 0.17, 2200.0)
    assert out.shape == (3, 4)
    assert out[1, 2] == natural_frequency(15e-3, 0.78e-3, 72e9, 0.17, 2200.0)
    temps = np.linspace(-20.0, 40.0, 12).reshape(3, 4)
    assert DEFAULT_SHELL.frequency_hz(temps).shape == (3, 4)


def test_mode_three_is_higher():
    # Eq. (13): omega_3 / omega_2 = (3 * 8 / (2 * 3)) sqrt(I3 J2 / (I2 J3))
    f2 = natural_frequency(15e-3, 0.78e-3, 72e9, 0.17, 2200.0, n=2)
    f3 = natural_frequency(15e-3, 0.78e-3, 72e9, 0.17, 2200.0, n=3)
    ratio = 4.0 * math.sqrt(float(_mp_i(3) * _mp_j(2) / (_mp_i(2) * _mp_j(3))))
    assert f3 / f2 == pytest.approx(ratio, rel=1e-12)


# --------------------------------------------------------------------------- temperature


def test_fused_quartz_tcf_in_expected_band():
    # DESIGN.md: ~ +80 ppm/°C; slope of Eq. (18) of [1] at 0 °C: 0.3716 / 4424.901 = 84 ppm/°C
    tcf = frequency_temperature_coefficient(FUSED_QUARTZ)
    assert 75.0 <= tcf <= 90.0


def test_tcf_closed_form_at_reference():
    # Simplified by hand: (1/f) df/dT = (alpha + tcE - mu tcmu / (1 + mu)) / 2
    m = FUSED_QUARTZ
    expected = 0.5 * (
        m.expansion_per_c + m.youngs_tc_per_c - m.poisson * m.poisson_tc_per_c / (1 + m.poisson)
    )
    assert frequency_temperature_coefficient(m) == pytest.approx(expected * 1e6, rel=1e-14)
    # Only E's coefficient and expansion: (170 + 0.55) / 2 ppm/°C.
    only_e = frequency_temperature_coefficient(youngs_tc_per_c=1.7e-4, poisson_tc_per_c=0.0)
    assert only_e == pytest.approx(85.275, rel=1e-13)


@pytest.mark.parametrize("temperature_c", [-20.0, 0.0, 20.0, 40.0])
@pytest.mark.parametrize(
    "shell",
    [DEFAULT_SHELL, Shell(5e-3, 0.2e-3, FUSED_QUARTZ, n=3)],
    ids=["default", "small-n3"],
)
def test_tcf_equals_finite_difference(shell, temperature_c):
    step = 0.5
    f = shell.frequency_hz
    numeric = (f(temperature_c + step) - f(temperature_c - step)) / (2 * step) / f(temperature_c)
    analytic = frequency_temperature_coefficient(shell.material, temperature_c)
    assert analytic == pytest.approx(numeric * 1e6, rel=1e-6)


def test_tcf_vectorised():
    temps = np.array([-20.0, 20.0, 40.0])
    out = frequency_temperature_coefficient(FUSED_QUARTZ, temps)
    assert out.shape == (3,)
    assert out[1] == frequency_temperature_coefficient(FUSED_QUARTZ)


def test_shell_temperature_laws():
    # Eq. (15) with the linear laws written out at T = T0 + 30 °C.
    m, dt = FUSED_QUARTZ, 30.0
    s = 1 + m.expansion_per_c * dt
    expected = natural_frequency(
        DEFAULT_RADIUS_M * s,
        DEFAULT_THICKNESS_M * s,
        m.youngs_modulus_pa * (1 + m.youngs_tc_per_c * dt),
        m.poisson * (1 + m.poisson_tc_per_c * dt),
        m.density_kg_m3 / s**3,
    )
    assert DEFAULT_SHELL.frequency_hz(m.reference_temperature_c + dt) == pytest.approx(
        expected, rel=1e-14
    )


def test_round_trip_dicts():
    data = json.loads(json.dumps(DEFAULT_SHELL.to_dict()))
    assert Shell.from_dict(data) == DEFAULT_SHELL
    assert Material.from_dict(FUSED_QUARTZ.to_dict()) == FUSED_QUARTZ


# --------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    ("n", "match"),
    [(1, "n must be >= 2"), (0, "rigid-body"), (2.5, "integer"), (True, "integer")],
)
def test_bad_mode_number(n, match):
    with pytest.raises(InputError, match=match):
        shape_integral_i(n)
    with pytest.raises(InputError, match=match):
        shape_integral_j(n)
    with pytest.raises(InputError, match=match):
        natural_frequency(15e-3, 0.78e-3, 72e9, 0.17, 2200.0, n=n)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"radius_m": -1.0}, r"radius_m must be finite and > 0 .*-1\.0"),
        ({"thickness_m": float("nan")}, "thickness_m must be finite"),
        ({"youngs_modulus_pa": [72e9, 0.0]}, r"youngs_modulus_pa .* got 0\.0"),
        ({"poisson": 0.5}, r"0 <= poisson < 0\.5.*got 0\.5"),
        ({"poisson": -0.1}, "poisson"),
        ({"density_kg_m3": "heavy"}, "density_kg_m3 must be a number"),
    ],
)
def test_bad_frequency_inputs(kwargs, match):
    args = {
        "radius_m": 15e-3,
        "thickness_m": 0.78e-3,
        "youngs_modulus_pa": 72e9,
        "poisson": 0.17,
        "density_kg_m3": 2200.0,
    }
    with pytest.raises(InputError, match=match):
        natural_frequency(**{**args, **kwargs})


def test_bad_material_and_shell():
    with pytest.raises(InputError, match="poisson"):
        Material(72e9, 0.6, 2200.0)
    with pytest.raises(InputError, match="youngs_tc_per_c must be a finite number"):
        Material(72e9, 0.17, 2200.0, youngs_tc_per_c=float("inf"))
    with pytest.raises(InputError, match="thickness_m"):
        Shell(15e-3, 0.0)
    with pytest.raises(InputError, match=r"material must be a hrgtc\.simulate\.shell\.Material"):
        Shell(15e-3, 0.78e-3, material={"youngs_modulus_pa": 72e9})
    with pytest.raises(InputError, match="unknown field `colour`"):
        Material.from_dict({**FUSED_QUARTZ.to_dict(), "colour": "clear"})


def test_bad_temperatures():
    with pytest.raises(InputError, match="NaN or inf"):
        DEFAULT_SHELL.frequency_hz([20.0, float("nan")])
    with pytest.raises(InputError, match=r"-273\.15"):
        DEFAULT_SHELL.frequency_hz(-300.0)
    with pytest.raises(InputError, match="linear temperature laws"):
        DEFAULT_SHELL.frequency_hz(1e5)
    with pytest.raises(InputError, match="unknown material override"):
        frequency_temperature_coefficient(youngs_tc=1e-4)


def test_module_doctests():
    result = doctest.testmod(shell_module, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0
    assert result.failed == 0
