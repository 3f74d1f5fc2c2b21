"""Tests of hrgtc.recording.time_checks._change_row: where a sample rate changes, and to what.

Written for mutants that no test killed (make mutation, issue 21): the validator says "the
sample rate changes within the file: split it at row N", and N must be the row of the
change. Truth: step series built with the change at a known row (10 Hz -> 8 Hz).
"""

from __future__ import annotations

import numpy as np

from hrgtc.recording.time_checks import _change_row

ROWS, PERIOD_S = 100, 0.1  # blocks of 100 steps; nominal 10 Hz


def _steps(change: int = 230, size: int = 400) -> np.ndarray:
    """Steps of 0.1 s, then of 0.125 s (8 Hz) from step ``change`` on."""
    steps = np.full(size, PERIOD_S)
    steps[change:] = 0.125
    return steps


def test_the_change_is_found_at_its_row_not_at_an_earlier_jitter():
    steps = _steps()
    steps[20] = 0.125  # one late sample long before: not the change
    assert _change_row(steps, 2, ROWS, PERIOD_S) == (229, 8.0)


def test_a_first_new_step_within_half_the_tolerance_starts_the_change():
    steps = _steps()
    steps[230] = 0.1255  # 0.4 % off the new period: it is the new rate
    assert _change_row(steps, 2, ROWS, PERIOD_S) == (229, 8.0)


def test_an_intermediate_step_between_the_rates_is_not_the_change():
    steps = _steps()
    steps[229] = 0.1228  # 1.8 % off the new period: the transition, not the new rate
    assert _change_row(steps, 2, ROWS, PERIOD_S) == (229, 8.0)


def test_a_change_at_the_first_step_is_at_row_zero():
    assert _change_row(np.full(300, 0.125), 0, ROWS, PERIOD_S) == (0, 8.0)


def test_zero_steps_do_not_count_in_the_new_rate():
    steps = _steps(change=260)
    steps[200:240] = 0.0  # duplicated times: not a period
    assert _change_row(steps, 2, ROWS, PERIOD_S) == (259, 8.0)


def test_the_search_stays_within_the_block_that_changed():
    steps = _steps(change=300)
    steps[230:250] = 0.12
    steps[250:300] = 0.13  # jitter: the median, 0.125, is none of the steps
    at, rate_hz = _change_row(steps, 2, ROWS, PERIOD_S)
    assert at == 199 and rate_hz == 1.0 / 0.125
