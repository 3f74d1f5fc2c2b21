"""Fuzz: corrupted recordings and model files give a clear error or a correct result.

Random corruptions (hypothesis, derandomized by conftest's profile) of a valid CSV
and Parquet recording and of a valid model file go through ``hrgtc compensate``
in-process; :mod:`fuzzing` judges each outcome. Never a traceback, never an exit 0
with wrong numbers. ``bench/fuzz_report.py`` runs more cases and prints the counts.
"""

from __future__ import annotations

from collections import Counter

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzing import (
    Fixture,
    csv_corruption,
    judge_data,
    judge_model,
    model_corruption,
    parquet_corruption,
    write_case,
)

FUZZ = settings(max_examples=80, deadline=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
OUTCOMES: Counter = Counter()


@pytest.fixture(scope="module")
def fixture(tmp_path_factory):
    return Fixture(tmp_path_factory.mktemp("fuzz"))


def _check(outcome: str, what: str) -> None:
    OUTCOMES[outcome.split(":")[0]] += 1
    assert outcome in ("error", "correct"), f"{what}: {outcome}"


def test_corrupted_csv_recordings(fixture):
    @FUZZ
    @given(st.data())
    def case(data):
        content, what = data.draw(csv_corruption(fixture.csv_text))
        _check(judge_data(fixture, write_case(fixture.folder, "case.csv", content)), what)

    case()


def test_corrupted_parquet_recordings(fixture):
    @FUZZ
    @given(st.data())
    def case(data):
        content, what = data.draw(parquet_corruption(fixture))
        _check(judge_data(fixture, write_case(fixture.folder, "case.parquet", content)), what)

    case()


def test_corrupted_model_files(fixture):
    @FUZZ
    @given(st.data())
    def case(data):
        content, what = data.draw(model_corruption(fixture.model_text))
        _check(judge_model(fixture, write_case(fixture.folder, "case.json", content)), what)

    case()


def test_the_uncorrupted_files_give_the_expected_result(fixture):
    assert judge_data(fixture, fixture.csv_path) == "correct"
    assert judge_data(fixture, fixture.parquet_path) == "correct"
    assert judge_model(fixture, fixture.model_path) == "correct"
