"""The play memory of the simulator (the play of laws.BiasLaw, unit-play) and the lag-or-hysteresis
experiment (hrgtc.simulate.history): issue 29, item 1."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.simulate import campaign, standard_profiles, units
from hrgtc.simulate.history import HistoryExperiment, classify, settle_bound
from hrgtc.simulate.laws import BiasLaw, play_operator

FAST = HistoryExperiment(rates_c_per_min=(1.0, 0.1, 0.01))


def _play_by_hand(x, width, state):
    """The play operator written from its definition, one sample at a time."""
    out = []
    for value in x:
        state = min(max(state, value - width / 2), value + width / 2)
        out.append(state)
    return np.array(out), state


def test_play_operator_is_its_definition_and_chunk_invariant():
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(0.0, 0.3, 5000))
    whole, last = play_operator(x, 1.5, x[0] + 0.4)
    by_hand, hand_last = _play_by_hand(x, 1.5, x[0] + 0.4)
    np.testing.assert_array_equal(whole, by_hand)
    assert last == hand_last
    state, pieces = x[0] + 0.4, []
    for chunk in np.array_split(x, [1, 2, 777, 3001]):
        out, state = play_operator(chunk, 1.5, state)
        pieces.append(out)
    np.testing.assert_array_equal(np.concatenate(pieces), whole)
    assert np.all(np.abs(whole - x) <= 0.75 + 1e-12)  # never further than w/2 from its input


def test_play_law_checks_its_power_on_state():
    with pytest.raises(InputError, match="play_initial_offset_c must be within"):
        BiasLaw(4.0, play_dph_per_c=0.4, play_width_c=2.0, play_initial_offset_c=1.5)
    with pytest.raises(InputError, match="play_width_c >= 0"):
        BiasLaw(4.0, play_dph_per_c=0.4, play_width_c=-1.0)


def test_unit_play_round_trips_and_other_units_write_no_play():
    unit = units.get("unit-play")
    data = json.loads(json.dumps(unit.to_dict()))
    law = data["bias_law"]
    assert (law["play_dph_per_c"], law["play_width_c"]) == (0.4, 2.0)
    assert "play_initial_offset_c" not in law  # its default, 0, is not written
    assert units.unit_from_dict(data) == unit
    assert unit.bias_law.hysteresis_dph == 0.0  # the memory is the play, not the tanh
    for name in ("paper-unit", "unit-b"):
        assert not any(k.startswith("play") for k in units.get(name).to_dict()["bias_law"])


def test_play_state_is_carried_from_chunk_to_chunk_and_power_on_is_bounded():
    profile = standard_profiles.warmup(-20.0, 20.0, 2.0)
    whole = campaign.simulate_run(profile, "unit-play", 0.1, seed=2)
    pieces = campaign.concatenate(list(campaign.iter_run_chunks(
        profile, "unit-play", 0.1, seed=2, chunk_rows=333)))
    np.testing.assert_array_equal(whole["bias_dph"], pieces["bias_dph"])
    # another power-on history (the play at T_r + w/2 instead of T_r) changes the bias by
    # at most s * w/2, and by nothing once the warm-up has pushed the play from below
    base = units.get("unit-play")
    other = replace(base, bias_law=replace(base.bias_law, play_initial_offset_c=1.0))
    moved = campaign.simulate_run(profile, other, 0.1, seed=2)["bias_dph"] - whole["bias_dph"]
    assert np.abs(moved).max() == pytest.approx(0.4 * 1.0, rel=1e-12)
    assert np.all(np.abs(moved) <= 0.4 * 1.0 + 1e-12)
    engaged = whole["resonator_c"] > whole["resonator_c"][0] + 2.0  # risen by more than w
    assert np.abs(moved[engaged]).max() < 1e-12


def test_experiment_calls_the_play_unit_hysteresis_of_slope_times_width():
    verdict = classify("unit-play", FAST)
    law = units.get("unit-play").bias_law
    assert verdict.verdict == "hysteresis"
    # settled from above - from below = s w (engaged on both approaches), up to what the
    # lag leaves after the hold (settle_bound); that bound is small, so the test is sharp
    assert verdict.tolerance_dph < 1e-4
    assert abs(verdict.settled_difference_dph - law.play_dph_per_c * law.play_width_c) \
        <= verdict.tolerance_dph
    # the heating - cooling split does not vanish at rate 0: it goes to -s w
    assert verdict.split_at_zero_rate_dph == pytest.approx(-0.8, abs=0.01)


def test_experiment_calls_a_pure_lag_lag():
    base = units.get("unit-b")
    lag = replace(base, name="lag-only", bias_law=replace(base.bias_law, hysteresis_dph=0.0))
    verdict = classify(lag, FAST)
    assert verdict.verdict == "lag"
    assert abs(verdict.settled_difference_dph) <= verdict.tolerance_dph
    splits = np.abs(verdict.split_dph)
    assert np.all(np.diff(splits) < 0)  # shrinks as the rate goes to 0
    assert abs(verdict.split_at_zero_rate_dph) < 0.01


def test_unit_b_tanh_term_is_a_lag_not_a_memory():
    verdict = classify("unit-b", FAST)
    assert verdict.verdict == "lag"
    assert abs(verdict.settled_difference_dph) <= verdict.tolerance_dph
    # at 1 °C/min the tanh is saturated: unit-b's split exceeds the pure lag's by 2h = 0.4
    base = units.get("unit-b")
    lag = classify(replace(base, bias_law=replace(base.bias_law, hysteresis_dph=0.0)), FAST)
    assert verdict.split_dph[0] - lag.split_dph[0] == pytest.approx(0.4, abs=1e-3)


def test_settle_bound_shrinks_with_the_hold_and_refuses_multi_axis_units():
    short, long = (settle_bound("unit-b", replace(FAST, hold_h=h)) for h in (2.0, 8.0))
    assert short > 100 * long > 0.0
    with pytest.raises(InputError, match="single-axis"):
        classify("imu-3", FAST)
