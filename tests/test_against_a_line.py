"""hrgtc against a plain per-axis line of rate on temperature, held out (issue 20, Done when).

On burst recordings, trained on the first 60 % of the time and validated on the rest,
the compensated 10 s bias stability must lie within the statistical interval of a
plain least-squares line ``a + b·T`` fitted on the same training samples where the
truth is linear, below it where the truth is not, and never above raw.

The line is computed here with numpy alone, on the same held-out part, as the spread
(ddof 1) of the held-out burst means after the df/dt filter's warm-up, the figure the
evaluation gives for 5 s bursts at τ = 10 s (the raw figure is checked equal to the
evaluation's first, so both figures come from the same samples). Its interval is the
χ² one of a standard deviation of N burst means (N − 1 degrees of freedom, 68.3 %).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from bursts import cut_bursts
from hrgtc import drift
from hrgtc.cli import app
from hrgtc.evaluation import evaluate
from hrgtc.evaluation.metrics import bias_stability_interval
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Metadata, Recording
from hrgtc.settings.compensation import BIAS_ONLY
from hrgtc.thermometry import identity

THERMOMETER = identity((-20.0, 50.0))
TRAINED = 0.6  # share of the time trained on; the rest is held out


def _burst_means(time_s: np.ndarray, values: np.ndarray, from_s: float) -> np.ndarray:
    """Mean of each burst (a step over 1 s starts one) that starts at ``from_s`` or later."""
    burst = np.r_[0, np.cumsum(np.diff(time_s) > 1.0)]
    means = np.bincount(burst, values) / np.bincount(burst)
    starts = time_s[np.r_[0, np.flatnonzero(np.diff(burst)) + 1]]
    return means[starts >= from_s]


def _line_figure(train_t, train_rate, held_time, held_t, held_rate, from_s):
    """Held-out burst-mean spread of the residual of a line fitted on the training part,
    and N. [°/h]"""
    slope, intercept = np.polyfit(train_t, train_rate, 1)
    means = _burst_means(held_time, held_rate - (intercept + slope * held_t), from_s)
    return float(np.std(means, ddof=1)), means.size


def simulated_bursts(seed: int, curve: float, hours: float = 4.0,
                     walk: float = 0.03) -> Recording:
    """A MEMS axis at rest cooling 25 -> 5 °C (cosine ramp), its sensor as thermometer, at
    10 Hz, cut to 5 s bursts every 60 s. Bias [°/h] = 14400 + 36 (T − 15) + curve (T − 15)²,
    white noise of 60 °/h per sample and a random walk of ``walk`` °/h per sample (0.03:
    its slow noise is ±11 °/h over the 4 h)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 0.1)
    temperature = 25.0 - 20.0 * (1.0 - np.cos(np.pi * t / t[-1])) / 2.0
    bias = 14400.0 + 36.0 * (temperature - 15.0) + curve * (temperature - 15.0) ** 2
    rate = bias + 60.0 * rng.standard_normal(t.size) + np.cumsum(walk * rng.standard_normal(t.size))
    run = Recording({"time_s": t, "freq_hz": temperature, "rate_dph": rate, "bias_dph": bias},
                    Metadata(sample_rate_hz=10.0, unit="mems"), source=f"bursts-{seed}")
    return cut_bursts(run, 5.0, 60.0)


def _part(run: Recording, keep: np.ndarray, name: str) -> Recording:
    return Recording({n: run[n][keep] for n in run.names}, run.metadata, source=name)


def _held_out(seed: int, curve: float, walk: float = 0.03) -> dict[str, float]:
    run = simulated_bursts(seed, curve, walk=walk)
    t = run.time_s
    cut = t[0] + TRAINED * (t[-1] - t[0])
    train, held = _part(run, t < cut, "train"), _part(run, t >= cut, "held")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # beyond the trained temperatures, by design
        model = drift.fit([train], THERMOMETER)
        fitted = Model.single(AxisModel(thermometer=THERMOMETER, drift=model), unit="mems")
        figures = evaluate(fitted, held, settings=BIAS_ONLY).axis
    from_s = held.time_s[0] + model.settings.warmup_s
    raw = _burst_means(held.time_s, held.rate_dph, from_s)
    assert np.std(raw, ddof=1) == pytest.approx(figures.raw_10s, rel=1e-9)  # the same part
    line, n = _line_figure(train["freq_hz"], train.rate_dph, held.time_s, held["freq_hz"],
                           held.rate_dph, from_s)
    return {"raw": figures.raw_10s, "hrgtc": figures.compensated_10s, "line": line, "n": n,
            "terms": model.selected}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_simulated_bursts_with_a_linear_truth_are_within_the_interval_of_a_line(seed):
    found = _held_out(seed, curve=0.0)
    low, high = bias_stability_interval(found["line"], found["n"])
    assert low <= found["hrgtc"] <= high, found
    assert found["hrgtc"] <= found["raw"], found


