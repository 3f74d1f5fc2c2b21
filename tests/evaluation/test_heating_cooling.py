"""Tests of hrgtc.evaluation.heating_cooling: a run's figures split into heating and cooling."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from hrgtc import drift
from hrgtc.drift.features import FeatureStream, causal_rate
from hrgtc.evaluation import evaluate
from hrgtc.evaluation.heating_cooling import DirectionSplit
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Metadata, Recording
from hrgtc.settings.compensation import EvaluationSettings

from synthetic import THERMOMETER, law, ramp_run

FS = 5.0


def cycle_run(seed, heating_extra_dph_per_c_per_h=0.0):
    """Chamber 20 -> -20 -> 20 °C with holds; resonator a 2600 s lag; bias = law + an extra
    term while heating (the resonator warming) only."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 8 * 3600.0, 1.0 / FS)
    chamber = np.interp(t, [0, 7200, 14400, 21600, 28800], [20.0, -20.0, -20.0, 20.0, 20.0])
    a = -np.expm1(-1.0 / (2600.0 * FS))
    resonator = signal.lfilter([a], [1.0, a - 1.0], chamber, zi=[(1.0 - a) * 20.0])[0]
    rate_c_per_s = (chamber - resonator) / 2600.0
    f = THERMOMETER.frequency(resonator) - THERMOMETER.frequency(20.0)
    bias = law(f, THERMOMETER.slope_hz_per_c(resonator) * rate_c_per_s)
    bias += heating_extra_dph_per_c_per_h * np.maximum(rate_c_per_s, 0.0) * 3600.0
    return Recording(
        {"time_s": t, "freq_hz": THERMOMETER.frequency(resonator) + rng.normal(0, 0.002, t.size),
         "rate_dph": bias + rng.normal(0.0, 1.0, t.size), "resonator_c": resonator,
         "bias_dph": bias},
        Metadata(sample_rate_hz=FS, input_rate_dph=0.0), source=f"cycle-{seed}")


@pytest.fixture(scope="module")
def model():
    runs = [ramp_run(seed=31, hours=4.0, sample_rate_hz=FS),
            ramp_run(seed=32, start_c=-20.0, end_c=20.0, hours=4.0, sample_rate_hz=FS)]
    return Model.single(AxisModel(THERMOMETER, drift.fit(runs, THERMOMETER)), unit="synthetic")


def test_split_by_hand_and_by_the_resonator_temperature(model):
    run = cycle_run(seed=3, heating_extra_dph_per_c_per_h=0.8)
    result = evaluate(model, run, settings=EvaluationSettings(allan=False)).axis
    split = result.directions
    assert split is not None
    # by hand: 10 s block means after the settling, df/dt from the filter, 5 % dead band
    settle, rows = round(model.drift.settings.warmup_s * FS), round(10.0 * FS)
    df = causal_rate(run.freq_hz - model.drift.settings.reference_freq_hz,
                     model.drift.settings.rate_tau_s, FS)[0][settle:]
    comp = (run.rate_dph - model.drift.predict_recording(run))[settle:]
    n = comp.size // rows
    df_blocks = df[: n * rows].reshape(n, rows).mean(axis=1)
    comp_blocks = comp[: n * rows].reshape(n, rows).mean(axis=1)
    band = 0.05 * np.max(np.abs(df_blocks))
    heating, cooling = df_blocks > band, df_blocks < -band  # df/dT > 0 for Table 1's unit
    assert split.blocks == {"heating": int(heating.sum()), "cooling": int(cooling.sum())}
    assert split.compensated_dph["heating"] == pytest.approx(
        np.std(comp_blocks[heating], ddof=1), rel=1e-9)
    assert split.compensated_dph["cooling"] == pytest.approx(
        np.std(comp_blocks[cooling], ddof=1), rel=1e-9)
    # physical truth: blocks called heating are those where the resonator warms
    warming = np.diff(run["resonator_c"][settle:][: n * rows: rows], append=np.nan) > 0
    assert np.mean(warming[heating][:-1]) == 1.0 and np.mean(warming[cooling]) == 0.0
    # the extra bias while heating, which the model does not have, shows on heating only
    assert split.residual_rms_dph["heating"] > 3 * split.residual_rms_dph["cooling"]
    assert split.compensated_dph["heating"] > 1.5 * split.compensated_dph["cooling"]
    d = result.to_dict()["heating_cooling"]
    assert d["heating"]["blocks"] == split.blocks["heating"]
    assert d["cooling"]["compensated_dph"] == pytest.approx(split.compensated_dph["cooling"])
    assert "heating:" in result.summary().text() and "cooling:" in result.summary().text()


