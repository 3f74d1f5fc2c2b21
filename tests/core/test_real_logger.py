"""The real PAN cold-test recording: 25 bursts of 5 s every 300 s, ms time, 50 Hz.

The reality check of the time axis: its bursts are segments, a warm-up is seconds
from power-on, windows stay inside a burst, and the gap modes differ visibly.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.compensate import Compensator
from hrgtc.core.errors import CalibrationError
from hrgtc.core.timeline import Timeline
from hrgtc.drift.features import FeatureSettings, parse_terms
from hrgtc.drift.windows import Windowing, window_means
from hrgtc.model import load_model
from hrgtc.recording import ReadOptions

PAN = Path(__file__).resolve().parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
COLUMNS = {"time_s": "time (ms)", "temperature_c": "temp", "rate_dph_x": "gyrox rad/s",
           "rate_dph_y": "gyroy rad/s", "rate_dph_z": "gyroz rad/s"}
ARGS = ["--time-unit", "ms", "--thermometer", "sensor", "--rate-unit", "radps",
        "--col", ",".join(f"{k}={v}" for k, v in COLUMNS.items()),
        "--temp-scale", "0.00587", "--temp-offset", "24.28", "--spikes", "drop"]
runner = CliRunner()


def options(**more) -> ReadOptions:
    return ReadOptions(columns=COLUMNS, units={"time": "ms", "rate": "radps"},
                       thermometer="sensor", temp_scale=0.00587, temp_offset_c=24.28,
                       spikes="drop", axis="x", **more)


def test_info_header_gives_span_recorded_duration_and_25_segments():
    result = runner.invoke(app, ["info", str(PAN), *ARGS, "--gaps", "bridge", "--json"])
    assert result.exit_code == 0, result.stderr
    timeline = json.loads(result.stdout)["timeline"]
    assert timeline["segments"] == 25
    assert timeline["recorded_s"] == pytest.approx(125.0)
    assert timeline["burst_length_s"] == pytest.approx(5.0)
    assert timeline["burst_period_s"] == pytest.approx(305.0, abs=0.1)
    assert timeline["bursty"] is True
    text = runner.invoke(app, ["info", str(PAN), *ARGS, "--gaps", "bridge"]).stdout
    assert "recorded 125 s" in " ".join(text.split()) and "25 segment(s)" in text


def test_the_bursts_are_segments_and_the_warm_up_is_seconds_from_power_on():
    run = options(gaps="bridge").read(PAN)
    line = Timeline.from_time(run.time_s, 1.0 / run.sample_rate_hz)
    assert line.n_segments == 25 and line.samples_per_segment.tolist() == [250] * 25
    settings = FeatureSettings(reference_freq_hz=20.0, sample_rate_hz=50.0, rate_tau_s=1.0,
                               warmup_s=3.0)  # shorter than the first burst's 5 s
    windows = window_means([run], settings, parse_terms(["f", "df"]), Windowing(4.0))
    # the warm-up drops 3 s of the first burst (150 samples), nothing of the other 24; the
    # 1 s remainders of 24 bursts are under half a window: dropped and counted
    assert windows.dropped == {"warmup": 150, "partial_windows": 24 * 50}
    assert windows.segments == 25
    # 4 s windows in 5 s bursts: one full window per burst; the first burst's 2 s after the
    # warm-up are half a window: kept
    assert windows.time_s.size == 1 + 24
    # no window mean mixes two bursts: each centre lies inside a burst
    inside = [np.any((run.time_s.min() <= c) & (np.abs(line.start_s - c) < 5.0)) for c in
              windows.time_s]
    assert all(inside)


def test_split_restarts_the_filter_per_burst_and_says_so_bridge_carries_on():
    run = options(gaps="split").read(PAN)
    settings = FeatureSettings(reference_freq_hz=20.0, sample_rate_hz=50.0, rate_tau_s=10.0,
                               warmup_s=50.0)
    with pytest.raises(CalibrationError, match=r"after every gap .*--gaps bridge"):
        window_means([run], settings, parse_terms(["f", "df"]), Windowing(10.0, gaps="split"))
    bridged = window_means([run], settings, parse_terms(["f", "df"]),
                           Windowing(10.0, gaps="bridge"))
    assert bridged.dropped["warmup"] == 250  # the first burst (15 s to 20 s) only
    assert bridged.time_s.size == 24


def test_evaluate_split_on_a_burst_file_refuses_instead_of_settling_figures(tmp_path):
    model = tmp_path / "pan.json"
    result = runner.invoke(app, ["calibrate", "--drift", str(PAN), *ARGS, "--gaps", "bridge",
                                 "--terms", "f", "--warmup-s", "50", "-o", str(model)])
    assert result.exit_code == 0, result.stderr
    split = runner.invoke(app, ["evaluate", str(PAN), "--model", str(model), *ARGS,
                                "--gaps", "split", "--json"])
    assert split.exit_code == 2
    assert "--gaps bridge" in " ".join(split.stderr.split())
    bridge = runner.invoke(app, ["evaluate", str(PAN), "--model", str(model), *ARGS,
                                 "--gaps", "bridge", "--json"])
    assert bridge.exit_code == 0, bridge.stderr


def test_holdout_trains_on_the_first_bursts_and_validates_on_the_last(tmp_path):
    model = tmp_path / "held.json"
    result = runner.invoke(app, ["calibrate", "--drift", str(PAN), *ARGS, "--gaps", "bridge",
                                 "--holdout-fraction", "0.25", "--window-s", "5", "--json",
                                 "--warmup-s", "50", "-o", str(model)])
    assert result.exit_code == 0, result.stderr
    document, _ = json.JSONDecoder().raw_decode(result.stdout)
    for entry in document["axes"].values():
        (held,) = entry["validation"]
        assert held["n_samples"] == 6 * 250  # the last quarter: 6 whole bursts of 25
        # trained on the first 19 bursts, the first inside the 50 s warm-up: 18 windows of 5 s
        assert entry["drift"]["n_windows"] == 18
    both = runner.invoke(app, ["calibrate", "--drift", str(PAN), "--drift", str(PAN), *ARGS,
                               "--gaps", "bridge", "--holdout-s", "30", "-o", str(model),
                               "--force"])
    assert both.exit_code == 2 and "exactly one --drift" in " ".join(both.stderr.split())


def test_compensate_flags_the_first_warmup_seconds_not_samples_on_a_burst_file(tmp_path):
    """The compensator's own settling is seconds on the time axis (issue 20 item 1): with
    ``--gaps bridge`` the 50 s warm-up (5 × tau 10 s) flags the samples within 50 s of the
    first one: the first burst (15 s to 20 s, 250 samples of 6250) -- as training skips
    them -- not 50 s × 50 Hz = 2,500 samples (40 % of the file, ten bursts)."""
    model = tmp_path / "pan.json"
    result = runner.invoke(app, ["calibrate", "--drift", str(PAN), *ARGS, "--gaps", "bridge",
                                 "--terms", "f", "--warmup-s", "50", "-o", str(model)])
    assert result.exit_code == 0, result.stderr
    run = options(gaps="bridge").read(PAN)
    by_hand = int(np.count_nonzero(run.time_s - run.time_s[0] < 50.0))
    assert by_hand == 250
    out = runner.invoke(app, ["compensate", str(PAN), "--model", str(model), *ARGS,
                              "--gaps", "bridge", "--json", "-o", str(tmp_path / "c.parquet")])
    assert out.exit_code == 0, out.stderr
    document, _ = json.JSONDecoder().raw_decode(out.stdout[out.stdout.index("{"):])
    assert document["ranges"]["settling_fraction"] == pytest.approx(by_hand / 6250)
    # compensate's accounting (item 7): flagged by reason, never dropped
    accounting = document["accounting"]
    assert accounting["read"] == accounting["used"] == 6250 and accounting["dropped"] == {}
    flagged = accounting["flagged"]
    assert flagged["warmup"] == by_hand and flagged["spikes"] == 3  # the three known spikes
    # its own training file: nothing beyond the trained ranges (issue 20), the settling
    # samples counted as warm-up only
    assert document["out_of_range_fraction"] == document["rate_out_of_range_fraction"] == 0.0
    assert "out_of_range" not in flagged and "rate_out_of_range" not in flagged, flagged
    lines = PAN.read_text().splitlines(keepends=True)  # rows 100-109 sent twice
    doubled = tmp_path / "doubled.csv"
    doubled.write_text("".join(lines[:111] + lines[101:111] + lines[111:]))
    again = runner.invoke(app, ["compensate", str(doubled), "--model", str(model), *ARGS,
                                "--gaps", "bridge", "--json", "-o", str(tmp_path / "d.parquet")])
    assert again.exit_code == 0, again.stderr
    counted, _ = json.JSONDecoder().raw_decode(again.stdout[again.stdout.index("{"):])
    assert counted["accounting"]["read"] == 6260 and counted["rows"] == 6250
    assert counted["accounting"]["dropped"] == {"duplicates": 10}
    text = runner.invoke(app, ["compensate", str(PAN), "--model", str(model), *ARGS, "--gaps",
                               "bridge", "-o", str(tmp_path / "t.parquet")]).stdout
    assert "samples: 6250 read, 6250 used, flagged 250 warm-up" in " ".join(text.split())
    unit = load_model(model).of_axis("x")
    for engine in ("fused", "numpy"):  # the kernel and the numpy reference agree
        compensator = Compensator(unit, engine=engine, gaps="bridge")
        flags = compensator.transform(run)["in_range"]
        assert compensator.axis.settling == by_hand, engine
        assert not flags[:by_hand].any()
