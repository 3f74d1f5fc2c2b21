"""hrgtc.core.student_t: Student's t tail, against scipy.stats.t.sf bit for bit."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy import stats

from hrgtc.core.student_t import t_sf

X = np.array([0.0, 1e-300, 0.5, 1.96, 3.0, 12.0, 40.0, -2.0, np.inf, -np.inf, np.nan])


@pytest.mark.parametrize("df", [1, 3, 7.5, 120, 1e6, np.inf, 0, -1, np.nan])
def test_array_equals_scipy_stats(df):
    expected = stats.t.sf(X, df)
    got = t_sf(X, df)
    assert got.dtype == expected.dtype and got.shape == expected.shape
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("x", [0.0, 0.7, 2.5, 80.0, np.inf, -np.inf, np.nan])
@pytest.mark.parametrize("df", [2, 30.0, 0])
def test_scalar_equals_scipy_stats(x, df):
    expected = stats.t.sf(x, df)
    got = t_sf(x, df)
    assert np.ndim(got) == 0
    assert np.array_equal(got, expected, equal_nan=True)


def test_broadcast_df_equals_scipy_stats():
    rng = np.random.default_rng(1)
    x = np.abs(rng.standard_normal((4, 6))) * 3
    df = np.array([1, 4, 9, 50, 0, 2.5])
    np.testing.assert_array_equal(t_sf(x, df), stats.t.sf(x, df))


def test_imports_no_scipy_stats():
    code = ("import sys; from hrgtc.core.student_t import t_sf; t_sf(1.0, 3); "
            "print('scipy.stats' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip() == "False"
