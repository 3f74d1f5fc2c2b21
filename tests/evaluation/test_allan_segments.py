"""Every deviation pooled within segments (no difference across a gap) and its pooled edf."""

from __future__ import annotations

import math

import allantools
import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.evaluation.allan import allan_deviation, deviation_edf, equivalent_degrees_of_freedom
from hrgtc.evaluation.allan_segments import pooled_deviation, pooled_edf

FS = 10.0
#: hrgtc kind/overlapping -> allantools function (data_type="freq")
KINDS = {("allan", True): allantools.oadev, ("allan", False): allantools.adev,
         ("modified", True): allantools.mdev, ("hadamard", True): allantools.ohdev,
         ("time", True): allantools.tdev}


def _stepped_segments(seed=0, sizes=(700, 1500, 333, 1024)):
    """White noise of σ 1 plus a random walk, each segment at its own offset (a step at
    every gap, as a restart or a turn of the unit gives)."""
    rng = np.random.default_rng(seed)
    offsets = (0.0, 50.0, -30.0, 80.0)
    return [rng.normal(0.0, 1.0, n) + 0.01 * np.cumsum(rng.normal(size=n)) + offsets[k]
            for k, n in enumerate(sizes)]


def _hand_pooled(parts, function, taus):
    """allantools on each segment, combined by the pooled-variance formula
    σ² = Σ σ_k² n_k / Σ n_k (allantools drops a segment's τ with fewer than 2 terms)."""
    weighted: dict[float, float] = {}
    count: dict[float, int] = {}
    for part in parts:
        t, dev, _err, ns = function(part, rate=FS, data_type="freq", taus=taus)
        for tau, d, n in zip(t, dev, ns, strict=True):
            key = round(float(tau) * FS)
            weighted[key] = weighted.get(key, 0.0) + float(d) ** 2 * int(n)
            count[key] = count.get(key, 0) + int(n)
    return {m: (math.sqrt(weighted[m] / count[m]), count[m]) for m in weighted}


def _single_terms(parts, kind, overlapping, m):
    """Whether some segment holds exactly one term at factor m (allantools drops it)."""
    for part in parts:
        n = part.size
        terms = (n // m - 1 if not overlapping else n + 1 - 2 * m if kind == "allan"
                 else n + 1 - 3 * m if kind == "hadamard" else n + 2 - 3 * m)
        if terms == 1:
            return True
    return False


@pytest.mark.parametrize(("kind", "overlapping"), list(KINDS))
def test_pooled_deviation_equals_segments_pooled_by_hand_and_not_the_across_gap_one(
        kind, overlapping):
    parts = _stepped_segments()
    values = np.concatenate(parts)
    breaks = np.cumsum([p.size for p in parts])[:-1]
    taus = 2.0 ** np.arange(0, 10) / FS
    result = pooled_deviation(values, FS, breaks, taus, overlapping, kind=kind)
    assert result.segments == 4
    hand = _hand_pooled(parts, KINDS[kind, overlapping], taus)
    compared = 0
    for tau, dev, n in zip(result.taus_s, result.deviation, result.counts, strict=True):
        m = round(tau * FS)
        if _single_terms(parts, kind, overlapping, m):
            continue
        expected, count = hand[m]
        assert dev == pytest.approx(expected, rel=1e-9) and n == count
        compared += 1
    assert compared >= 6
    # across the gaps the steps of 30-110 show at every τ that spans one
    joined = allan_deviation(values, FS, taus, overlapping, kind=kind)
    longest = result.taus_s[-1]
    across = joined.deviation[np.flatnonzero(np.isclose(joined.taus_s, longest))[0]]
    assert across > 3.0 * result.deviation[-1]


def test_no_gap_is_the_plain_deviation_and_a_gap_changes_nothing_without_a_step():
    rng = np.random.default_rng(5)
    values = rng.normal(size=3000)
    plain = allan_deviation(values, FS, confidence=0.683)
    same = pooled_deviation(values, FS, [], confidence=0.683)
    assert same.deviation == pytest.approx(plain.deviation, rel=1e-12)
    assert same.lower == pytest.approx(plain.lower, rel=1e-12) and same.segments == 1
    assert same.counts.tolist() == plain.counts.tolist()
    long = rng.normal(size=5000)  # from 4096 samples on, the numba kernels themselves
    assert np.array_equal(pooled_deviation(long, FS).deviation,
                          allan_deviation(long, FS).deviation)
    # an offset added to the second segment leaves the pooled curve as it was
    stepped = values.copy()
    stepped[1700:] += 1e3
    a = pooled_deviation(values, FS, [1700], kind="modified")
    b = pooled_deviation(stepped, FS, [1700], kind="modified")
    assert b.deviation == pytest.approx(a.deviation, rel=1e-9)


def test_bad_breaks_and_no_tau_are_errors():
    with pytest.raises(InputError, match="breaks"):
        pooled_deviation(np.ones(10), FS, [11])
    with pytest.raises(InputError, match="two terms"):
        pooled_deviation(np.arange(12.0), FS, [2, 4, 6, 8, 10], taus=[1.0])


