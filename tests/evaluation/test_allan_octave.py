"""Tests of the compiled octave Allan sums (hrgtc.evaluation._allan_octave, _allan_sums).

Independent truths: the numba kernels (checkpointed double-double phase, another
algorithm), the sums in exact rational arithmetic (fractions.Fraction) and allantools.

[SP1065] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
         Publication 1065, 2008: Eq. (11).
"""

from __future__ import annotations

import subprocess
import sys
from fractions import Fraction

import allantools
import numpy as np
import pytest

from hrgtc.evaluation import _allan_kernels, _allan_octave, _allan_sums
from hrgtc.evaluation.allan import allan_deviation


def octave_factors(n: int) -> np.ndarray:
    """The octave factors with at least two terms in n samples (allan_deviation's)."""
    return np.array([2**k for k in range(64) if n + 1 - 2 * 2**k > 1], dtype=np.int64)


def native(y: np.ndarray) -> np.ndarray:
    levels = octave_factors(y.size).size
    return np.array(_allan_octave.octave_sums(y, float(np.mean(y)), levels))


def drifting(n: int, seed: int) -> np.ndarray:
    """A tiny noise on a large, random-walking rate: a float64 phase loses digits here."""
    rng = np.random.default_rng(seed)
    return 1e4 + np.cumsum(rng.normal(0.0, 1e-3, n)) + rng.normal(0.0, 1e-2, n)


def ramp(n: int, seed: int) -> np.ndarray:
    """A steep linear drift under a small noise: the phase is large, its curvature small."""
    return 1e4 + np.arange(n) + np.random.default_rng(seed).normal(0.0, 1e-3, n)


def white(n: int, seed: int) -> np.ndarray:
    return 12.5 + np.random.default_rng(seed).normal(0.0, 1.0, n)


def exact_sums(y: np.ndarray, factors: np.ndarray) -> list[float]:
    """Σ (X[i+2m] − 2X[i+m] + X[i])² in rational arithmetic, X the phase of y − mean."""
    mean = Fraction(float(np.mean(y)))
    phase = [Fraction(0)]
    for value in y.tolist():
        phase.append(phase[-1] + Fraction(value) - mean)
    out = []
    for m in factors.tolist():
        total = Fraction(0)
        for i in range(len(phase) - 2 * m):
            d = phase[i + 2 * m] - 2 * phase[i + m] + phase[i]
            total += d * d
        out.append(float(total))
    return out


# sizes around the chunk (32768 terms) and the octaves, several chunks per pass, and
# factors beyond the sweep's (m > 65536: one plain pass per two octaves from 524_289 on)
@pytest.mark.parametrize("n", [3, 4, 5, 6, 7, 8, 9, 17, 1000, 32_769, 65_537, 70_001,
                               262_144, 300_007, 600_001, 2_100_003])
@pytest.mark.parametrize("data", [white, drifting])
def test_equals_the_numba_kernels(n, data):
    y = data(n, seed=n)
    factors = octave_factors(n)
    ours = native(y)
    theirs = _allan_kernels.sums_of_squares(y, "allan", factors)
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=0.0)


@pytest.mark.parametrize("data", [white, drifting, ramp])
def test_equals_the_exact_sums(data):
    y = data(3001, seed=7)
    factors = octave_factors(y.size)
    np.testing.assert_allclose(native(y), exact_sums(y, factors), rtol=1e-14, atol=0.0)


@pytest.mark.parametrize("n", [32_769, 300_007])
def test_a_long_steep_ramp_to_extended_precision(n):
    # the numba kernels' recursion loses ~1e-11 here (the step's rounding, carried over a
    # block); the pairwise sums stay at ~1e-14 of the same sums in x87 extended precision
    y = ramp(n, seed=n)
    factors = octave_factors(n)
    phase = np.concatenate(([0.0], np.cumsum((y - np.mean(y)).astype(np.longdouble))))
    extended = [np.sum((phase[2 * m:] - 2 * phase[m:-m] + phase[:-2 * m]) ** 2)
                for m in factors.tolist()]
    np.testing.assert_allclose(native(y), np.array(extended, dtype=np.float64),
                               rtol=5e-14, atol=0.0)


