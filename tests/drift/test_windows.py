"""Tests of hrgtc.drift.windows: each training run has its own df/dt filter (issue 21 item 8)."""

from __future__ import annotations

import numpy as np

from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.windows import window_means
from hrgtc.recording import Recording

from synthetic import ramp_run


def test_each_run_starts_its_own_filter_even_with_a_short_warm_up():
    # Two runs recorded one after the other (the second's clock continues the first's) at
    # different temperatures, and a warm-up of one sample: were the filter state shared,
    # the second run's first windows would read the 40 degC jump between the runs as a
    # rate. Each run's windows must equal those of the run trained alone.
    first = ramp_run(seed=1, start_c=20.0, end_c=-20.0, hours=1.0)
    second = ramp_run(seed=2, start_c=20.0, end_c=-20.0, hours=1.0)
    second = second.with_columns(time_s=second.time_s + first.time_s[-1] + 0.1)
    settings = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, rate_tau_s=5.0,
                               warmup_s=0.1)
    terms = parse_terms(["f", "df"])
    both = window_means([first, second], settings, terms, window_s=10.0)
    alone = window_means([second], settings, terms, window_s=10.0)
    mine = both.run == 1
    np.testing.assert_array_equal(both.variables["df"][mine], alone.variables["df"])
    np.testing.assert_array_equal(both.terms[mine], alone.terms)
    # the test has power: one filter over both runs (shared state) reads the jump
    joined = Recording({n: np.concatenate([first[n], second[n]]) for n in first.names},
                       first.metadata, "joined")
    shared = window_means([joined], settings, terms, window_s=10.0)
    leaked = shared.variables["df"][np.searchsorted(shared.time_s, second.time_s[0])]
    assert abs(leaked - alone.variables["df"][0]) > 10 * np.std(alone.variables["df"][-20:])
