"""Tests of hrgtc.drift.slow_noise: the training residual's white and random-walk parts,
and the held-out ratio they give on their own (the guarded selection's slow-noise test)."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.drift.cross_validation import held_out_rms, prune_slow_noise
from hrgtc.drift.slow_noise import _held_out_rms, _operators, null_ratios, slow_noise


def _walk(seed: int, n: int, white: float, walk_per_s: float, step_s: float = 60.0):
    rng = np.random.default_rng(seed)
    time_s = np.arange(n) * step_s
    noise = np.cumsum(np.sqrt(walk_per_s * step_s) * rng.standard_normal(n))
    return time_s, noise + white * rng.standard_normal(n)


@pytest.mark.parametrize(("white", "walk_per_s"), [(8.5, 0.1), (8.5, 0.0), (2.0, 1.0)])
def test_reml_recovers_the_simulated_white_and_walk_about_a_curve_it_fits(white, walk_per_s):
    # white window means plus a random walk, about a quadratic trend the design holds:
    # the trend must not show as walk, nor the walk be hidden by the trend's terms
    estimates = []
    for seed in range(12):
        time_s, noise = _walk(seed, 240, white, walk_per_s)
        u = time_s / time_s[-1]
        design = np.column_stack([np.ones(u.size), u, u**2])
        y = 100.0 + 300.0 * u - 250.0 * u**2 + noise
        found = slow_noise(design, y, time_s)
        estimates.append((found.white_dph, found.walk_dph2_per_s))
    white_found, walk_found = np.median(estimates, axis=0)
    assert white_found == pytest.approx(white, rel=0.15)  # under a walk 4x its size, too
    assert walk_found == pytest.approx(walk_per_s, rel=0.3, abs=0.02 * white**2 / 3600.0)


def test_the_null_held_out_rms_is_the_cross_validation_figure():
    # the simulated ratios use linear maps of the noise: on one noise record they are
    # held_out_rms of the refits, computed another way
    time_s, noise = _walk(3, 120, 5.0, 0.2)
    f = np.linspace(25.0, 12.0, 120)
    x = np.column_stack([f, f**2, np.sin(time_s / 2000.0)])
    folds = np.full(120, -1)
    folds[:24], folds[-24:] = 1, 0
    names = ("f", "f^2", "df")
    for columns in ([0], [0, 1], [0, 1, 2]):
        terms = [names[c] for c in columns]
        direct = held_out_rms(x, noise, folds, names, terms)
        mapped = _held_out_rms(_operators(x, folds, columns), noise[:, None])[0]
        assert mapped == pytest.approx(direct, rel=1e-10)


def test_the_same_model_twice_gives_a_ratio_of_one_and_a_draw_is_reproducible():
    time_s, _ = _walk(4, 80, 5.0, 0.2)
    x = np.linspace(0.0, 1.0, 80)[:, None]
    folds = np.full(80, -1)
    folds[:16], folds[-16:] = 1, 0
    noise = slow_noise(np.ones((80, 1)), _walk(4, 80, 5.0, 0.2)[1], time_s)
    same = null_ratios(x, folds, time_s, [0], [0], noise, draws=50)
    np.testing.assert_allclose(same, 1.0, rtol=1e-12)
    np.testing.assert_array_equal(null_ratios(x, folds, time_s, [], [0], noise, draws=50),
                                  null_ratios(x, folds, time_s, [], [0], noise, draws=50))


def test_a_square_that_followed_the_walk_goes_and_a_real_one_stays():
    # one monotonic ramp: the truth is a line plus a random walk (seed picked where the
    # extreme blocks prefer f, f²), or a line plus a real square of the same size
    n = 144
    time_s = np.arange(n) * 60.0
    f = 25.0 - 10.0 * (1.0 - np.cos(0.6 * np.pi * time_s / time_s[-1]))
    x = np.column_stack([f, f**2])
    folds = np.full(n, -1)
    folds[: n // 5], folds[-(n // 5):] = 1, 0
    names, parents = ("f", "f^2"), {"f^2": ["f"]}
    walked = []
    for seed in range(40):
        _, noise = _walk(seed, n, 8.5, 0.3)
        y = 36.0 * f + noise
        if held_out_rms(x, y, folds, names, names) < 0.8 * held_out_rms(x, y, folds, names,
                                                                          ["f"]):
            walked.append(prune_slow_noise(x, y, folds, time_s, names, names, parents,
                                           keep=["f"])[0])
    # those are the walks that most look like curvature (the level is 5 % over all walks):
    # still, most of their squares go
    assert len(walked) >= 5
    assert sum(kept == ("f",) for kept in walked) > 0.5 * len(walked)
    curved = 36.0 * f + 0.5 * (f - 15.0) ** 2 + _walk(1, n, 8.5, 0.009)[1]
    kept, tests = prune_slow_noise(x, curved, folds, time_s, names, names, parents, keep=["f"])
    assert kept == names and tests[-1]["kept"] and tests[-1]["chance"] < 0.05
