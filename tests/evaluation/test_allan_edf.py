"""Tests of hrgtc.evaluation._allan_edf: Greenhall's edf and the intervals of mdev, tdev, hdev.

Independent truth: allantools (``edf_greenhall``, ``confidence_interval``, ``mdev``,
``tdev``, ``ohdev``), which implements [GR2003] separately; and the coverage of the
interval on simulated white noise, whose modified Allan variance is known exactly.

[SP1065] W. J. Riley, "Handbook of Frequency Stability Analysis", NIST Special
         Publication 1065, 2008: Section 5.3.3, Eq. (45).
[GR2003] C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based on
         finite differences", Proc. 35th PTTI Meeting, 2003.
"""

from __future__ import annotations

import math

import allantools
import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.evaluation.allan import (
    ONE_SIGMA,
    allan_deviation,
    deviation_edf,
    equivalent_degrees_of_freedom,
    greenhall_edf,
)

# (d, overlapping, modified) of mdev/tdev, ohdev, hdev, oadev, adev (allantools.ci's table)
ESTIMATORS = [(2, True, True), (3, True, False), (3, False, False), (2, True, False),
              (2, False, False)]


@pytest.mark.parametrize(("d", "overlapping", "modified"), ESTIMATORS)
@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
@pytest.mark.parametrize("n_phase", [61, 1001, 100_001])
def test_greenhall_edf_equals_allantools(d, overlapping, modified, alpha, n_phase):
    # m from 1 to beyond J_max = 100: the basic sum (Eq. 10) and the tables 1-3 of [GR2003]
    for m in (1, 2, 3, 4, 8, 16, 33, 64, 256, 4096):
        if n_phase < m / (1 if modified else m) + m * d + 1:
            continue
        try:
            expected = allantools.edf_greenhall(alpha, d, m, n_phase, overlapping=overlapping,
                                                modified=modified)
        except NotImplementedError:  # white PM, unmodified, < d + 1 terms: open in [GR2003]
            expected = math.nan
        ours = greenhall_edf(n_phase, m, alpha, d, overlapping=overlapping, modified=modified)
        if math.isnan(expected):
            assert math.isnan(ours)
        else:
            assert ours == pytest.approx(expected, rel=1e-12), (m, ours, expected)


@pytest.mark.parametrize(("kind", "reference", "d", "modified"), [
    ("modified", allantools.mdev, 2, True), ("time", allantools.tdev, 2, True),
    ("hadamard", allantools.ohdev, 3, False)])
@pytest.mark.parametrize("alpha", [1, 0, -1, -2])
@pytest.mark.parametrize("confidence", [ONE_SIGMA, 0.95])
def test_intervals_equal_allantools(kind, reference, d, modified, alpha, confidence):
    rate = np.random.default_rng(7).normal(0.0, 0.3, 3000) + 5.0
    fs = 10.0
    result = allan_deviation(rate, fs, "octave", kind=kind, confidence=confidence,
                             noise_alpha=alpha)
    taus, devs, _, _ = reference(rate, rate=fs, data_type="freq", taus="octave")
    np.testing.assert_allclose(result.deviation, devs, rtol=1e-9)
    for k, (tau, dev) in enumerate(zip(taus, devs, strict=True)):
        m = round(tau * fs)
        edf = allantools.edf_greenhall(alpha, d, m, rate.size + 1, overlapping=True,
                                       modified=modified)
        low, high = allantools.confidence_interval(dev, edf, ci=confidence)
        assert result.lower[k] == pytest.approx(low, rel=1e-9)
        assert result.upper[k] == pytest.approx(high, rel=1e-9)
        assert result.lower[k] < result.deviation[k] < result.upper[k]
    assert result.confidence == confidence


def test_mdev_interval_covers_the_true_value_68_percent_of_the_time():
    # white FM: the mean of 300 variance estimates (unbiased) stands for the true value
    rng = np.random.default_rng(11)
    m_index = 3  # m = 8
    estimates, lows, highs = [], [], []
    for _ in range(300):
        result = allan_deviation(rng.normal(size=400), 1.0, "octave", kind="modified",
                                 confidence=ONE_SIGMA)
        estimates.append(result.deviation[m_index])
        lows.append(result.lower[m_index])
        highs.append(result.upper[m_index])
    truth = math.sqrt(np.mean(np.square(estimates)))  # the variance is unbiased
    covered = np.mean([lo <= truth <= hi for lo, hi in zip(lows, highs, strict=True)])
    assert 0.60 <= covered <= 0.76


def test_deviation_edf_and_errors():
    assert deviation_edf("allan", 1001, 4) == equivalent_degrees_of_freedom(1001, 4)
    assert deviation_edf("time", 1001, 4, -1) == deviation_edf("modified", 1001, 4, -1)
    assert deviation_edf("hadamard", 1001, 4, -2) == greenhall_edf(1001, 4, -2, 3)
    with pytest.raises(InputError, match="kind='total'"):
        deviation_edf("total", 1001, 4)
    with pytest.raises(InputError, match="does not converge"):
        greenhall_edf(1001, 4, -2, 1)
    with pytest.raises(InputError, match="noise_alpha=3"):
        greenhall_edf(1001, 4, 3, 2)
    with pytest.raises(InputError, match="m=400 needs"):
        greenhall_edf(1001, 400, 0, 3)