# ----------------------------------------------------------------------------- pooled edf
def test_pooled_edf_reduces_to_the_record_and_adds_for_equal_segments():
    for kind in ("allan", "modified", "hadamard", "time"):
        one = deviation_edf(kind, 1001, 8)
        assert pooled_edf(kind, [1000], 8) == pytest.approx(one, rel=1e-12)
        assert pooled_edf(kind, [1000] * 5, 8) == pytest.approx(5 * one, rel=1e-12)
    normal = equivalent_degrees_of_freedom(1000 // 4 + 1, 1)
    assert pooled_edf("allan", [1000, 1000], 4, overlapping=False) == pytest.approx(2 * normal)
    # segments without a term add nothing; none with a term: NaN
    assert pooled_edf("allan", [1000, 10], 8) == pytest.approx(deviation_edf("allan", 1001, 8))
    assert math.isnan(pooled_edf("allan", [10, 10], 8))


def _stencil_squares(data, kind, m):
    """Sum and number of squared stencil terms of each row of ``data`` (numpy, SP 1065)."""
    x = np.concatenate([np.zeros((data.shape[0], 1)), np.cumsum(data, axis=1)], axis=1)
    if kind == "allan":
        d = x[:, 2 * m:] - 2 * x[:, m:-m] + x[:, :-2 * m]
    elif kind == "hadamard":
        d = x[:, 3 * m:] - 3 * x[:, 2 * m:-m] + 3 * x[:, m:-2 * m] - x[:, :-3 * m]
    else:  # modified: m consecutive second differences summed
        p = np.concatenate([np.zeros((x.shape[0], 1)), np.cumsum(x, axis=1)], axis=1)
        d = p[:, 3 * m:] - 3 * p[:, 2 * m:-m] + 3 * p[:, m:-2 * m] - p[:, :-3 * m]
    return np.sum(d * d, axis=1), d.shape[1]


@pytest.mark.parametrize(("kind", "m"), [("allan", 4), ("allan", 32), ("modified", 8),
                                         ("hadamard", 8)])
def test_pooled_edf_matches_a_monte_carlo_of_the_pooled_variance(kind, m):
    """The edf of the pooled estimator, 2·E[s²]²/Var[s²] over 4000 white-noise recordings of
    three unequal segments (numpy, segment by segment), against pooled_edf (Satterthwaite
    over the segments' edfs). The Monte Carlo edf has a relative standard error of ~3 %;
    SP 1065's simple edf (Allan) and Greenhall's are themselves approximations of a few
    per cent."""
    rng = np.random.default_rng(11)
    lengths = [160, 400, 1000]
    trials = 4000
    total = np.zeros(trials)
    count = 0
    for length in lengths:
        sums, terms = _stencil_squares(rng.normal(size=(trials, length)), kind, m)
        total += sums
        count += terms
    variances = total / count  # the pooled variance up to a constant factor
    empirical = 2.0 * variances.mean() ** 2 / variances.var(ddof=1)
    assert pooled_edf(kind, lengths, m) == pytest.approx(empirical, rel=0.12)
    # and pooled_deviation is that estimator: one of the recordings through it
    data = rng.normal(size=(1, sum(lengths)))
    result = pooled_deviation(data[0], 1.0, np.cumsum(lengths)[:-1], [float(m)], kind=kind)
    parts = np.split(data, np.cumsum(lengths)[:-1], axis=1)
    sums = [_stencil_squares(p, kind, m) for p in parts]
    scale = {"allan": 2.0 * m * m, "hadamard": 6.0 * m * m, "modified": 2.0 * m ** 4}[kind]
    expected = math.sqrt(sum(s[0][0] for s in sums) / sum(s[1] for s in sums) / scale)
    assert result.deviation[0] == pytest.approx(expected, rel=1e-9)


def test_pooled_interval_uses_the_pooled_edf_not_the_total_samples():
    rng = np.random.default_rng(2)
    lengths = [100] * 10
    values = rng.normal(size=sum(lengths))
    breaks = np.cumsum(lengths)[:-1]
    result = pooled_deviation(values, 1.0, breaks, [32.0], confidence=0.683)
    edf = result.edf[0]
    assert edf == pytest.approx(10 * deviation_edf("allan", 101, 32), rel=1e-12)
    # one record of the same total length would claim 1.6 times more
    assert deviation_edf("allan", 1001, 32) > 1.5 * edf
    assert result.counts[0] == 10 * (101 - 64)
    low, high = result.lower[0], result.upper[0]
    from scipy.stats import chi2
    assert low == pytest.approx(result.deviation[0] * math.sqrt(edf / chi2.ppf(0.8415, edf)))
    assert high == pytest.approx(result.deviation[0] * math.sqrt(edf / chi2.ppf(0.1585, edf)))
