"""Tests of hrgtc.recording.time_checks._change_row: where a sample rate changes, and to what.

Written for mutants that no test killed (make mutation, issue 21): the validator says "the
sample rate changes within the file: split it at row N", and N must be the row of the
change. Truth: step series built with the change at a known row (10 Hz -> 8 Hz).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

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


# -- the hint for a step back in time (_step_diagnosis, through validate) --------------------
def _in_memory(time_s: np.ndarray, rate_dph: np.ndarray | None = None):
    from hrgtc.recording import Metadata, Recording

    rng = np.random.default_rng(0)
    n = time_s.size
    rate_dph = rng.normal(10.0, 1.0, n) if rate_dph is None else rate_dph
    return Recording({"time_s": time_s, "freq_hz": 4428.5 + rng.normal(0.0, 1e-3, n),
                      "rate_dph": rate_dph}, Metadata(sample_rate_hz=10.0, input_rate_dph=10.0))


def _step_back_cases():
    t = 10_000.0 + np.arange(3000) / 10.0  # the step back at row 2000, past the 1000 rows
    duplicate_time = t.copy()
    duplicate_time[2000] = duplicate_time[1999]
    back = t.copy()
    back[2000:] -= 50.0
    hour = t.copy()
    hour[2000:] -= 3600.0  # seconds, not clock times: not daylight saving time
    reset = t.copy()
    reset[2000:] -= reset[2000]
    wrap = (4294.967296 - 150.0 + np.arange(3000) / 10.0) % 4294.967296  # at row 1500
    return [(duplicate_time, 2000, "two records with the same time and other values"),
            (back, 2000, "neither a counter wrap, a reset to zero nor a duplicated block"),
            (hour, 2000, "neither a counter wrap, a reset to zero nor a duplicated block"),
            (reset, 2000, "the logger's clock restarted near zero"),
            (wrap, 1500, "a 32-bit time counter wrapped")]


@pytest.mark.parametrize(("time_s", "row", "hint"), _step_back_cases(),
                         ids=["duplicate_time", "back", "hour", "reset", "wrap"])
def test_a_step_back_is_diagnosed_at_its_row(time_s, row, hint):
    from hrgtc.core.errors import RecordingError
    from hrgtc.recording import validate

    with pytest.raises(RecordingError, match=rf"row {row}: .*; {re.escape(hint)}"):
        validate(_in_memory(time_s))


def test_repeated_rows_are_diagnosed_as_a_duplicated_block():
    from hrgtc.core.errors import RecordingError
    from hrgtc.recording import Metadata, Recording, validate

    run = _in_memory(10_000.0 + np.arange(3000) / 10.0)
    rows = np.r_[np.arange(2000), np.arange(1990, 3000)]  # rows 1990-1999 sent twice
    repeated = Recording({name: run[name][rows] for name in run.names},
                         Metadata(sample_rate_hz=10.0, input_rate_dph=10.0))
    with pytest.raises(RecordingError, match=r"row 2000: .*; the rows repeat earlier ones"):
        validate(repeated)
