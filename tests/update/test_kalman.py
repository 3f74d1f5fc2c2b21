"""The update's Kalman filter against a second method, and its bounded process noise."""

from __future__ import annotations

import numpy as np

from hrgtc.simulate import simulate_run
from hrgtc.simulate.standard_profiles import constant
from hrgtc.update.kalman import heldout_rms, jump_statistic, run_filter, split_heldout

from field_ageing import aged_unit


def batch_wls(mean, covariance, rows, z, r):
    """The posterior of a linear Gaussian model by one weighted least-squares solve of the
    stacked, whitened system [L⁻¹; R^-½ H] x = [L⁻¹ m; R^-½ z] (L the prior's Cholesky
    factor): an independent second method (no recursion, no gain). ``r``: the measurements'
    variances, or their whole covariance matrix (generalised least squares)."""
    whiten = np.linalg.inv(np.linalg.cholesky(covariance))
    noise = np.diag(r) if np.ndim(r) == 1 else np.asarray(r)
    weights = np.linalg.inv(np.linalg.cholesky(noise))
    a = np.vstack([whiten, weights @ rows])
    b = np.concatenate([whiten @ mean, weights @ z])
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    return x, np.linalg.inv(a.T @ a)


def walk_covariance(problem):
    """Covariance of the blocks' random walks, q·(min(t_i, t_j) - start) within a run, 0
    across runs: the walk of :class:`hrgtc.update.kalman.Walk` written as one matrix."""
    walk = problem.walk
    start = walk.start_h[walk.state]
    t = problem.times_h - start
    same = walk.state[:, None] == walk.state[None, :]
    return walk.q_per_h * np.where(same, np.minimum(t[:, None], t[None, :]), 0.0)


def without_walk_states(problem):
    """The states of the problem less the walks' (which the batch method integrates out)."""
    keep = np.setdiff1d(np.arange(problem.mean.size), np.unique(problem.walk.state))
    return keep, problem.mean[keep], problem.covariance[np.ix_(keep, keep)], \
        problem.rows[:, keep]


def test_one_update_without_process_noise_is_the_batch_least_squares(parent, field_recording,
                                                                     known):
    """Issue 29: the Kalman update and a batch weighted least squares with the same prior
    agree to 1e-9 (a single update, no process noise), on the aged unit's real problem."""
    from dataclasses import replace

    result = parent.update(field_recording, replace(known, ageing_tau_h=0.0))
    axis = result.axes[""]
    p = axis.problem
    assert p.tau_h == 0.0 and p.rows.shape[0] == axis.n_blocks > 20
    # the day's bias wanders: the likelihood chose a walk (the simulated unit's rate random
    # walk is 0.1 °/h/√h, q = 0.01 (°/h)²/h), and the batch method takes it as the
    # covariance of the measurements
    assert 1e-3 <= p.walk.q_per_h <= 0.1
    figures = {f.name: f.value for _, fs in result.summary().sections for f in fs}
    assert figures["walk_dph_per_sqrt_h"] == np.sqrt(p.walk.q_per_h)
    keep, mean, prior, rows = without_walk_states(p)
    x, covariance = batch_wls(mean, prior, rows, p.z, np.diag(p.r) + walk_covariance(p))
    np.testing.assert_allclose(np.subtract(axis.after, axis.before), x[:p.n_model],
                               rtol=0.0, atol=1e-9)
    np.testing.assert_allclose(axis.covariance_after, covariance[:p.n_model, :p.n_model],
                               rtol=1e-9, atol=1e-15)
    # and the filter alone on the same inputs, nuisance constants included; without the
    # walk, it is the weighted least squares of independent blocks
    run = run_filter(p.mean, p.covariance, p.rows, p.z, p.r, p.times_h, p.n_model, 0.0, p.walk)
    np.testing.assert_allclose(run.mean[keep], x, rtol=0.0, atol=1e-9)
    x, _ = batch_wls(p.mean[keep], p.covariance[np.ix_(keep, keep)], rows, p.z, p.r)
    run = run_filter(p.mean, p.covariance, p.rows, p.z, p.r, p.times_h, p.n_model, 0.0)
    np.testing.assert_allclose(run.mean[keep], x, rtol=0.0, atol=1e-9)


