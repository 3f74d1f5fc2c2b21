"""Tests of hrgtc.evaluation.metrics and .allan: bias stability, Allan deviation, noise terms.

Independent truth: the NBS 1000-point data set with its published deviations
(NIST SP 1065 [SP1065], Table 31), allantools (a second implementation), the
closed-form Allan deviation of white and random-walk noise, the IEEE Std 952
Annex C noise model, and a plain-Python block average.

[SP1065] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
         Publication 1065, 2008, Section 12.3 (test suites), Table 31. The same
         values are used by allantools' tests/nbs14/test_nbs14_1000point.py.
"""

from __future__ import annotations

import json
import math
import statistics

import allantools
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.core.errors import InputError
from hrgtc.evaluation.metrics import (
    AllanResult,
    NoiseTerms,
    ResidualResult,
    allan_deviation,
    bias_stability,
    bias_stability_table,
    noise_terms,
    residual_against_truth,
)


# ----------------------------------------------------------------------------- NBS data set
def nbs_1000_point() -> np.ndarray:
    """The NBS 1000-point frequency data set of [SP1065] (Section 12.3).

    Lehmer generator n_{i+1} = 16807·n_i mod (2^31 − 1), n_0 = 1234567890,
    x_i = n_i / (2^31 − 1).
    """
    n = [1234567890]
    for _ in range(999):
        n.append((16807 * n[-1]) % 2147483647)
    # The first three generated numbers, as published (quoted in allantools' test).
    assert n[1:4] == [395529916, 1209410747, 633705974]
    return np.array(n, dtype=np.float64) / 2147483647.0


# [SP1065] Table 31, 1000-point data set, tau = 1, 10, 100 (data interval 1 s).
NBS_ADEV = (2.922319e-01, 9.965736e-02, 3.897804e-02)  # normal Allan deviation
NBS_OADEV = (2.922319e-01, 9.159953e-02, 3.241343e-02)  # overlapping Allan deviation


def test_nbs_1000_point_normal_allan_deviation():
    result = allan_deviation(nbs_1000_point(), 1.0, taus=[1, 10, 100], overlapping=False)
    np.testing.assert_array_equal(result.taus_s, [1.0, 10.0, 100.0])
    np.testing.assert_allclose(result.deviation, NBS_ADEV, rtol=1e-6)  # 7 published digits
    # floor(N/m) - 1 second differences, SP 1065 Eq. (6)-(7)
    np.testing.assert_array_equal(result.counts, [999, 99, 9])


def test_nbs_1000_point_overlapping_allan_deviation():
    result = allan_deviation(nbs_1000_point(), 1.0, taus=[1, 10, 100], overlapping=True)
    np.testing.assert_allclose(result.deviation, NBS_OADEV, rtol=1e-6)
    # N + 1 - 2m second differences of the phase, SP 1065 Eq. (11)
    np.testing.assert_array_equal(result.counts, [999, 981, 801])


# ----------------------------------------------------------------------------- vs allantools
@pytest.fixture(scope="module")
def gyro_like() -> np.ndarray:
    """Rate in °/h: a large offset (Earth rate + bias), white noise and a slow walk."""
    rng = np.random.default_rng(11)
    n = 6001
    return 12.5 + rng.normal(0.0, 0.8, n) + np.cumsum(rng.normal(0.0, 0.01, n))


@pytest.mark.parametrize(
    "taus",
    [
        "octave",
        "decade",
        [0.005, 0.0123, 0.05, 0.5, 0.501, 3.333, 7.0, 1e6],  # rounding, duplicates, too long
        np.array([0.01, 2.0, 14.99]),
    ],
)
@pytest.mark.parametrize("overlapping", [True, False])
def test_equals_allantools(gyro_like, taus, overlapping):
    fs = 200.0
    reference = allantools.oadev if overlapping else allantools.adev
    ref_taus, ref_dev, _, ref_n = reference(gyro_like, rate=fs, data_type="freq", taus=taus)
    result = allan_deviation(gyro_like, fs, taus=taus, overlapping=overlapping)
    np.testing.assert_array_equal(result.taus_s, ref_taus)
    np.testing.assert_array_equal(result.counts, ref_n)
    np.testing.assert_allclose(result.deviation, ref_dev, rtol=1e-10, atol=0.0)
    assert result.overlapping is overlapping


