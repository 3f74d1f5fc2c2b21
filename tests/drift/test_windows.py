"""Tests of hrgtc.drift.windows: each training run has its own df/dt filter (issue 21 item 8)."""

from __future__ import annotations

import numpy as np
import pytest

from hrgtc.core.timeline import min_partial_rows
from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.windows import Windowing, window_means
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
    both = window_means([first, second], settings, terms, Windowing(10.0))
    alone = window_means([second], settings, terms, Windowing(10.0))
    mine = both.run == 1
    np.testing.assert_array_equal(both.variables["df"][mine], alone.variables["df"])
    np.testing.assert_array_equal(both.terms[mine], alone.terms)
    # the test has power: one filter over both runs (shared state) reads the jump
    joined = Recording({n: np.concatenate([first[n], second[n]]) for n in first.names},
                       first.metadata, "joined")
    shared = window_means([joined], settings, terms, Windowing(10.0))
    leaked = shared.variables["df"][np.searchsorted(shared.time_s, second.time_s[0])]
    assert abs(leaked - alone.variables["df"][0]) > 10 * np.std(alone.variables["df"][-20:])


def _reference_window_means(rows, chunks, flush=False):
    """Window means one segment at a time, the plain way (the definition); ``flush``: the
    run ends after the chunks (its last partial window kept when long enough)."""
    min_rows = min(rows, min_partial_rows(rows))
    out, carry, dropped = [], None, 0
    for block, breaks, cuts in chunks:
        marks = {int(b): "break" for b in breaks}
        marks.update({int(c): "cut" for c in cuts if int(c) not in marks})
        edges = [0, *sorted(m for m in marks if m > 0), block.shape[0]]
        for k in range(len(edges) - 1):
            kind = marks.get(edges[k])
            if kind == "break" and carry is not None and carry.shape[0]:
                if carry.shape[0] >= min_rows:
                    out.append(carry.mean(axis=0))
                else:
                    dropped += carry.shape[0]
                carry = None
            elif kind == "cut" and carry is not None:
                dropped += carry.shape[0]
                carry = None
            part = block[edges[k]:edges[k + 1]]
            if carry is not None:
                part = np.concatenate([carry, part])
            complete = part.shape[0] // rows
            if complete:
                out.extend(part[: complete * rows].reshape(complete, rows, -1).mean(axis=1))
            carry = part[complete * rows:]
    if flush and carry is not None and carry.shape[0]:
        if carry.shape[0] >= min_rows:
            out.append(carry.mean(axis=0))
        else:
            dropped += carry.shape[0]
    return np.array(out), dropped


def _check_against_the_definition(rows, chunks):
    from hrgtc.drift.windows import _WindowMeans

    means = _WindowMeans(rows)
    got = [means.transform(block, breaks, cuts) for block, breaks, cuts in chunks]
    got = [g for g in got if g.shape[0]]
    got = np.concatenate(got) if got else np.empty((0, 3))
    expected, dropped = _reference_window_means(rows, chunks)
    assert got.shape[0] == expected.shape[0]
    if expected.size:
        np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-9)
    assert means.partial_dropped_rows == dropped
    # and the end of the run: the last segment's partial window
    tail = means.flush()
    expected, dropped = _reference_window_means(rows, chunks, flush=True)
    assert got.shape[0] + tail.shape[0] == expected.shape[0]
    if tail.shape[0]:
        np.testing.assert_allclose(tail, expected[-1:], rtol=1e-12, atol=1e-9)
    assert means.partial_dropped_rows == dropped


@pytest.mark.parametrize("seed", range(6))
def test_window_means_of_many_segments_equal_the_plain_definition(seed):
    """Thousands of short segments per chunk (a burst file) are averaged all at once; the
    windows, the partial windows kept at breaks and the rows dropped are those of taking
    one segment at a time."""
    rng = np.random.default_rng(seed)
    rows = int(rng.integers(3, 40))
    chunks = []
    for _ in range(int(rng.integers(1, 5))):
        n = int(rng.integers(1, 3000))
        block = rng.normal(size=(n, 3)) + rng.normal(size=3) * 100.0
        marks = np.unique(rng.integers(0, n, size=int(rng.integers(0, n // 5 + 2))))
        is_cut = rng.random(marks.size) < 0.3
        chunks.append((block, marks[~is_cut], marks[is_cut]))
    _check_against_the_definition(rows, chunks)


@pytest.mark.parametrize("seed", range(40))
def test_window_means_across_short_chunks_equal_the_plain_definition(seed):
    """Chunks shorter than a window (a window and a segment spanning several chunks, the
    carry growing over them), empty chunks, breaks and cuts at a chunk's first row, a row
    marked both (a break), segments shorter than a window, column-major blocks (as
    window_means builds them): the plain definition still."""
    rng = np.random.default_rng(1000 + seed)
    rows = int(rng.integers(1, 12))
    chunks = []
    for _ in range(int(rng.integers(1, 30))):
        n = int(rng.integers(0, 3 * rows + 2))
        block = rng.normal(size=(n, 3)) + rng.normal(size=3) * 100.0
        if rng.random() < 0.5:
            block = np.asfortranarray(block)
        breaks = np.flatnonzero(rng.random(n) < rng.choice([0.0, 0.05, 0.3]))
        cuts = np.flatnonzero(rng.random(n) < rng.choice([0.0, 0.05, 0.3]))
        chunks.append((block, breaks, cuts))
    _check_against_the_definition(rows, chunks)


def test_window_means_of_bursts_one_window_long_each():
    """The burst bench's case: each burst exactly one window, a break at each burst, in one
    chunk and split across chunks mid-burst: every burst is one window, nothing dropped."""
    from hrgtc.drift.windows import _WindowMeans

    rows, bursts = 25, 40
    block = np.asfortranarray(np.arange(rows * bursts * 2, dtype=float).reshape(-1, 2))
    starts = np.arange(0, rows * bursts, rows)
    whole = _WindowMeans(rows)
    got = whole.transform(block, starts)
    np.testing.assert_array_equal(got, block.reshape(bursts, rows, 2).mean(axis=1))
    split = _WindowMeans(rows)
    cut = rows * 7 + 11
    parts = [split.transform(block[:cut], starts),
             split.transform(block[cut:], starts[starts >= cut] - cut)]
    np.testing.assert_allclose(np.concatenate(parts), got, rtol=1e-15)
    assert whole.flush().shape[0] == 0 and split.flush().shape[0] == 0
    assert whole.partial_dropped_rows == split.partial_dropped_rows == 0