def test_chunking_does_not_change_the_split(model):
    run = cycle_run(seed=4)
    whole, parts = DirectionSplit(model, FS), DirectionSplit(model, FS)
    comp = run.rate_dph - model.drift.predict_recording(run)
    whole.partial_fit(run, run.rate_dph, comp)
    for start in range(0, len(run), 7777):
        stop = min(start + 7777, len(run))
        parts.partial_fit(run.slice(start, stop), run.rate_dph[start:stop], comp[start:stop])
    a, b = whole.finish(), parts.finish()
    assert a.blocks == b.blocks and a.residual_rms_dph is None
    for d in ("heating", "cooling"):
        assert a.compensated_dph[d] == pytest.approx(b.compensated_dph[d], rel=1e-12)
        assert a.raw_dph[d] > a.compensated_dph[d]  # the model removes the thermal drift


def burst_run(run, burst_s, period_s=60.0):
    """The rows of ``run`` in bursts of ``burst_s`` every ``period_s`` (a duty-cycled logger)."""
    keep = np.mod(run.time_s - run.time_s[0], period_s) < burst_s - 1e-9
    return Recording({k: run[k][keep] for k in run.columns}, run.metadata, source="bursts")


@pytest.mark.parametrize("burst_s", [5.0, 15.0])
def test_blocks_never_span_a_gap_and_match_the_burst_means_by_hand(model, burst_s):
    """5 s bursts every 60 s: one block mean per burst (the partial block kept from half a
    block less one sample); 15 s bursts: a full 10 s block and a 5 s partial one per burst.
    Before the blocks were on the time axis, a "10 s block" joined two bursts 60 s apart."""
    run = burst_run(cycle_run(seed=5), burst_s)
    comp = run.rate_dph - model.drift.predict_recording(run)
    split = DirectionSplit(model, FS)
    for start in range(0, len(run), 1234):  # chunks that cut bursts too
        stop = min(start + 1234, len(run))
        split.partial_fit(run.slice(start, stop), run.rate_dph[start:stop], comp[start:stop])
    found = split.finish()
    # by hand: df/dt from the model's causal filter over the whole file (true Δt across the
    # gaps), the settling in seconds, then each burst cut into 50-row blocks and a tail
    df = FeatureStream(model.drift.settings, ("df",)).transform(run)["df"]
    settled = run.time_s - run.time_s[0] >= model.drift.settings.warmup_s
    burst = np.floor((run.time_s - run.time_s[0]) / 60.0).astype(int)
    rows = round(10.0 * FS)
    df_means, raw_means, comp_means, partial = [], [], [], 0
    for b in np.unique(burst[settled]):
        idx = np.flatnonzero(settled & (burst == b))
        for k in range(0, idx.size, rows):
            part = idx[k:k + rows]
            if part.size < rows:
                if part.size < 24:  # half of 50 rows less one
                    continue
                partial += 1
            df_means.append(df[part].mean())
            raw_means.append(run.rate_dph[part].mean())
            comp_means.append(comp[part].mean())
    df_means, raw_means, comp_means = map(np.array, (df_means, raw_means, comp_means))
    assert partial == np.unique(burst[settled]).size  # every burst ends in a partial block
    band = 0.05 * np.max(np.abs(df_means))
    heating, cooling = df_means > band, df_means < -band
    assert found.blocks == {"heating": int(heating.sum()), "cooling": int(cooling.sum())}
    assert found.partial_blocks == partial and found.reason is None
    for name, mask in (("heating", heating), ("cooling", cooling)):
        assert found.raw_dph[name] == pytest.approx(np.std(raw_means[mask], ddof=1), rel=1e-9)
        assert found.compensated_dph[name] == pytest.approx(
            np.std(comp_means[mask], ddof=1), rel=1e-9)
    assert f"{partial} blocks cut short by a gap" in found.summary().text()


def test_no_block_is_said_once_with_the_reason(model):
    """3 s bursts (15 rows) are shorter than half a 10 s block: one line that says so, not an
    empty line per direction."""
    run = burst_run(cycle_run(seed=6), 3.0)
    comp = run.rate_dph - model.drift.predict_recording(run)
    split = DirectionSplit(model, FS)
    split.partial_fit(run, run.rate_dph, comp)
    found = split.finish()
    assert found.blocks == {"heating": 0, "cooling": 0}
    assert found.reason == "bursts of at most 3 s are shorter than half the 10 s block (4.8 s)"
    text = found.summary().text()
    assert text.count("\n") == 0 and "no 10 s block (bursts of at most 3 s" in text
    assert found.to_dict()["reason"] == found.reason


def test_a_run_shorter_than_half_a_block_after_the_settling_says_so(model):
    run = cycle_run(seed=7).slice(0, round((model.drift.settings.warmup_s + 3.0) * FS))
    split = DirectionSplit(model, FS)
    split.partial_fit(run, run.rate_dph, run.rate_dph)
    assert split.finish().reason == (
        "the settled run (3 s) is shorter than half the 10 s block (4.8 s)")
    early = DirectionSplit(model, FS)
    early.partial_fit(run.slice(0, 10), run.rate_dph[:10], run.rate_dph[:10])
    assert "past the df/dt filter's" in early.finish().reason
