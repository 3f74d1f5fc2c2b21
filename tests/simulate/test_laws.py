"""The simulator's laws (hrgtc.simulate.laws): the scale-factor law against numpy's
polynomials, and every law's JSON round trip."""

from __future__ import annotations

import json

import numpy as np
import pytest
from numpy.polynomial import Polynomial

from hrgtc.core.errors import InputError
from hrgtc.simulate.laws import (
    BiasLaw,
    PolynomialFrequencyLaw,
    ScaleFactorLaw,
    ShellFrequencyLaw,
    frequency_law_from_dict,
    table1_frequency_law,
)
from hrgtc.simulate.shell import FUSED_QUARTZ, Shell


def test_scale_factor_law_is_the_polynomial_in_temperature_offset():
    law = ScaleFactorLaw((-80.0, -4.5, 0.035, 2.0e-4), reference_c=25.0)
    temperature = np.linspace(-20.0, 60.0, 81)
    # Independent method: numpy's Polynomial in (T - T0).
    expected = Polynomial([-80.0, -4.5, 0.035, 2.0e-4])(temperature - 25.0)
    np.testing.assert_allclose(law.ppm(temperature), expected, rtol=0, atol=1e-12)
    assert law.ppm(np.array([25.0])).tolist() == [-80.0]  # k0 at T0


def test_scale_factor_law_rejects_non_finite_coefficients():
    with pytest.raises(InputError, match="coefficients_ppm must be finite numbers"):
        ScaleFactorLaw((1.0, float("nan")))
    with pytest.raises(InputError, match="coefficients_ppm must be finite numbers"):
        ScaleFactorLaw(())
    with pytest.raises(InputError, match=r"reference_c must be finite \[°C\]"):
        ScaleFactorLaw((1.0,), reference_c=float("inf"))


@pytest.mark.parametrize(
    "law",
    [
        table1_frequency_law(),
        ShellFrequencyLaw(Shell(13.0e-3, 0.75e-3, FUSED_QUARTZ)),
    ],
)
def test_frequency_laws_round_trip_through_json(law):
    again = frequency_law_from_dict(json.loads(json.dumps(law.to_dict())))
    assert again == law
    temperature = np.array([-20.0, 20.0, 60.0])
    assert np.array_equal(again.frequency_hz(temperature), law.frequency_hz(temperature))


def test_bias_and_scale_factor_laws_round_trip_through_json():
    bias = BiasLaw(2.5, 25.0, (-0.09, 1.5e-3, 1.0e-5), -0.18, 2.0e-3, 0.2, 0.5)
    assert BiasLaw.from_dict(json.loads(json.dumps(bias.to_dict()))) == bias
    scale = ScaleFactorLaw((150.0, 6.0, 0.02), reference_c=20.0)
    assert ScaleFactorLaw.from_dict(json.loads(json.dumps(scale.to_dict()))) == scale


def test_unknown_frequency_law_kind():
    with pytest.raises(InputError, match="frequency law kind 'spline' is unknown"):
        frequency_law_from_dict({"kind": "spline"})
    assert isinstance(
        frequency_law_from_dict({"kind": "polynomial", "coefficients": [1.0, 2.0]}),
        PolynomialFrequencyLaw,
    )