@pytest.mark.parametrize(("walk", "seed"), [(0.1, 4), (0.1, 5), (0.3, 4), (0.3, 5), (0.3, 12)])
def test_a_random_walk_that_looks_like_curvature_does_not_beat_the_line(walk, seed):
    # a random walk of ±40 °/h (0.1 per sample) or ±110 °/h (0.3) over the 4 h: on these
    # seeds the F-tests and the extreme blocks took it for f², f³ or df-powers, which then
    # ran away beyond the trained temperatures (1.2x-2.2x the line held out); their gain
    # on the extreme blocks does not beat the slow noise of the training residual
    # (bench/bench_selection.py has the 12-seed study)
    found = _held_out(seed, curve=0.0, walk=walk)
    _, high = bias_stability_interval(found["line"], found["n"])
    assert found["hrgtc"] <= high, found
    assert found["hrgtc"] <= found["raw"], found


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_simulated_bursts_with_a_curved_truth_are_better_than_a_line(seed):
    found = _held_out(seed, curve=0.5)
    low, _ = bias_stability_interval(found["line"], found["n"])
    # a term beyond the line is kept: f² (seeds 1, 2), or df, which the cosine ramp makes
    # follow the curvature as well (seed 3: f, df; held out 2.0x better than the line)
    assert set(found["terms"]) - {"f"}, found
    assert found["hrgtc"] < low, found  # below the line's whole interval
    assert found["hrgtc"] <= found["raw"], found


# ---------------------------------------------------------------- the real cold test
DATA = Path(__file__).parent / "data" / "pan-cold-test"
RUN = DATA / "pan_tvc_cold_2020-03-07.csv"
LOG = DATA / "pan_etu_cold_handlog_2020-03-07.csv"
#: Single-sample spikes of the x gyro (rows of the file; see tests/cli/test_sensors_end_to_end.py).
SPIKES = [2340, 2570, 3223]
DPH_PER_RADPS = 180.0 / np.pi * 3600.0
#: The evaluation leaves out the df/dt filter's warm-up, 5 × the default 10 s time constant,
#: where the model has a rate term.
WARMUP_S = 50.0


@pytest.mark.slow
def test_cold_test_held_out_is_within_the_interval_of_a_line_and_never_worse_than_raw(tmp_path):
    """The PAN cold test, trained on its first 60 %, validated on the colder 40 % (all of it
    below the trained temperatures): every axis no worse than raw, and within the χ²
    interval of a numpy line fitted on the same training samples (x: the line is what
    generalises; y: f and df do better than the line, z: nothing to compensate)."""
    result = CliRunner().invoke(app, [
        "calibrate", "--drift", str(RUN), "--thermometer", "sensor", "--gaps", "bridge",
        "--time-unit", "ms", "--rate-unit", "radps",
        "--col", "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
        "rate_dph_z=gyroz rad/s,temperature_c=temp",
        "--temp-ref", str(LOG), "--temp-ref-col", "time_s=Time,temperature_c=C1 (C)",
        "--temp-ref-start", "15:45", "--holdout-fraction", "0.4",
        "-o", str(tmp_path / "pan.json"), "--json"])
    assert result.exit_code == 0, result.output
    document = json.loads(result.stdout[result.stdout.index("{"):])
    # the file with numpy alone: a line in the raw count is a line in °C
    table = np.genfromtxt(RUN, delimiter=",", names=True, encoding="utf-8-sig")
    time_s = table["time_ms"] / 1000.0
    count = np.where(table["temp"] > 32767, table["temp"] - 65536.0, table["temp"])
    cut = round(TRAINED * time_s.size)  # a burst's start: the held-out part's first row
    assert time_s[cut] - time_s[cut - 1] > 1.0
    train = np.ones(time_s.size, dtype=bool)
    train[cut:] = False
    train[SPIKES] = False
    held = slice(cut, None)
    found = {}
    model = json.loads((tmp_path / "pan.json").read_text())
    for axis in "xyz":
        rate = table[f"gyro{axis}_rads"] * DPH_PER_RADPS
        figures = document["axes"][axis]["validation"][0]["bias_stability_10s_dph"]
        # the warm-up is left out where the model has a rate term (none to wait for else)
        warmup_s = model["axes"][axis]["drift"]["settings"]["warmup_s"]
        assert warmup_s in (0.0, WARMUP_S)
        from_s = time_s[cut] + warmup_s
        raw = _burst_means(time_s[held], rate[held], from_s)
        assert np.std(raw, ddof=1) == pytest.approx(figures["raw"], rel=1e-6)  # the same part
        line, n = _line_figure(count[train], rate[train], time_s[held], count[held], rate[held],
                               from_s)
        low, high = bias_stability_interval(line, n)
        found[axis] = (figures["compensated"], line, n)
        # the accounting starts from the file's rows (issue 27): the trained and the held-out
        # part read every row of the file between them, and drop its three spikes
        trained_rows = document["axes"][axis]["drift"]["accounting"]
        held_rows = document["axes"][axis]["validation"][0]["accounting"]
        assert trained_rows["read"] + held_rows["read"] == time_s.size
        assert trained_rows["dropped"].get("spikes", 0) == sum(r < cut for r in SPIKES)
        assert held_rows["dropped"].get("spikes", 0) == sum(r >= cut for r in SPIKES)
        assert figures["compensated"] <= figures["raw"] * (1.0 + 1e-9), (axis, figures)
        if axis == "y":  # the df/dt term earns its place: better than the whole interval
            assert figures["compensated"] < low, (axis, figures, line, n)
        else:  # x: the line is what generalises (f² fitted on 13 windows did not); z: flat
            assert low <= figures["compensated"] <= high, (axis, figures, line, n)
    # what the docs quote (docs/real-loggers/motion.md), the line's N = 9 held-out bursts
    assert {a: round(v[0], 1) for a, v in found.items()} == {"x": 20.2, "y": 7.7, "z": 28.9}