def test_equals_allantools_all_taus_short_record():
    data = np.random.default_rng(3).normal(size=97)
    ref_taus, ref_dev, _, ref_n = allantools.oadev(data, rate=1.0, data_type="freq", taus="all")
    result = allan_deviation(data, 1.0, taus="all")
    np.testing.assert_array_equal(result.taus_s, ref_taus)
    np.testing.assert_array_equal(result.counts, ref_n)
    np.testing.assert_allclose(result.deviation, ref_dev, rtol=1e-10)


@settings(max_examples=40, deadline=None)
@given(
    data=st.lists(
        st.floats(min_value=-1e3, max_value=1e3, allow_nan=False), min_size=8, max_size=300
    ),
    offset=st.floats(min_value=-1e4, max_value=1e4, allow_nan=False),
    overlapping=st.booleans(),
)
def test_constant_offset_leaves_allan_deviation_unchanged(data, offset, overlapping):
    rate = np.array(data)
    base = allan_deviation(rate, 10.0, overlapping=overlapping)
    shifted = allan_deviation(rate + offset, 10.0, overlapping=overlapping)
    np.testing.assert_array_equal(shifted.taus_s, base.taus_s)
    # only the rounding of rate + offset may differ
    atol = 1e-12 * (abs(offset) + np.max(np.abs(rate)) + 1.0)
    np.testing.assert_allclose(shifted.deviation, base.deviation, rtol=1e-9, atol=atol)


# ----------------------------------------------------------------------------- noise laws
def test_white_noise_follows_minus_half_slope_and_gives_arw():
    fs, sigma, n = 100.0, 3.0, 400_000
    rate = np.random.default_rng(5).normal(0.0, sigma, n)
    result = allan_deviation(rate, fs)
    m = result.taus_s * fs
    expected = sigma / np.sqrt(result.taus_s * fs)  # white noise: σ(τ) = σ/√(τ·fs)
    edf = np.array([allantools.edf_simple(n + 1, mi, 0) for mi in m])  # white FM, SP 1065
    good = result.blocks >= 16
    assert good.sum() >= 10
    rel_sd = 1.0 / np.sqrt(2.0 * edf[good])
    assert np.all(np.abs(result.deviation[good] / expected[good] - 1.0) < 4.0 * rel_sd)

    terms = noise_terms(result)
    arw_true = sigma / math.sqrt(fs) / 60.0  # N = σ/√fs [°/h·√s]; ARW = N/60 [°/√h]
    assert terms.arw_deg_per_rt_h == pytest.approx(arw_true, rel=0.10)
    assert terms.rrw_dph_per_rt_h is None


def test_rate_random_walk_gives_plus_half_slope_and_rrw():
    fs, q, n = 10.0, 0.01, 1 << 20
    rng = np.random.default_rng(2)
    rate = rng.normal(0.0, 1.0, n) + np.cumsum(rng.normal(0.0, q, n))
    result = allan_deviation(rate, fs)
    region = (result.taus_s >= 100.0) & (result.blocks >= 8)
    slope = np.polyfit(np.log(result.taus_s[region]), np.log(result.deviation[region]), 1)[0]
    assert slope == pytest.approx(0.5, abs=0.15)

    terms = noise_terms(result)
    # random walk of step q per sample: σ²(τ) = K_s²·τ/3 with K_s = q·√fs [°/h/√s]
    rrw_true = q * math.sqrt(fs) * 60.0  # σ at τ = 3 h, [°/h/√h]
    assert terms.rrw_dph_per_rt_h == pytest.approx(rrw_true, rel=0.20)
    assert terms.floor_reached


