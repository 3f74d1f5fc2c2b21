"""The noise model Σ C_k τ^k: exact recovery, coverage on allantools' Kasdin noise, gaps."""

from __future__ import annotations

import dataclasses
import math

import allantools
import numpy as np
import pytest
from scipy import stats

from hrgtc.core.errors import InputError
from hrgtc.evaluation.allan import allan_deviation
from hrgtc.evaluation.allan_segments import pooled_deviation
from hrgtc.evaluation.noise_model import TERMS, fit_noise_model, pooled_avar, unit_noises

#: (b of allantools.Noise: the phase PSD slope) -> (term, power k of τ)
KASDIN = {-2: ("angle_random_walk", -1), -3: ("bias_instability", 0),
          -4: ("rate_random_walk", 1)}


def _exact_allan(coefficients, n=8192, fs=2.0):
    """An overlapping Allan deviation whose values are exactly √(Σ C_k τ^k) (edf and τ of
    a real one on white noise)."""
    real = allan_deviation(np.random.default_rng(0).standard_normal(n), fs, confidence=0.683)
    tau = real.taus_s
    avar = sum(c * tau ** TERMS[k][0] for k, c in coefficients.items())
    return dataclasses.replace(real, deviation=np.sqrt(avar))


def test_noise_free_allan_variance_gives_its_coefficients_back():
    truth = {"quantization": 0.5, "angle_random_walk": 4.0, "bias_instability": 0.04,
             "rate_random_walk": 2e-4, "rate_ramp": 1e-6}
    model = fit_noise_model(_exact_allan(truth), terms=tuple(TERMS), bootstrap=50,
                            min_blocks=2)
    assert model.fitted == tuple(TERMS)
    for name, c in truth.items():
        assert model.coefficients[name] == pytest.approx(c, rel=1e-9), name
    assert model.chi2 < 1e-20
    assert model.terms["angle_random_walk"] == pytest.approx(math.sqrt(4.0) / 60.0, rel=1e-9)
    assert model.terms["bias_instability"] == pytest.approx(0.2 / 0.6643, rel=1e-3)
    assert model.terms["rate_random_walk"] == pytest.approx(60.0 * math.sqrt(6e-4), rel=1e-9)
    assert model.terms["rate_ramp"] == pytest.approx(3600.0 * math.sqrt(2e-6), rel=1e-9)
    assert model.terms["quantization"] == pytest.approx(math.sqrt(0.5 / 3.0), rel=1e-9)
    np.testing.assert_allclose(model.allan_variance(model.taus_s),
                               _exact_allan(truth).deviation[:model.taus_s.size] ** 2,
                               rtol=1e-12)
    # selected by AIC: a missing term is left out, not fitted as a small positive number
    sparse = fit_noise_model(_exact_allan({"angle_random_walk": 4.0, "rate_random_walk": 2e-4}),
                             bootstrap=50, min_blocks=2)
    assert sparse.fitted == ("angle_random_walk", "rate_random_walk")
    assert sparse.coefficients["rate_random_walk"] == pytest.approx(2e-4, rel=1e-9)
    assert sparse.intervals["bias_instability"] is None


def test_unit_noises_have_the_allan_variance_of_their_term():
    """Each simulated unit noise has σ² = τ^k (within its sampling error; the sampled
    flicker is 1.05 times the asymptote at 4 samples, as allantools' Kasdin FFM)."""
    fs = 4.0
    factors = np.array([8, 32, 128])
    taus = factors / fs
    units = unit_noises(300, 8192, fs, np.random.default_rng(3))
    for name, unit in units.items():
        mean = pooled_avar(unit, (8192,), factors).mean(axis=0)
        expected = taus ** TERMS[name][0]
        if name == "rate_ramp":  # deterministic but for its sign: exact up to rounding
            np.testing.assert_allclose(mean, expected, rtol=1e-9)
        else:
            np.testing.assert_allclose(mean, expected, rtol=0.12, err_msg=name)


def test_arw_agrees_with_allantools_on_white_noise():
    """White rate noise from allantools' Kasdin generator: the fitted ARW equals the one read
    from allantools' own oadev at τ = 1 s (N = σ(1 s)·√(1 s)/60) within 1 %, and the
    generator's N lies in its interval."""
    np.random.seed(11)  # noqa: NPY002 - allantools.Noise draws from the global generator
    n, qd = 1 << 16, 2.5
    noise = allantools.Noise(n + 1, qd, -2)
    noise.generateNoise()
    rate = np.diff(noise.time_series)  # τ0 = 1 s
    model = fit_noise_model(allan_deviation(rate, 1.0, confidence=0.683), bootstrap=100)
    _, adev, _, _ = allantools.oadev(rate, rate=1.0, data_type="freq", taus=[1.0])
    allantools_arw = float(adev[0]) / 60.0
    assert model.terms["angle_random_walk"] == pytest.approx(allantools_arw, rel=0.01)
    truth = math.sqrt(noise.adev(1.0, 1.0) ** 2) / 60.0
    low, high = model.intervals["angle_random_walk"]
    assert low <= truth <= high
    assert model.summary()["noise_model.angle_random_walk"].unit == "°/√h"


