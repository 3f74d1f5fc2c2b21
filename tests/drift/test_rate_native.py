"""The df/dt filter's C pass (``_rate_native.c``) computes the bits of the numba step the
fused compensation kernel calls (:func:`hrgtc.drift._rate_numba.filter_run`), and its
module does not import numba.

Compared bit for bit (``.view(np.int64)``: a NaN's payload and a zero's sign too) on
uniform, jittered, stalled and backward clocks, steps on both sides of the series limit,
restarts, NaN and infinite samples, huge offsets, states carried across chunks, lengths
0 to 3 and a million.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from hrgtc.drift import _rate_kernel as native
from hrgtc.drift import _rate_numba as numba_kernel
from hrgtc.drift.rate_filter import STATE_SIZE, new_state
from hrgtc.drift.rate_weights import SERIES_LIMIT


def bits(values) -> np.ndarray:
    return np.asarray(values, dtype=np.float64).view(np.int64)


def both(x, t, tau, restart=None, state=None, keep_lag=True):
    """(rate, lag, state) of the C pass and of the numba step, from copies of ``state``."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    t = np.ascontiguousarray(t, dtype=np.float64)
    mask = np.zeros(0, np.int8) if restart is None else np.ascontiguousarray(restart, np.int8)
    out = []
    for run in (native.rate_pass, numba_kernel.filter_run):
        s = (new_state() if state is None else state).copy()
        rate = np.full(x.size, -7.0)
        lag = np.full(x.size if keep_lag else 0, -7.0)
        run(x, t, tau, mask, s, rate, lag)
        out.append((rate, lag, s))
    return out


def assert_same(x, t, tau, **kwargs):
    (rate, lag, state), (rate_n, lag_n, state_n) = both(x, t, tau, **kwargs)
    np.testing.assert_array_equal(bits(rate), bits(rate_n))
    np.testing.assert_array_equal(bits(lag), bits(lag_n))
    np.testing.assert_array_equal(bits(state), bits(state_n))
    return state


def signal(rng, n):
    return 1e-3 * np.cumsum(rng.standard_normal(n)) + np.sin(np.arange(n) / 50.0)


@pytest.mark.parametrize("n", [0, 1, 2, 3, 1001, 1_000_000])
@pytest.mark.parametrize("tau", [0.5, 30.0, 600.0])
def test_uniform_and_jittered_clocks(n, tau):
    rng = np.random.default_rng(n + int(tau))
    x = signal(rng, n)
    assert_same(x, np.arange(n) / 200.0, tau)
    assert_same(x, 1.7e9 + np.cumsum(rng.uniform(0.0, 2.0, n)), tau)  # stalls, large offset
    assert_same(x + 1e10, np.arange(n) * 7.0, tau, keep_lag=False)  # huge level, long steps


def test_steps_around_the_series_limit_backwards_and_not_finite():
    rng = np.random.default_rng(3)
    tau = 10.0
    # steps of r just below, at and above the limit, zero and negative steps, a gap
    r = np.array([SERIES_LIMIT * f for f in (0.5, 0.999999, 1.0, 1.000001, 2.0, 1e-12)]
                 + [0.0, -0.3, 50.0, 1e-300, 1e300])
    steps = np.tile(r * tau, 300)
    rng.shuffle(steps)
    t = np.cumsum(steps)
    x = signal(rng, t.size)
    x[rng.integers(0, x.size, 30)] = rng.choice([np.nan, np.inf, -np.inf, -0.0, 0.0], 30)
    assert_same(x, t, tau)
    t_bad = t.copy()
    t_bad[rng.integers(0, t.size, 10)] = np.nan
    assert_same(x, t_bad, tau)


def test_restarts_and_states_across_chunks():
    rng = np.random.default_rng(4)
    n = 30_000
    x = signal(rng, n)
    t = np.cumsum(rng.uniform(0.004, 0.006, n))
    restart = (rng.random(n) < 0.001).astype(np.int8)
    restart[:3] = [0, 1, 1]
    state = None
    for a, b in ((0, 1), (1, 2), (2, 10_000), (10_000, n)):
        state = assert_same(x[a:b], t[a:b], 2.0, restart=restart[a:b], state=state)
    assert state is not None and state.size == STATE_SIZE


def test_step_weights_are_the_numba_ones():
    rng = np.random.default_rng(5)
    dts = np.concatenate([rng.uniform(0, 2 * SERIES_LIMIT, 2000), 10.0 ** rng.uniform(-12, 6, 2000),
                          [0.0, -0.0, SERIES_LIMIT, np.inf, np.nan, 1e-320]])
    for dt in dts:
        got = native.step_weights(float(dt), 1.0)
        want = numba_kernel.step_weights(float(dt), 1.0)
        np.testing.assert_array_equal(bits(got), bits(want))


def test_first_time_problem():
    t = np.arange(10.0)
    assert native.first_time_problem(t, 0.0, 0.0) == (0, -1)
    assert native.first_time_problem(np.empty(0), 5.0, 1.0) == (0, -1)
    assert native.first_time_problem(t, 0.5, 1.0) == (3, 0)  # before the previous chunk
    assert native.first_time_problem(t, 0.5, 0.0) == (0, -1)  # no previous chunk
    back = t.copy()
    back[6] = 4.5
    assert native.first_time_problem(back, 0.0, 0.0) == (2, 6)
    for bad in (np.nan, np.inf, -np.inf):
        odd = back.copy()
        odd[4] = bad
        assert native.first_time_problem(odd, 0.0, 0.0) == (1, 4)  # the first problem
    assert native.first_time_problem(np.array([np.nan]), 0.0, 1.0) == (1, 0)


def test_the_module_does_not_import_numba():
    code = ("import sys; import hrgtc.drift._rate_kernel; import hrgtc.drift.rate_filter; "
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_wrong_arrays_are_refused_not_read():
    x = np.arange(5.0)
    rate = np.empty(5)
    with pytest.raises(ValueError, match="one length"):
        native.rate_pass(x, np.arange(4.0), 1.0, np.zeros(0, np.int8), new_state(), rate, rate)
    with pytest.raises(ValueError, match="state"):
        native.rate_pass(x, x, 1.0, np.zeros(0, np.int8), np.zeros(3), rate, rate)
    with pytest.raises(TypeError, match="restart"):
        native.rate_pass(x, x, 1.0, np.zeros(5, np.int64), new_state(), rate, rate)
    with pytest.raises(TypeError, match="out_rate"):
        native.rate_pass(x, x, 1.0, np.zeros(0, np.int8), new_state(), rate[::-1], rate)
    with pytest.raises(TypeError, match="time_s"):
        native.first_time_problem(np.arange(5), 0.0, 0.0)