def test_noise_terms_recover_ieee_952_model():
    # Annex C of IEEE Std 952-1997: σ²(τ) = N²/τ + (0.664·B)² + K²·τ/3 (τ in h for N, K).
    arw, bias_instability, rrw = 0.001, 0.05, 0.05  # [°/√h], [°/h], [°/h/√h]
    taus = 0.005 * 2.0 ** np.arange(28)  # [s]
    n_s, k_s = arw * 60.0, rrw / 60.0  # the same in τ-seconds units
    variance = n_s**2 / taus + (0.664 * bias_instability) ** 2 + k_s**2 * taus / 3.0
    allan = AllanResult(
        taus_s=taus,
        deviation=np.sqrt(variance),
        counts=np.full(taus.size, 10**9),
        overlapping=True,
        sample_rate_hz=200.0,
        n_samples=10**12,
    )
    terms = noise_terms(allan)
    assert terms.arw_deg_per_rt_h == pytest.approx(arw, rel=0.10)
    assert terms.bias_instability_dph == pytest.approx(bias_instability, rel=0.10)
    assert terms.rrw_dph_per_rt_h == pytest.approx(rrw, rel=0.20)
    assert terms.floor_reached
    assert terms.arw_taus_s[1] < terms.bias_instability_tau_s < terms.rrw_taus_s[0]


def test_noise_terms_refuse_a_record_too_short():
    result = allan_deviation(np.random.default_rng(0).normal(size=20), 1.0)
    with pytest.raises(InputError, match="at least 3 averaging times"):
        noise_terms(result)


# ----------------------------------------------------------------------------- bias stability
def test_bias_stability_equals_plain_block_means():
    rng = np.random.default_rng(8)
    rate = 7.0 + rng.normal(0.0, 2.0, 20_537) + np.linspace(0.0, 3.0, 20_537)
    fs, tau = 200.0, 10.0
    m = 2000
    means = [statistics.fmean(rate[i : i + m].tolist()) for i in range(0, 10 * m, m)]
    assert bias_stability(rate, fs, tau) == pytest.approx(statistics.stdev(means), rel=1e-12)


def test_bias_stability_of_white_noise():
    fs, sigma = 200.0, 5.0
    rate = np.random.default_rng(4).normal(0.0, sigma, 200 * 2000)
    table = bias_stability_table(rate, fs, taus_s=(0.1, 1.0, 4.0))
    for tau, value in table.items():
        blocks = int(rate.size // (tau * fs))
        tolerance = 4.0 / math.sqrt(2.0 * (blocks - 1))  # 4σ of a sample standard deviation
        assert value == pytest.approx(sigma / math.sqrt(tau * fs), rel=tolerance)


def test_bias_stability_table_gives_nan_where_too_short():
    rate = np.arange(300.0)
    table = bias_stability_table(rate, 10.0)
    assert list(table) == [1.0, 10.0, 100.0]
    assert math.isfinite(table[10.0])
    assert math.isnan(table[100.0])


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"rate_dph": np.zeros(15), "sample_rate_hz": 1.0, "tau_s": 10.0}, "at least 2 blocks"),
        ({"rate_dph": [1.0, np.nan, 2.0], "sample_rate_hz": 1.0, "tau_s": 1.0}, "index 1"),
        ({"rate_dph": np.zeros((4, 2)), "sample_rate_hz": 1.0}, "1-D"),
        ({"rate_dph": np.zeros(40), "sample_rate_hz": 0.0}, "sample_rate_hz"),
        ({"rate_dph": np.zeros(40), "sample_rate_hz": 1.0, "tau_s": 0.1}, "shorter than one"),
        ({"rate_dph": np.zeros(40), "sample_rate_hz": 1.0, "tau_s": -1.0}, "tau_s"),
    ],
)
def test_bias_stability_errors(kwargs, match):
    with pytest.raises(InputError, match=match):
        bias_stability(**kwargs)


