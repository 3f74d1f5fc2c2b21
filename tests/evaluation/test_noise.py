"""Tests of hrgtc.evaluation.noise: each noise term only where its slope shows."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from hrgtc.evaluation import NoiseTerms, allan_deviation, noise_terms

FS, N = 10.0, 200_000


def _terms(rate: np.ndarray) -> NoiseTerms:
    return noise_terms(allan_deviation(rate, FS))


def test_white_noise_has_arw_but_no_flat_minimum_and_no_rrw():
    sigma = 3.0
    terms = _terms(np.random.default_rng(1).normal(0.0, sigma, N))
    assert terms.arw_deg_per_rt_h == pytest.approx(sigma / math.sqrt(FS) / 60.0, rel=0.1)
    assert terms.bias_instability_dph is None and not terms.floor_reached
    assert terms.bias_instability_reason.startswith("no flat minimum: the curve still falls")
    assert terms.rrw_dph_per_rt_h is None
    assert "does not rise" in terms.rrw_reason
    assert terms.text("bias_instability") == terms.bias_instability_reason
    assert terms.text("arw") == f"{terms.arw_deg_per_rt_h:.4g}"


def test_random_walk_gives_rrw_and_a_flat_minimum():
    q = 0.01
    rng = np.random.default_rng(2)
    terms = _terms(rng.normal(0.0, 1.0, N) + np.cumsum(rng.normal(0.0, q, N)))
    assert terms.rrw_dph_per_rt_h == pytest.approx(q * math.sqrt(FS) * 60.0, rel=0.25)
    assert terms.rrw_reason is None and terms.bias_instability_reason is None
    assert terms.bias_instability_dph == pytest.approx(terms.minimum_dph / 0.664)


def test_a_thermal_ramp_is_not_rate_random_walk():
    rng = np.random.default_rng(3)
    terms = _terms(rng.normal(0.0, 1.0, N) + np.linspace(0.0, 20.0, N))
    assert terms.arw_deg_per_rt_h == pytest.approx(1.0 / math.sqrt(FS) / 60.0, rel=0.1)
    assert terms.rrw_dph_per_rt_h is None
    assert re.match(r"no \+½ slope: the curve rises as τ\^(0\.9\d|1)", terms.rrw_reason)
    assert "thermal ramp" in terms.rrw_reason
    # the old reading (any +½ points right of the minimum) would have quoted a number
    assert terms.floor_reached


def test_a_pure_ramp_has_no_arw():
    terms = _terms(np.linspace(0.0, 20.0, N) + np.random.default_rng(4).normal(0.0, 1e-4, N))
    assert terms.arw_deg_per_rt_h is None
    assert terms.arw_reason.startswith("no −½ slope")
    back = NoiseTerms.from_dict(json.loads(json.dumps(terms.to_dict())))
    assert back == terms
    assert "n/a (no −½ slope" in terms.summary().text()


def test_too_few_points_on_a_slope_say_how_many():
    from hrgtc.evaluation import AllanResult

    taus = 2.0 ** np.arange(8)
    dev = np.array([1.0, 0.72, 0.52, 0.4, 0.35, 0.33, 0.34, 0.48])  # rises as +½ only at the end
    allan = AllanResult(taus_s=taus, deviation=dev, counts=np.full(8, 10**6), overlapping=True,
                        sample_rate_hz=1.0, n_samples=10**6)
    terms = noise_terms(allan)
    assert terms.rrw_dph_per_rt_h is None
    assert terms.rrw_reason.startswith("no +½ slope: 1 point(s) right of the minimum")


def test_terms_carry_the_interval_and_n_of_the_points_they_are_read_from():
    q, sigma = 0.01, 1.0
    rng = np.random.default_rng(2)
    rate = rng.normal(0.0, sigma, N) + np.cumsum(rng.normal(0.0, q, N))
    allan = allan_deviation(rate, FS, confidence=0.683)
    terms = noise_terms(allan)
    usable = allan.blocks >= 8
    k = int(np.flatnonzero(usable)[np.argmin(allan.deviation[usable])])
    low, high = terms.bias_instability_interval
    assert low == pytest.approx(allan.lower[k] / 0.664) and high == pytest.approx(
        allan.upper[k] / 0.664)
    assert terms.bias_instability_n == allan.counts[k]
    for term, value in (("arw", terms.arw_deg_per_rt_h), ("rrw", terms.rrw_dph_per_rt_h)):
        low, high = getattr(terms, f"{term}_interval")
        assert low < value < high
        first, last = getattr(terms, f"{term}_taus_s")
        fitted = (allan.taus_s >= first) & (allan.taus_s <= last)
        assert getattr(terms, f"{term}_n") == int(allan.counts[fitted].min())
        assert re.fullmatch(r"\S+ \(\S+–\S+, N \d+\)", terms.text(term))
    # the truth of the white part is inside the ARW interval
    low, high = terms.arw_interval
    assert low < sigma / math.sqrt(FS) / 60.0 < high
    assert NoiseTerms.from_dict(json.loads(json.dumps(terms.to_dict()))) == terms