def test_a_float64_phase_is_less_accurate_on_the_same_data():
    # the test above would catch a phase-based kernel: allantools (a float64 phase)
    # misses the exact sums by far more than its tolerance
    y = ramp(3001, seed=7)
    factors = octave_factors(y.size)
    exact = np.array(exact_sums(y, factors))
    _, dev, _, counts = allantools.oadev(y, rate=1.0, data_type="freq", taus=factors * 1.0)
    theirs = dev**2 * 2.0 * counts * factors.astype(float) ** 2
    assert np.max(np.abs(theirs / exact - 1.0)) > 2e-14
    assert np.max(np.abs(native(y) / exact - 1.0)) < 2e-15


def test_the_same_bits_from_call_to_call():
    y = drifting(300_007, seed=3)  # 10 chunks in the first pass, swept and plain passes
    assert native(y).tobytes() == native(y).tobytes()


def test_allan_deviation_takes_the_native_path_for_power_of_two_factors(monkeypatch):
    y = white(50_001, seed=2)
    calls = []
    real = _allan_sums.octave_sums
    monkeypatch.setattr(_allan_sums, "octave_sums",
                        lambda *args: calls.append(args[1]) or real(*args))
    octave = allan_deviation(y, 10.0, taus="octave")
    some = allan_deviation(y, 10.0, taus=[0.1, 0.4, 1638.4])  # m = 1, 4, 16384
    assert len(calls) == 2 and calls[1].tolist() == [1, 4, 16384]
    np.testing.assert_array_equal(some.deviation, octave.deviation[[0, 2, 14]])
    ref_taus, ref_dev, _, ref_n = allantools.oadev(y, rate=10.0, data_type="freq",
                                                   taus="octave")
    np.testing.assert_array_equal(octave.taus_s, ref_taus)
    np.testing.assert_array_equal(octave.counts, ref_n)
    np.testing.assert_allclose(octave.deviation, ref_dev, rtol=1e-12, atol=0.0)
    allan_deviation(y, 10.0, taus="decade")  # m = 10 is no power of two: numba
    assert len(calls) == 2


_NO_NUMBA = """
import sys
import numpy as np
from hrgtc.evaluation.allan import allan_deviation
result = allan_deviation(np.random.default_rng(1).normal(size=100_000), 200.0,
                         taus="octave", kind=sys.argv[1])
print("numba" in sys.modules, result.deviation.size)
"""


@pytest.mark.parametrize(("kind", "numba"), [("allan", False), ("modified", True)])
def test_the_octave_allan_path_does_not_import_numba(kind, numba):
    out = subprocess.run([sys.executable, "-c", _NO_NUMBA, kind], capture_output=True,
                         text=True, check=True).stdout.split()
    assert out == [str(numba), "16"]


def test_a_missing_build_says_how_to_build_it(monkeypatch):
    import hrgtc.evaluation

    monkeypatch.setitem(sys.modules, "hrgtc.evaluation._allan_octave", None)
    monkeypatch.delattr(hrgtc.evaluation, "_allan_octave")
    with pytest.raises(ImportError, match=r"make \.venv/\.installed"):
        allan_deviation(white(1000, seed=1), 1.0)


def test_the_module_refuses_what_it_cannot_sum():
    y = white(100, seed=1)
    with pytest.raises(TypeError, match="float64"):
        _allan_octave.octave_sums(y.astype(np.float32), 0.0, 2)
    with pytest.raises(ValueError, match="contiguous"):
        _allan_octave.octave_sums(y[::2], 0.0, 2)
    with pytest.raises(ValueError, match="no term"):
        _allan_octave.octave_sums(y, 0.0, 8)  # m = 128 > 100 / 2
