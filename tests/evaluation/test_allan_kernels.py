"""Tests of the fused kernels of hrgtc.evaluation.allan: modified Allan, Hadamard, time dev, edf.

Independent truth: allantools (oadev, mdev, ohdev, tdev, edf_simple,
confidence_interval), the previous numpy implementation of the overlapping
Allan deviation (float64 phase, one vectorised pass per τ), kept here as a
second method, and the same sums in x87 extended precision (np.longdouble).

[SP1065] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
         Publication 1065, 2008: Eq. (11), (14), (15), (20); Table 5; Eq. (45).
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import allantools
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from hrgtc.core.errors import InputError
from hrgtc.evaluation.allan import (
    ONE_SIGMA,
    AllanResult,
    allan_deviation,
    confidence_interval,
    equivalent_degrees_of_freedom,
)


def numpy_oadev(rate: np.ndarray, m: int) -> float:
    """The previous implementation: float64 phase, whole-array second differences."""
    phase = np.concatenate(([0.0], np.cumsum(rate - rate.mean())))
    d = phase[2 * m :] - 2.0 * phase[m:-m] + phase[: -2 * m]
    return math.sqrt(float(np.sum(d * d)) / (2.0 * d.size)) / m


def noise(kind: str, n: int, seed: int) -> np.ndarray:
    """Rate data of one power-law type around a large offset (as a gyro's Earth rate + bias)."""
    rng = np.random.default_rng(seed)
    if kind == "white_fm":
        y = rng.normal(0.0, 1.0, n)
    elif kind == "white_pm":
        y = np.diff(rng.normal(0.0, 1.0, n + 1))
    elif kind == "flicker_fm":
        spectrum = np.fft.rfft(rng.normal(size=n))
        spectrum[1:] /= np.sqrt(np.arange(1, spectrum.size))
        spectrum[0] = 0.0
        y = np.fft.irfft(spectrum, n)
    else:  # random-walk FM plus white
        y = np.cumsum(rng.normal(0.0, 0.05, n)) + rng.normal(0.0, 1.0, n)
    return 12.5 + y


REFERENCES = {
    "allan": allantools.oadev,
    "modified": allantools.mdev,
    "hadamard": allantools.ohdev,
    "time": allantools.tdev,
}


@pytest.mark.parametrize("noise_kind", ["white_fm", "white_pm", "flicker_fm", "rw_fm"])
@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard", "time"])
@pytest.mark.parametrize(
    "taus", ["octave", "decade", [0.01, 0.0123, 0.5, 3.333, 7.0, 19.9, 1e6]]
)
def test_equals_allantools(noise_kind, kind, taus):
    fs = 100.0
    rate = noise(noise_kind, 20_011, seed=len(noise_kind) + len(kind))
    ref_taus, ref_dev, _, ref_n = REFERENCES[kind](rate, rate=fs, data_type="freq", taus=taus)
    result = allan_deviation(rate, fs, taus=taus, kind=kind)
    np.testing.assert_array_equal(result.taus_s, ref_taus)
    np.testing.assert_array_equal(result.counts, ref_n)
    np.testing.assert_allclose(result.deviation, ref_dev, rtol=1e-12, atol=0.0)
    assert result.kind == kind


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_all_taus_equal_allantools_on_a_short_record(kind):
    rate = noise("rw_fm", 301, seed=9)
    ref_taus, ref_dev, _, ref_n = REFERENCES[kind](rate, rate=2.0, data_type="freq", taus="all")
    result = allan_deviation(rate, 2.0, taus="all", kind=kind)
    np.testing.assert_array_equal(result.taus_s, ref_taus)
    np.testing.assert_array_equal(result.counts, ref_n)
    np.testing.assert_allclose(result.deviation, ref_dev, rtol=1e-12, atol=0.0)


def test_equals_the_previous_numpy_implementation():
    rate = noise("white_fm", 300_007, seed=4)
    result = allan_deviation(rate, 1.0, taus=[1, 3, 64, 4097, 50_000])
    expected = [numpy_oadev(rate, m) for m in (1, 3, 64, 4097, 50_000)]
    np.testing.assert_allclose(result.deviation, expected, rtol=1e-12, atol=0.0)


def test_accurate_where_a_float64_phase_is_not():
    # A tiny noise on a huge, drifting rate: the float64 phase (allantools, the
    # old numpy path) loses digits; extended precision shows the kernels do not.
    rng = np.random.default_rng(21)
    n = 200_000
    rate = 1e4 + np.cumsum(rng.normal(0.0, 1e-3, n)) + rng.normal(0.0, 1e-2, n)
    ms = [1, 16, 1024, 30_000]
    mean = np.mean(rate)  # the same y - mean as the kernels
    phase = np.concatenate(([0.0], np.cumsum((rate - mean).astype(np.longdouble))))
    exact = []
    for m in ms:
        d = phase[2 * m :] - 2 * phase[m:-m] + phase[: -2 * m]
        exact.append(float(np.sqrt(np.sum(d * d) / (2 * d.size)) / m))
    result = allan_deviation(rate, 1.0, taus=ms)
    np.testing.assert_allclose(result.deviation, exact, rtol=1e-13, atol=0.0)


def test_deterministic_bits_for_any_thread_count():
    import numba

    from hrgtc.evaluation import _allan_kernels

    rate = noise("rw_fm", 100_003, seed=5)
    first = allan_deviation(rate, 10.0, kind="modified").deviation
    again = allan_deviation(rate, 10.0, kind="modified").deviation
    previous = _allan_kernels.THREADS
    try:
        _allan_kernels.THREADS = 1
        single = allan_deviation(rate, 10.0, kind="modified").deviation
    finally:
        _allan_kernels.THREADS = previous
    assert numba.get_num_threads() >= 1
    assert first.tobytes() == again.tobytes() == single.tobytes()


@settings(max_examples=30, deadline=None)
@given(
    data=st.lists(
        st.floats(min_value=-1e3, max_value=1e3, allow_nan=False), min_size=12, max_size=300
    ),
    offset=st.floats(min_value=-1e4, max_value=1e4, allow_nan=False),
    kind=st.sampled_from(["allan", "modified", "hadamard", "time"]),
)
def test_constant_offset_leaves_every_deviation_unchanged(data, offset, kind):
    rate = np.array(data)
    base = allan_deviation(rate, 10.0, kind=kind)
    shifted = allan_deviation(rate + offset, 10.0, kind=kind)
    np.testing.assert_array_equal(shifted.taus_s, base.taus_s)
    atol = 1e-12 * (abs(offset) + np.max(np.abs(rate)) + 1.0)  # rounding of rate + offset
    np.testing.assert_allclose(shifted.deviation, base.deviation, rtol=1e-9, atol=atol)


# ----------------------------------------------------------------------------- edf and CI
@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
@pytest.mark.parametrize("m", [1, 2, 7, 100, 499])
def test_simple_edf_equals_allantools(alpha, m):
    # [SP1065] Table 5, as allantools.edf_simple
    assert equivalent_degrees_of_freedom(1001, m, alpha) == pytest.approx(
        allantools.edf_simple(1001, m, alpha), rel=1e-13
    )


@pytest.mark.parametrize("level", [ONE_SIGMA, 0.9, 0.95])
def test_confidence_interval_equals_allantools(level):
    rate = noise("white_fm", 5001, seed=2)
    result = allan_deviation(rate, 1.0, confidence=level, noise_alpha=0)
    for k, m in enumerate(result.taus_s):
        edf = allantools.edf_simple(5002, m, 0)
        lo, hi = allantools.confidence_interval(result.deviation[k], edf, ci=level)
        assert result.lower[k] == pytest.approx(lo, rel=1e-12)
        assert result.upper[k] == pytest.approx(hi, rel=1e-12)
    assert np.all(result.lower < result.deviation) and np.all(result.deviation < result.upper)
    assert result.confidence == level


def test_confidence_interval_covers_white_noise_truth():
    rate = np.random.default_rng(8).normal(0.0, 2.0, 200_000)
    result = allan_deviation(rate, 1.0, confidence=0.999, taus=[1, 10, 100, 1000])
    truth = 2.0 / np.sqrt(result.taus_s)  # white FM: σ(τ) = σ/√m
    assert np.all((result.lower < truth) & (truth < result.upper))


def test_result_with_interval_round_trips_and_reports():
    rate = noise("white_fm", 3000, seed=1)
    result = allan_deviation(rate, 10.0, confidence=0.95)
    back = AllanResult.from_dict(json.loads(json.dumps(result.to_dict())))
    np.testing.assert_array_equal(back.lower, result.lower)
    np.testing.assert_array_equal(back.upper, result.upper)
    assert back.confidence == 0.95 and back.kind == "allan"
    assert "lower" in result.summary().text() and "0.95 confidence" in result.summary().text()
    plain = allan_deviation(rate, 10.0, kind="hadamard")
    assert plain.lower is None
    assert AllanResult.from_dict(json.loads(json.dumps(plain.to_dict()))).kind == "hadamard"
    assert "Hadamard deviation" in plain.summary().text()


def test_errors():
    rate = np.zeros(100)
    with pytest.raises(InputError, match="not a known deviation"):
        allan_deviation(rate, 1.0, kind="total")
    with pytest.raises(InputError, match="overlapping form only"):
        allan_deviation(rate, 1.0, kind="modified", overlapping=False)
    with pytest.raises(InputError, match=r"confidence must be in \(0, 1\)"):
        allan_deviation(rate, 1.0, confidence=1.5)
    with pytest.raises(InputError, match="noise_alpha=3"):
        equivalent_degrees_of_freedom(101, 2, 3)
    with pytest.raises(InputError, match="m=60"):
        equivalent_degrees_of_freedom(101, 60, 0)
    with pytest.raises(InputError, match="no averaging time"):
        allan_deviation(rate, 1.0, taus=[40.0], kind="hadamard")


def test_importing_allan_does_not_import_numba():
    code = ("import sys, hrgtc.evaluation.allan, hrgtc.evaluation.metrics; "
            "print('numba' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_confidence_interval_function_on_arrays():
    lower, upper = confidence_interval([1.0, 2.0], [10.0, 1000.0], 0.9)
    assert lower.shape == upper.shape == (2,)
    assert upper[1] / lower[1] < upper[0] / lower[0]  # more edf, narrower interval


def test_non_overlapping_interval_covers_68_percent_of_white_noise_records():
    rng = np.random.default_rng(17)
    sigma, m, n, trials = 1.0, 4, 96, 2000  # 24 τ-means: 22 second differences
    truth = sigma / math.sqrt(m)  # white rate noise: σ_y(τ) = σ/√m
    hits = 0
    for _ in range(trials):
        result = allan_deviation(rng.normal(0.0, sigma, n), 1.0, taus=[float(m)],
                                 overlapping=False, confidence=ONE_SIGMA)
        hits += result.lower[0] <= truth <= result.upper[0]
    assert hits / trials == pytest.approx(ONE_SIGMA, abs=0.035)  # binomial sd 0.010


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_many_taus_shared_among_threads_equal_one_tau_at_a_time_bit_for_bit(kind, monkeypatch):
    """From MANY_TAUS τ on, the τ (not the blocks of one τ) go to the threads: same bits."""
    from hrgtc.evaluation import _allan_kernels

    rate = noise("flicker_fm", 9_001, seed=11)  # 3 blocks at small m, 1 at large
    taus = np.arange(1, 2_000, 7) / 4.0
    many = allan_deviation(rate, 4.0, taus=taus, kind=kind)
    monkeypatch.setattr(_allan_kernels, "MANY_TAUS", 10**9)
    one = allan_deviation(rate, 4.0, taus=taus, kind=kind)
    assert many.taus_s.size >= _allan_kernels.TAU_BATCH + 1  # two batches, the last partial
    assert many.deviation.tobytes() == one.deviation.tobytes()
    np.testing.assert_array_equal(many.counts, one.counts)