# ----------------------------------------------------------------------------- API details
def test_allan_deviation_errors():
    with pytest.raises(InputError, match="not a known spacing"):
        allan_deviation(np.zeros(100), 1.0, taus="weekly")
    with pytest.raises(InputError, match="no averaging time"):
        allan_deviation(np.zeros(100), 1.0, taus=[1000.0])
    with pytest.raises(InputError, match="at least 3"):
        allan_deviation([1.0, 2.0], 1.0)
    with pytest.raises(InputError, match="inf"):
        allan_deviation([1.0, 2.0, np.inf, 4.0], 1.0)


def test_allan_progress_and_round_trips():
    calls = []
    rate = np.random.default_rng(1).normal(size=5000)
    result = allan_deviation(rate, 50.0, progress=lambda done, total: calls.append((done, total)))
    assert calls[-1][0] == calls[-1][1] == len(calls)
    back = AllanResult.from_dict(json.loads(json.dumps(result.to_dict())))
    np.testing.assert_array_equal(back.deviation, result.deviation)
    np.testing.assert_array_equal(back.counts, result.counts)
    assert back.n_samples == 5000 and back.sample_rate_hz == 50.0
    assert "overlapping" in result.summary().text()

    terms = noise_terms(result)
    assert NoiseTerms.from_dict(json.loads(json.dumps(terms.to_dict()))) == terms
    assert "angle random walk" in terms.summary().text()


def test_residual_against_truth():
    fs = 10.0
    time_s = np.arange(4000) / fs
    truth = 2.0 * np.sin(time_s / 50.0)
    offset = 0.3 * (np.arange(4000) >= 2000)  # the model is 0.3 °/h high in the second half
    result = residual_against_truth(
        bias_model_dph=truth + offset, true_bias_dph=truth, sample_rate_hz=fs, taus_s=(10.0, 1000.0)
    )
    assert result.mean_dph == pytest.approx(0.15)
    assert result.rms_dph == pytest.approx(math.sqrt(0.5 * 0.09))
    assert result.max_abs_dph == pytest.approx(0.3)
    # 40 blocks of 10 s, 20 at 0 and 20 at 0.3: stdev = 0.15·√(40/39)
    assert result.bias_stability_dph[10.0] == pytest.approx(0.15 * math.sqrt(40 / 39))
    assert math.isnan(result.bias_stability_dph[1000.0])
    data = json.loads(json.dumps(result.to_dict()))
    assert data["bias_stability_dph"]["1000"] is None
    back = ResidualResult.from_dict(data)
    assert back.rms_dph == result.rms_dph and math.isnan(back.bias_stability_dph[1000.0])
    assert "rms" in result.summary().text()
    with pytest.raises(InputError, match="samples but true_bias_dph"):
        residual_against_truth(bias_model_dph=truth, true_bias_dph=truth[:-1], sample_rate_hz=fs)
    with pytest.raises(TypeError):
        residual_against_truth(truth, truth, fs)  # type: ignore[misc]


def test_bias_stability_interval_covers_the_true_sigma_68_percent_of_the_time():
    from hrgtc.evaluation.metrics import bias_stability_interval

    rng = np.random.default_rng(11)
    sigma, blocks, m, trials = 2.0, 12, 50, 3000
    hits = 0
    for _ in range(trials):
        rate = rng.normal(0.0, sigma, blocks * m)
        value = bias_stability(rate, 1.0, float(m))
        low, high = bias_stability_interval(value, blocks)
        hits += low <= sigma / math.sqrt(m) <= high
    assert hits / trials == pytest.approx(0.683, abs=0.03)  # binomial sd 0.0085
    assert all(math.isnan(v) for v in bias_stability_interval(1.0, 1))