def test_a_ramp_is_read_in_degrees_per_hour_per_hour():
    """A rate rising 0.01 °/h each second is a ramp of 36 °/h/h, with white noise beside it
    (ARW σ/√fs/60); on a ramp alone the covariance has no scatter and the fit still runs."""
    t = np.arange(4096.0)
    alone = fit_noise_model(allan_deviation(0.01 * t, 1.0, confidence=0.683), bootstrap=50)
    assert alone.fitted == ("rate_ramp",)
    assert alone.terms["rate_ramp"] == pytest.approx(36.0, rel=1e-9)
    noisy = 0.01 * t + np.random.default_rng(0).standard_normal(t.size)
    model = fit_noise_model(allan_deviation(noisy, 1.0, confidence=0.683), bootstrap=50)
    assert model.terms["rate_ramp"] == pytest.approx(36.0, rel=0.01)
    assert model.terms["angle_random_walk"] == pytest.approx(1.0 / 60.0, rel=0.05)
    text = model.summary().text()
    assert "°/h/h" in text and "°/√h" in text


def test_gaps_are_fitted_within_segments():
    """Segments at different offsets: pooled within them the fit sees only the noise (ARW of
    the white noise recovered); a deviation across the steps would be far off."""
    rng = np.random.default_rng(5)
    sizes = (3000, 5000, 2500)
    rate = np.concatenate([1200.0 * k + 30.0 * rng.standard_normal(n)
                           for k, n in enumerate(sizes)])
    breaks = np.cumsum(sizes)[:-1]
    allan = pooled_deviation(rate, 10.0, breaks=breaks, confidence=0.683)
    with pytest.raises(InputError, match="segment_lengths"):
        fit_noise_model(allan)
    model = fit_noise_model(allan, segment_lengths=sizes, bootstrap=100,
                            terms=("angle_random_walk", "bias_instability"))
    truth = 30.0 / math.sqrt(10.0) / 60.0  # σ/√fs [°/h·√s] -> °/√h
    assert model.terms["angle_random_walk"] == pytest.approx(truth, rel=0.03)
    low, high = model.intervals["angle_random_walk"]
    assert low <= truth <= high
    assert model.segment_lengths == sizes


def test_bad_input_is_refused():
    allan = allan_deviation(np.random.default_rng(1).standard_normal(4096), 1.0,
                            confidence=0.683)
    with pytest.raises(InputError, match="edf"):
        fit_noise_model(allan_deviation(np.ones(4096) + np.arange(4096) * 1e-3, 1.0))
    with pytest.raises(InputError, match="terms"):
        fit_noise_model(allan, terms=("flicker",))
    with pytest.raises(InputError, match="confidence"):
        fit_noise_model(allan, confidence=1.0)
    with pytest.raises(InputError, match="add up"):
        fit_noise_model(allan, segment_lengths=(100, 200))


@pytest.mark.slow
def test_intervals_cover_the_kasdin_generators_allan_variance():
    """200 records of white, flicker and random-walk rate noise from allantools' Kasdin
    generator (an independent implementation), the three terms named: each 90 % interval
    holds the generator's exact term (allantools' ``Noise.adev`` of its spectrum) in a share
    of the seeds inside the 99 % binomial interval of 200 draws at 0.9 (docs/method.md,
    "Noise model")."""
    n, seeds, confidence = 2048, 200, 0.9
    coefficients = {"angle_random_walk": 1.0, "bias_instability": 0.05,
                    "rate_random_walk": 5e-4}
    qd = {-2: 1.0, -3: 0.05 * math.pi / (2.0 * math.log(2.0)), -4: 3.0 * 5e-4}
    truth = {}
    for b, (name, k) in KASDIN.items():
        avar = allantools.Noise(n + 1, qd[b], b).adev(1.0, 10.0) ** 2 / 10.0 ** k
        assert avar == pytest.approx(coefficients[name], rel=1e-12)  # the generator's scale
        truth[name] = TERMS[name][2](avar)
    hits = dict.fromkeys(truth, 0)
    for seed in range(seeds):
        np.random.seed(1000 + seed)  # noqa: NPY002 - as above
        phase = np.zeros(n + 1)
        for b, q in qd.items():
            noise = allantools.Noise(n + 1, q, b)
            noise.generateNoise()
            phase += noise.time_series
        allan = allan_deviation(np.diff(phase), 1.0, confidence=0.683)
        model = fit_noise_model(allan, terms=tuple(truth), bootstrap=100,
                                confidence=confidence, seed=seed)
        for name, value in truth.items():
            low, high = model.intervals[name]
            hits[name] += low <= value <= high
    low, high = stats.binom.interval(0.99, seeds, confidence)
    for name, count in hits.items():
        assert low <= count <= high, f"{name}: {count} of {seeds} in [{low:g}, {high:g}]"
