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


# -- plausible-looking corruptions (issue 21): a fixed sample of bench/audit.py's corpus -------
from auditing import Audit  # noqa: E402
from corruptions import Material, recording_cases  # noqa: E402
from model_corruptions import model_cases  # noqa: E402

#: One case of each class this branch fixed or the main branch handles, run in ``make test``;
#: ``python bench/audit.py`` runs all of them (and those other engineers fix).
SAMPLE = (
    "rate_dph_z dropped / 3-axis .csv",
    "rate_dph_z renamed rate_z / 3-axis .parquet",
    "rate_dph_x stored n3 / 3-axis .h5",
    "rate_dph stored n1 / 1-axis .h5",
    "freq_hz stored scalar / 1-axis .h5",
    "rate_dph stored compound / 1-axis .h5",
    "headers freq_hz/rate_dph swapped / 1-axis .csv",
    "rate x57.3 (logged in rad/s) / 1-axis .parquet",
    "compensated file / 1-axis .parquet",
    "CR-only line ends / 1-axis .csv",
    "trailing delimiter / 3-axis .csv",
    "spaces / 1-axis .csv",
    "duplicated header name / 1-axis .csv",
    "rate x1/3600 (logged in °/h, declared °/s) / 1-axis .parquet",
    "rate_dph_y x3600 only / 3-axis .csv",
    "time in ms / 3-axis .h5",
    "bursts of 5 s every 30 s / 1-axis .csv",
    "one row missing (2 periods: not a gap) / 1-axis .h5",
    "NaN in rate_dph_x row 4321 / 3-axis .parquet",
    "drift.ranges.f reversed",
    "truncated at 50%",
    # issue 27's audit
    "stray rate_dph_x beside rate_dph / 1-axis .csv",
    "upper-case header / 3-axis .csv",
    "stray CR inside row 500 / 1-axis .csv",
    "only 5 rows / 1-axis .parquet",
    "headers chamber_c/temperature_c swapped / 1-axis .parquet",
    "duplicate key 'intercept_dph' in drift",
)


@pytest.fixture(scope="module")
def audit(tmp_path_factory):
    folder = tmp_path_factory.mktemp("audit")
    audit = Audit(Material(folder / "material"), folder / "work")
    for axes in ("1", "3"):  # the undamaged files' results, once
        for command in ("info", "compensate", "evaluate", "calibrate"):
            audit.baseline(command, axes)
    return audit


def test_the_corpus_is_as_large_as_the_issue_asks():
    recordings, models = recording_cases(), model_cases()
    assert len(recordings) >= 600 and len(models) >= 70
    assert len({c.name for c in recordings + models}) == len(recordings) + len(models)
    for case in recordings + models:  # every error names what the message must carry
        for expect in case.expect.values():
            assert expect.outcome != "error" or expect.names or case.family == "damaged bytes"


@pytest.mark.parametrize("name", SAMPLE)
def test_a_sample_of_plausible_corruptions_gives_clear_errors_or_correct_results(audit, name):
    """Clear errors or correct results (silent only where the docs say nothing can tell)."""
    case = next(c for c in recording_cases() + model_cases() if c.name == name)
    for outcome in audit.run(case):
        assert outcome.verdict in ("clear", "correct") or outcome.undetectable, (
            f"{name} / {outcome.command}: {outcome.verdict}: {outcome.message}")
