"""The thermal-history variables gsat and play (issue 29, item 2): the play against the
simulator's own play operator (two implementations), causal and chunk-invariant streaming,
the power-on rule's bound, and the width grid."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.drift.features import FeatureSettings, FeatureStream, compute_variables
from hrgtc.drift.variables.play import learn_width, play_lag
from hrgtc.simulate.laws import play_operator

from synthetic import THERMOMETER, lagged_run

SETTINGS = FeatureSettings(reference_freq_hz=4425.0, sample_rate_hz=10.0, reference_c=20.0,
                           rate_tau_s=10.0, warmup_s=50.0, gradient_saturation_c=1.5,
                           play_width_c=2.0)


def _wandering(seed: int, size: int = 20000) -> np.ndarray:
    """A temperature that wanders up and down by several widths. [°C]"""
    return 10.0 * np.sin(np.linspace(0.0, 7.0, size)) + np.cumsum(
        np.random.default_rng(seed).normal(0.0, 0.05, size))


def test_play_is_the_simulators_play_operator_from_the_first_temperature():
    temperature = _wandering(1)
    model, last = play_lag(temperature, 2.0)
    truth, truth_last = play_operator(temperature, 2.0, temperature[0])
    np.testing.assert_array_equal(model, truth - temperature)
    assert last == truth_last
    assert np.all(np.abs(model) <= 1.0 + 1e-12)  # within w/2 of the temperature


def test_power_on_rule_bound_whatever_the_history():
    """Any true state within T0 ± w/2 at power-on: the variable never more than w/2 from
    the one that history gives, never further than at the start, and equal to it once the
    temperature has moved by w one way."""
    temperature = _wandering(2)
    model, _ = play_lag(temperature, 2.0)
    for offset in (-1.0, -0.4, 0.3, 1.0):
        truth = play_operator(temperature, 2.0, temperature[0] + offset)[0] - temperature
        gap = np.abs(truth - model)
        assert gap.max() <= abs(offset) + 1e-12
        assert np.all(np.diff(gap) <= 1e-12)  # the play never moves two states apart
        moved = np.flatnonzero(np.abs(temperature - temperature[0]) >= 2.0)[0]
        assert gap[moved:].max() <= 1e-12  # forgotten after a move of w


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_streaming_is_causal_and_chunk_invariant(seed):
    run = lagged_run(seed, hours=1.0)
    restart = np.zeros(len(run), dtype=bool)
    restart[[0, 9000]] = True  # a segment start: the play starts again at its temperature
    names = ("f", "g", "gsat", "play")
    whole = FeatureStream(SETTINGS, names, THERMOMETER).transform(run, restart)
    rng = np.random.default_rng(seed)
    bounds = [0, *sorted(rng.choice(np.arange(1, len(run)), 6, replace=False)), len(run)]
    stream = FeatureStream(SETTINGS, names, THERMOMETER)
    parts = [stream.transform(run.slice(a, b), restart[a:b])
             for a, b in itertools.pairwise(bounds)]
    for name in names:
        np.testing.assert_allclose(np.concatenate([p[name] for p in parts]), whole[name],
                                   rtol=0.0, atol=1e-12)
    # causal: the first rows do not depend on what follows
    head = FeatureStream(SETTINGS, names, THERMOMETER).transform(run.slice(0, 5000))
    np.testing.assert_array_equal(head["play"], whole["play"][:5000])
    # the values: gsat is tanh(g / G_s); play restarts at 0 on the restart row
    np.testing.assert_allclose(whole["gsat"], np.tanh(whole["g"] / 1.5), rtol=0, atol=1e-15)
    assert whole["play"][0] == 0.0 and whole["play"][9000] == 0.0
    assert np.abs(whole["play"]).max() == pytest.approx(1.0)  # the ramp engages the play


def test_the_variables_say_what_they_need():
    with pytest.raises(InputError, match="play needs the unit's thermometer"):
        FeatureStream(SETTINGS, ("play",))
    zero = FeatureSettings(**{**SETTINGS.to_dict(), "play_width_c": 0.0})
    with pytest.raises(InputError, match="play_width_c > 0"):
        compute_variables(lagged_run(1, hours=0.1), zero, ("play",), THERMOMETER)
    with pytest.raises(InputError, match="gradient_saturation_c > 0"):
        FeatureStream(FeatureSettings(**{**SETTINGS.to_dict(), "gradient_saturation_c": 0.0}),
                      ("gsat",), THERMOMETER)


def test_unused_history_settings_stay_out_of_the_model_file():
    """Files of models without them keep their text (their golden files and hashes)."""
    plain = FeatureSettings(**{**SETTINGS.to_dict(), "gradient_saturation_c": 0.0,
                               "play_width_c": 0.0}).to_dict()
    assert "play_width_c" not in plain and "gradient_saturation_c" not in plain
    assert SETTINGS.to_dict()["play_width_c"] == 2.0
    assert FeatureSettings.from_dict(SETTINGS.to_dict()) == SETTINGS


def test_learn_width_takes_the_lowest_finite_score():
    width, scores = learn_width(lambda w: math.nan if w > 3 else abs(w - 1.0), (0.5, 1.0, 4.0))
    assert width == 1.0 and math.isnan(scores[4.0])
    with pytest.raises(InputError, match="no width"):
        learn_width(lambda w: math.inf, (1.0,))
    with pytest.raises(InputError, match="widths must be"):
        learn_width(lambda w: 0.0, (0.0,))
