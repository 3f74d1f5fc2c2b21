"""The history step of the estimator (issue 29): ``play`` and ``gsat`` added on top of a
fit's own selection, the play's width by leave-one-run-out, each kept only where it wins
(:func:`hrgtc.pipeline.terms.add_history`)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from hrgtc.pipeline.terms import ALL_IN, add_history

CANDIDATES = ("f", "f^2", "f^3", "g", "f*g", "f^2*g")


def _model(selected, score, width=0.0, candidates=CANDIDATES):
    validation = None if score is None else SimpleNamespace(score_dph=score)
    drift = SimpleNamespace(selected=tuple(selected), cross_validation=validation,
                            candidates=tuple(candidates),
                            settings=SimpleNamespace(play_width_c=width))
    return SimpleNamespace(axes={"": SimpleNamespace(drift=drift)})


class _Fits:
    """A fit whose leave-one-run-out score is given per term set and width; the selection
    with ``play`` offered keeps ``offered``."""

    def __init__(self, base_terms, base_score, play_scores, gsat_gain=0.0,
                 candidates=CANDIDATES, offered=None):
        self.base_terms, self.base_score = tuple(base_terms), base_score
        self.play_scores, self.gsat_gain, self.candidates = play_scores, gsat_gain, candidates
        self.offered = (*self.base_terms, "play") if offered is None else tuple(offered)
        self.calls: list[dict] = []

    def __call__(self, options):
        self.calls.append(dict(options))
        if not options:
            return _model(self.base_terms, self.base_score, candidates=self.candidates)
        terms, width = tuple(options["terms"]), options["play_width_c"]
        if "select" not in options:  # the selection with the history term offered
            return _model(self.offered, 0.5, width, self.candidates)
        score = self.play_scores[width] if "play" in terms else self.base_score
        if "gsat" in terms:
            score -= self.gsat_gain
        return _model(terms, score, width, self.candidates)


def test_play_with_the_base_powers_of_f_and_the_rest_chosen_with_play_offered():
    # offered play, the selection drops f^3 (play stands in for it) and f^2*g (which
    # stood in for the memory without play) and finds f*g
    fits = _Fits(("f", "f^2", "f^3", "g", "f^2*g"), 0.33, {1.0: 0.32, 2.0: 0.30, 4.0: 0.31},
                 offered=("f", "f^2", "g", "f*g", "play"))
    choice = add_history(fits, (1.0, 2.0, 4.0))
    assert choice.added == ("play",)
    assert choice.play_width_c == 2.0
    assert choice.model.axes[""].drift.selected == ("f", "f^2", "f^3", "g", "f*g", "play")
    offered = [c for c in fits.calls[1:] if "select" not in c]
    forced = [c for c in fits.calls[1:] if "select" in c]
    assert [c["play_width_c"] for c in offered] == [1.0, 2.0, 4.0]
    assert all(c["terms"] == (*CANDIDATES, "play") for c in offered)
    for options in forced:  # refitted as they are, none chosen again
        assert {k: options[k] for k in ALL_IN} == ALL_IN
    assert choice.scores["base"] == 0.33 and choice.scores["play w=2"] == 0.30


def test_history_terms_that_do_not_beat_the_base_score_are_not_kept():
    fits = _Fits(("f", "g"), 0.30, {1.0: 0.31, 2.0: 0.305}, gsat_gain=-0.01)
    choice = add_history(fits, (1.0, 2.0))
    assert choice.added == ()
    assert choice.model is choice.base
    assert choice.play_width_c == 2.0  # the best width is still said
    assert choice.scores["+gsat"] == pytest.approx(0.31)


def test_gsat_is_kept_on_top_of_play_only_when_it_lowers_the_score_again():
    fits = _Fits(("f", "g"), 0.33, {2.0: 0.31}, gsat_gain=0.02)
    choice = add_history(fits, (2.0,))
    assert choice.added == ("play", "gsat")
    assert choice.model.axes[""].drift.selected == ("f", "g", "play", "gsat")
    assert fits.calls[-1]["play_width_c"] == 2.0


def test_gsat_is_not_tried_without_the_gradient_among_the_candidates():
    fits = _Fits(("f",), 0.33, {2.0: 0.31}, gsat_gain=0.02, candidates=("f", "f^2"))
    choice = add_history(fits, (2.0,))
    assert choice.added == ("play",)
    assert "+gsat" not in choice.scores
    assert all("gsat" not in options.get("terms", ()) for options in fits.calls)


def test_one_training_run_keeps_no_history_term_and_fits_nothing_more():
    fits = _Fits(("f", "g"), None, {2.0: 0.1})
    choice = add_history(fits, (2.0,))
    assert choice.added == () and choice.model is choice.base
    assert math.isinf(choice.scores["base"])
    assert fits.calls == [{}]


def test_the_axis_judged_is_the_one_named():
    def fit(options):
        terms = tuple(options.get("terms", ("f",)))
        score = 0.35 if "play" in terms else 0.4
        if options and "select" not in options:
            terms = ("f", "play")
        return SimpleNamespace(axes={"x": _model(terms, score, candidates=("f",)).axes[""],
                                     "y": _model(("f", "play"), 0.1).axes[""]})

    choice = add_history(fit, (2.0,), axis="x")
    assert choice.added == ("play",)
    assert choice.model.axes["x"].drift.selected == ("f", "play")
    assert choice.scores == {"base": 0.4, "play w=2": 0.35}