def test_72_hours_at_constant_temperature_keep_the_covariance_bounded(parent, known):
    """72 h still at 20 °C (the offset observed every 10 min, the slope never): the
    covariance of the corrections never exceeds the prior's, whatever the process noise."""
    run = simulate_run(constant(20.0, 72.0), aged_unit(), sample_rate_hz=0.5, seed=5)
    result = parent.update(run, known)
    axis = result.axes[""]
    assert axis.terms == ("const",) and axis.n_blocks > 400
    prior = np.trace(axis.covariance_before)
    assert np.all(axis.traces <= prior) and axis.traces[-1] > 0.0


def test_the_process_noise_is_bounded_and_leaves_unexcited_directions_alone():
    """At f = 0 the slope is unexcited: over 72 h of blocks with a fast process noise (τ =
    5 h) its estimate stays at 0 and its variance at the prior's, the offset's variance stays
    under the prior's, and P ≤ prior (Loewner order) after every block."""
    prior = np.diag([1.0, 0.04, 0.09])  # offset, slope, one run's nuisance
    n = 432  # 72 h of 10 min blocks
    rows = np.column_stack([np.ones(n), np.zeros(n), np.ones(n)])
    z = np.random.default_rng(3).normal(0.5, 0.2, n)
    times_h = np.arange(n) / 6.0
    ceiling = prior[:2, :2]
    for count in (1, 10, 100, n):
        run = run_filter(np.zeros(3), prior, rows[:count], z[:count], np.full(count, 0.04),
                         times_h[:count], 2, 5.0)
        assert run.mean[1] == 0.0 and run.covariance[1, 1] == 0.04
        assert np.linalg.eigvalsh(ceiling - run.covariance[:2, :2]).min() >= -1e-15
        assert np.all(run.traces <= np.trace(ceiling))
    # the offset is observed (with its nuisance): its variance stays well inside the prior's,
    # with the process noise as without it
    still = run_filter(np.zeros(3), prior, rows, z, np.full(n, 0.04), times_h, 2, 0.0)
    assert 0.0 < still.covariance[0, 0] < 0.1 * prior[0, 0]
    assert 0.0 < run.covariance[0, 0] < 0.1 * prior[0, 0]


def test_a_planted_step_is_found_where_it_is():
    rng = np.random.default_rng(0)
    residual = rng.normal(0.0, 0.2, 30)
    runs = np.zeros(30, dtype=int)
    quiet, _ = jump_statistic(residual, runs, 0.2)
    stepped, where = jump_statistic(residual + np.where(np.arange(30) >= 17, 3.0, 0.0), runs, 0.2)
    assert quiet < 5.0 < 15.0 < stepped and where == 17
    # a step between two stretches (two runs, or two still periods) is not looked for
    runs[17:] = 1
    between, _ = jump_statistic(residual + np.where(np.arange(30) >= 17, 3.0, 0.0), runs, 0.2)
    assert between == quiet_of_parts(residual, runs)


def quiet_of_parts(residual, runs):
    return max(jump_statistic(residual[runs == k], runs[runs == k], 0.2)[0] for k in (0, 1))


def test_the_held_out_blocks_interleave_and_centring_removes_each_runs_mean():
    fit, held = split_heldout(10, 3)
    assert held.tolist() == [2, 5, 8] and fit.tolist() == [0, 1, 3, 4, 6, 7, 9]
    values = np.array([1.0, 3.0, 10.0, 14.0])
    runs = np.array([0, 0, 1, 1])
    assert heldout_rms(values, runs, centred=True) == np.sqrt((1 + 1 + 4 + 4) / 4)
    assert heldout_rms(values, runs, centred=False) == np.sqrt(np.mean(values ** 2))
