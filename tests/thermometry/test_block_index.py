"""The soak plateaus' block of each sample (``_plateau_kernel.block_index``) is numpy's
``floor_divide(t - t[0], block_s).astype(intp)`` bit for bit: on sample clocks of every
rate, clock times far from zero, times on and one ulp beside the block edges, and for
block lengths that are not binary fractions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.thermometry._plateau_kernel import _floor_divide, block_index


def _numpy(time_s, block_s):
    return np.floor_divide(time_s - time_s[0], block_s).astype(np.intp)


def _edges(block_s, origin, blocks=500):
    """Times on each block edge and one and two ulps either side, increasing."""
    edges = origin + block_s * np.arange(1, blocks)
    near = [np.nextafter(np.nextafter(edges, -np.inf), -np.inf), np.nextafter(edges, -np.inf),
            edges, np.nextafter(edges, np.inf), np.nextafter(np.nextafter(edges, np.inf), np.inf)]
    return np.unique(np.concatenate([[origin], *near]))


@pytest.mark.parametrize("block_s", [10.0, 1.0, 0.1, 1.0 / 3.0, 60.0, 7.3])
@pytest.mark.parametrize("origin", [0.0, 0.0025, 1.7e9 + 0.123, -35.5])
def test_block_index_equals_numpy_on_and_beside_the_edges(block_s, origin):
    times = _edges(block_s, origin)
    np.testing.assert_array_equal(block_index(times, block_s), _numpy(times, block_s),
                                  strict=True)


@pytest.mark.parametrize("rate_hz", [200.0, 1.0, 3.0, 0.37])
def test_block_index_equals_numpy_on_sample_clocks(rate_hz):
    rng = np.random.default_rng(int(rate_hz * 100))
    n = 200_000
    clock = np.arange(n) / rate_hz
    jittered = np.cumsum(rng.uniform(0.5, 1.5, n)) / rate_hz + 1.6e9
    for times in (clock, clock + 123.456, jittered):
        for block_s in (10.0, 0.1, 1.0 / 7.0):
            np.testing.assert_array_equal(block_index(times, block_s), _numpy(times, block_s),
                                          strict=True)


@settings(max_examples=300, deadline=None)
@given(st.floats(0.0, 1e10, allow_nan=False), st.floats(1e-6, 1e6, allow_nan=False))
def test_the_exact_path_is_numpys_floor_division(a, b):
    assert _floor_divide(a, b) == np.floor_divide(a, b)
    assert _floor_divide(-a, b) == np.floor_divide(-a, b)


def test_no_times():
    assert block_index(np.empty(0), 10.0).shape == (0,)


@pytest.mark.parametrize("b", [0.1, 0.3, 1.0 / 3.0, 7.3, 0.01, 1e-3])
def test_the_exact_path_on_multiples_and_integers(b):
    """Quotients that round onto or just beside an integer: the cases where the exact
    path's rounding of ``(a − fmod(a, b)) / b`` to its integer matters."""
    a = np.concatenate([np.arange(0.0, 5000.0), b * np.arange(5000),
                        np.nextafter(b * np.arange(1, 5000), np.inf)])
    ours = np.array([_floor_divide(x, b) for x in a])
    assert ours.tobytes() == np.floor_divide(a, b).tobytes()
