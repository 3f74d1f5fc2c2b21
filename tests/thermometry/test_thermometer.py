"""Tests of hrgtc.thermometry: the polynomial thermometer of Eq. (17)-(18) of [1]."""

from __future__ import annotations

import json
import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.core.errors import CalibrationError, ExtrapolationWarning, InputError
from hrgtc.thermometry import Thermometer, fit

from exact import exact_polynomial_fit

# Table 1 of [1]
TABLE1_T = [-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0]
TABLE1_F = [4416.97, 4421.05, 4424.90, 4428.56, 4432.07, 4435.56, 4439.20]


def relative_errors(ours, exact):
    return [abs(float((Fraction(float(c)) - e) / e)) for c, e in zip(ours, exact, strict=True)]


def normwise_error(ours, exact, x, y):
    """max_k |c_k - exact_k| * max|x|^k / max|y|: each term's error on the data's scale."""
    x_max = float(np.max(np.abs(x)))
    y_max = float(np.max(np.abs(y)))
    return max(
        abs(float(Fraction(float(c)) - e)) * x_max**k / y_max
        for k, (c, e) in enumerate(zip(ours, exact, strict=True))
    )


def test_table1_fit_equals_exact_least_squares():
    exact = exact_polynomial_fit(TABLE1_T, TABLE1_F, 3)
    th = fit(TABLE1_T, TABLE1_F, order=3)
    assert max(relative_errors(th.coefficients, exact)) < 1e-13


def test_badly_scaled_high_order_problem_keeps_its_digits():
    # x far from 0 and order 6: the raw Vandermonde has condition ~1e40.
    rng = np.random.default_rng(0)
    x = 1000.0 + np.linspace(0.0, 10.0, 40)
    true = np.array([1.0, -2.0, 0.5, 0.1, -0.02, 0.003, 1e-4])
    y = np.polynomial.polynomial.polyval(x - 1005.0, true) + rng.normal(0.0, 1e-3, x.size)
    exact = exact_polynomial_fit(x, y, 6)
    ours = fit(x, y, order=6)
    assert max(relative_errors(ours.coefficients, exact)) < 1e-12
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        naive = np.polyfit(x, y, 6)[::-1]
    # numpy.polyfit on raw x loses essentially every digit on the same problem.
    assert max(relative_errors(naive, exact)) > 1e-3


def test_standard_errors_equal_statsmodels_on_the_raw_design():
    sm = pytest.importorskip("statsmodels.api")
    th = fit(TABLE1_T, TABLE1_F, order=3)
    model = sm.OLS(np.array(TABLE1_F), np.vander(np.array(TABLE1_T), 4, increasing=True)).fit()
    np.testing.assert_allclose(th.standard_errors, model.bse, rtol=1e-9)
    np.testing.assert_allclose(th.residual_std_hz, np.sqrt(model.scale), rtol=1e-9)
    np.testing.assert_allclose(th.rsquared, model.rsquared, rtol=1e-12)
    np.testing.assert_allclose(th.pvalues, model.pvalues, rtol=1e-7)


@settings(max_examples=40, deadline=None)
@given(
    coefficients=st.lists(
        st.floats(-5.0, 5.0, allow_nan=False).filter(lambda v: abs(v) > 1e-3),
        min_size=2,
        max_size=5,
    ),
    offset=st.floats(-200.0, 200.0),
)
def test_exact_polynomial_data_returns_its_coefficients(coefficients, offset):
    x = offset + np.linspace(-10.0, 10.0, 25)
    y = np.polynomial.polynomial.polyval(x, coefficients)
    order = len(coefficients) - 1
    th = fit(x, y, order=order)
    exact = exact_polynomial_fit(x, y, order)
    # A backward-stable solver's forward error is bounded by eps times the condition
    # of the (column-equilibrated) raw problem; the fitted curve itself is exact.
    vandermonde = np.vander(x, order + 1, increasing=True)
    condition = np.linalg.cond(vandermonde / np.linalg.norm(vandermonde, axis=0))
    assert normwise_error(th.coefficients, exact, x, y) < 1e-14 * condition
    np.testing.assert_allclose(th.frequency(x), y, rtol=0, atol=1e-13 * np.max(np.abs(y)))


def test_inverse_is_exact_on_a_dense_grid():
    th = fit(TABLE1_T, TABLE1_F, order=3)
    temperatures = np.linspace(-20.0, 40.0, 100_001)
    recovered = th.temperature(th.frequency(temperatures))
    assert np.max(np.abs(recovered - temperatures)) < 1e-10


def test_inverse_keeps_the_shape_and_scalars():
    th = fit(TABLE1_T, TABLE1_F, order=3)
    assert np.ndim(th.temperature(4424.90)) == 0
    assert th.temperature(np.full((3, 2), 4424.90)).shape == (3, 2)


def test_out_of_range_frequencies_are_flagged_not_silent():
    th = fit(TABLE1_T, TABLE1_F, order=3)
    f = th.frequency(np.array([-30.0, 0.0, 50.0]))
    with pytest.warns(ExtrapolationWarning, match=r"2 of 3 frequencies \(66\.67%\)"):
        t = th.temperature(f)
    np.testing.assert_allclose(t, [-30.0, 0.0, 50.0], atol=1e-9)
    np.testing.assert_array_equal(th.in_range(f), [False, True, False])
    with pytest.warns(ExtrapolationWarning):
        far = th.temperature(np.array([3000.0]))
    assert np.isnan(far[0])


def test_non_monotonic_fit_raises_a_clear_error():
    t = np.linspace(-20.0, 40.0, 7)
    f = 4425.0 + 0.01 * (t - 10.0) ** 2  # a parabola turning at 10 °C
    th = fit(t, f, order=2)
    assert not th.is_monotonic
    with pytest.raises(CalibrationError, match=r"not monotonic.*df/dT = 0 at 10\.000"):
        th.temperature(4425.5)


def test_too_few_points_for_the_order():
    with pytest.raises(InputError, match=r"2 distinct temperature.*order-3.*at least 4"):
        fit([0.0, 10.0], [4424.9, 4428.6], order=3)


def test_mismatched_and_non_finite_input():
    with pytest.raises(InputError, match="temperatures_c has 3 values but frequencies_hz has 2"):
        fit([0.0, 1.0, 2.0], [1.0, 2.0])
    with pytest.raises(InputError, match=r"frequencies_hz\[1\] is nan"):
        fit([0.0, 1.0, 2.0, 3.0], [1.0, np.nan, 2.0, 3.0], order=1)


def test_exact_fit_has_no_error_estimates_but_still_inverts():
    th = fit([0.0, 10.0, 20.0, 30.0], [1.0, 2.0, 3.5, 5.5], order=3)
    assert all(np.isnan(th.standard_errors))
    assert th.temperature(3.5) == pytest.approx(20.0, abs=1e-12)


def test_dict_round_trip_through_json_is_exact():
    th = fit(TABLE1_T, TABLE1_F, order=3)
    again = Thermometer.from_dict(json.loads(json.dumps(th.to_dict())))
    assert again == th
    f = np.linspace(4417.0, 4439.0, 11)
    np.testing.assert_array_equal(again.temperature(f), th.temperature(f))
    with pytest.raises(InputError, match="not a valid thermometer record"):
        Thermometer.from_dict({"order": 3})


def test_summary_names_the_coefficients():
    text = fit(TABLE1_T, TABLE1_F, order=3).summary().text()
    assert "T^3" in text and "R²" in text
