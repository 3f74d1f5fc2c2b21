"""Tests of hrgtc.evaluation and the compensate / evaluate / demo commands."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc import load_model, recording
from hrgtc.cli import app
from hrgtc.evaluation import evaluate
from hrgtc.evaluation.metrics import bias_stability
from hrgtc.model import save_model
from hrgtc.pipeline.calibration import calibrate
from hrgtc.settings.compensation import EvaluationSettings


@pytest.fixture(scope="module")
def setup(tmp_path_factory, paper_campaign):
    folder = tmp_path_factory.mktemp("evaluation")
    files = paper_campaign
    model = calibrate(files.soaks, [files.cooldown]).model
    model_path = save_model(model, folder / "unit.json")
    return files, model, model_path


def test_evaluation_against_metrics_by_hand(setup):
    files, model, _ = setup
    result = evaluate(model, files.warmup).axis
    run = recording.read(files.warmup)
    raw = run.rate_dph - run.metadata.input_rate_dph
    settle = round(model.drift.settings.warmup_s * run.sample_rate_hz)  # left out, as in training
    rate_free = not any(v in t for t in model.drift.selected for v in ("df", "dh", "d2"))
    assert (settle == 0) == rate_free  # no rate term: no filter warm-up to leave out
    assert result.ranges.settling_fraction == pytest.approx(settle / len(run))
    assert result.raw_10s == pytest.approx(
        bias_stability(raw[settle:], run.sample_rate_hz, 10.0), rel=1e-12)
    predicted = model.drift.predict_recording(run, model.thermometer)
    assert result.compensated_10s == pytest.approx(
        bias_stability((raw - predicted)[settle:], run.sample_rate_hz, 10.0), rel=1e-12)
    truth = np.sqrt(np.mean((run["bias_dph"] - predicted) ** 2))
    assert result.residual_rms_dph == pytest.approx(truth, rel=1e-12)
    assert result.improvement_10s == pytest.approx(result.raw_10s / result.compensated_10s)
    assert set(result.bias_stability_dph) == {"raw", "compensated", "housing"}


def test_figures_carry_the_runs_numbers_with_units_and_intervals(setup):
    """The structured summary holds the same bias stabilities, intervals and levels as
    the result's fields, and its text carries them."""
    files, model, _ = setup
    result = evaluate(model, files.warmup).axis
    figures = result.figures()
    for series, row in result.bias_stability_dph.items():
        for tau_s, value in row.items():
            figure = figures[f"evaluation.bias_stability_dph.{series}.{tau_s:g}"]
            assert (figure.unit, figure.interval) == (
                "°/h", result.stability_interval(series, tau_s))
            assert figure.value == value or (math.isnan(figure.value) and math.isnan(value))
        assert figures[f"evaluation.rms_dph.{series}"].value == result.rms_dph[series]
    assert figures["evaluation.residual_rms_dph"].value == result.residual_rms_dph
    assert f"improvement at 10 s: {result.improvement_10s:.3g} ×" in figures.text()


def test_evaluate_command_json_layout(setup):
    files, _, model_path = setup
    result = CliRunner().invoke(app, ["evaluate", str(files.warmup), "--model", str(model_path),
                                      "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    for name in ("raw", "compensated", "housing"):
        assert set(data["bias_stability_dph"][name]) == {"1", "10", "100"}
    assert data["improvement_10s"] > 1.0
    assert 0.0 <= data["out_of_range_fraction"] <= 1.0
    assert set(data["allan"]["raw"]) >= {"arw_deg_per_rt_h", "bias_instability_dph"}
    text = CliRunner().invoke(app, ["evaluate", str(files.warmup), "--model", str(model_path)])
    assert text.exit_code == 0 and "3.0143 → 0.5848" in text.stdout


def test_compensate_command_file_to_file(setup, tmp_path):
    files, model, model_path = setup
    out = tmp_path / "comp.h5"
    args = ["compensate", str(files.warmup), "--model", str(model_path), "-o", str(out), "--json"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["rows"] == len(recording.read(files.warmup))
    written = recording.read(out)
    run = recording.read(files.warmup)
    np.testing.assert_array_equal(written["bias_model_dph"], model.drift.predict_recording(
        run, model.thermometer))
    np.testing.assert_array_equal(written["rate_comp_dph"],
                                  run.rate_dph - written["bias_model_dph"])
    assert set(np.unique(written["in_range"])) <= {0.0, 1.0}
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 2 and "--force" in again.output
    assert load_model(model_path).drift.selected == model.drift.selected


def test_demo_quick_end_to_end(tmp_path):
    result = CliRunner().invoke(app, ["demo", "--quick", "-o", str(tmp_path / "demo"), "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    # the unit's Table 2: every soak read back within 0.02 °C
    assert max(abs(r["error_c"]) for r in data["calibration"]["thermometer"]["table"]) < 0.02
    # the cool-down the paper shows: ~3 °/h raw (3.0143 in [1]) and much better compensated
    training = data["training"]["bias_stability_dph"]
    assert 2.5 < training["raw"]["10"] < 3.5
    assert training["compensated"]["10"] < 0.8
    for key in ("model_file", "report_file"):
        assert (tmp_path / "demo" / data[key].split("/")[-1]).exists()
    assert len(data["c_files"]) == 2
    # the unit with a thermal memory: on its held-out cycle the history model is closer to
    # the true bias than today's, heating and cooling alike (the figures: test_demo_figures)
    history = data["history"]
    assert history["kept"] and "play" in history["terms_with_history"]
    for direction in ("heating", "cooling"):
        figures = history["figures"][direction]
        assert figures["with_residual"] < figures["without_residual"], direction
    assert (tmp_path / "demo" / "unit-play" / "report.html").exists()
    again = CliRunner().invoke(app, ["demo", "--quick", "-o", str(tmp_path / "demo")])
    assert again.exit_code == 2 and "--force" in again.output


@pytest.mark.parametrize("command", ["evaluate", "compensate"])
def test_range_warnings_in_plain_output_and_strict_exit(setup, tmp_path, command):
    """A warm-up beyond the cool-down model's df/dt: the plain output says so; --strict exits 3."""
    files, _, model_path = setup
    args = [command, str(files.warmup), "--model", str(model_path)]
    if command == "compensate":
        args += ["-o", str(tmp_path / "out.parquet")]
    plain = CliRunner().invoke(app, args)
    assert plain.exit_code == 0, plain.output
    text = " ".join(plain.stdout.split())
    assert "beyond the trained df/dt" in text and "× the largest trained" in text
    if command == "evaluate":  # heating and cooling apart, in the plain output too
        assert "heating and cooling apart" in text and "compensated" in text
    strict = CliRunner().invoke(app, [*args, "--strict", "--force"] if command == "compensate"
                                else [*args, "--strict"])
    assert strict.exit_code == 3, strict.output


def test_evaluation_ranges_cover_temperature_and_df_dt(setup):
    files, model, _ = setup
    result = evaluate(model, files.warmup, settings=EvaluationSettings(allan=False)).axis
    data = result.to_dict()["ranges"]
    assert data["rate_fraction"] == pytest.approx(result.rate_out_of_range_fraction)
    assert data["rate_fraction"] > 0.0 and data["rate_excess_ratio"] > 1.0
    assert data["seen_rate_c_per_h"][1] > 0.0 >= data["trained_rate_c_per_h"][0]
    assert any("df/dt" in line for line in result.summary().text().splitlines())


def test_intervals_deviation_kinds_and_allan_csv(setup, tmp_path):
    files, model, model_path = setup
    result = evaluate(model, files.warmup, max_points=500).axis
    for series in ("raw", "compensated"):
        value = result.stability(series, 10.0)
        low, high = result.stability_interval(series, 10.0)
        assert low < value < high
        curve = result.allan[series]
        assert np.all(curve.lower < curve.deviation) and np.all(curve.deviation < curve.upper)
    std = result.prediction_std_dph
    assert 0.0 < std["median"] <= std["max"]
    assert std["median"] < result.compensated_10s * 10.0
    assert result.blocks["model_std_dph"].size == result.blocks["model_dph"].size

    csv_path = tmp_path / "allan.csv"
    out = CliRunner().invoke(app, ["evaluate", str(files.warmup), "--model", str(model_path),
                                   "--json", "--deviation", "mdev", "--allan-csv",
                                   str(csv_path)])
    assert out.exit_code == 0, out.output
    data = json.loads(out.stdout)
    assert data["deviation"] == "mdev" and data["allan"] == {}
    curve = data["allan_curve"]["raw"]  # mdev with Greenhall's edf (SP 1065 Section 5.3.3)
    assert all(low < dev < high for low, dev, high in
               zip(curve["lower"], curve["deviation"], curve["upper"], strict=True)
               if low is not None)
    assert curve["lower"][0] is not None
    low, high = data["bias_stability_interval_dph"]["raw"]["10"]
    assert low < data["bias_stability_dph"]["raw"]["10"] < high
    assert data["prediction_std_dph"]["max"] >= data["prediction_std_dph"]["median"] > 0.0
    rows = csv_path.read_text().splitlines()
    assert rows[0] == "series,tau_s,deviation,lower,upper,n,edf"
    raw_rows = [r.split(",") for r in rows[1:] if r.startswith("raw,")]
    assert [float(r[2]) for r in raw_rows] == pytest.approx(
        list(np.asarray(data["allan_curve"]["raw"]["deviation"], dtype=float)))
    again = CliRunner().invoke(app, ["evaluate", str(files.warmup), "--model", str(model_path),
                                     "--allan-csv", str(csv_path)])
    assert again.exit_code != 0 and "--force" in again.output
    oadev = CliRunner().invoke(app, ["evaluate", str(files.warmup), "--model", str(model_path),
                                     "--allan-csv", str(csv_path), "--force"])
    assert oadev.exit_code == 0, oadev.output
    assert "] (68.3% CI, N " in oadev.stdout  # "[0.93, 0.99] (68.3% CI, N 1795)"
    first = csv_path.read_text().splitlines()[1].split(",")
    assert float(first[3]) < float(first[2]) < float(first[4])
    bad = CliRunner().invoke(app, ["evaluate", str(files.warmup), "--model", str(model_path),
                                   "--deviation", "xdev"])
    assert bad.exit_code == 2


def test_allan_csv_carries_the_pooled_edf_behind_its_intervals(setup):
    """``--allan-csv`` has an ``edf`` column: on bursts (segments of 400 samples every 1000)
    the pooled edf of the segments (Satterthwaite over SP 1065 Table 5), and the interval of
    each row is the chi-squared interval of that many degrees of freedom."""
    from scipy.stats import chi2

    from hrgtc.evaluation.allan_segments import pooled_edf
    from hrgtc.evaluation.metrics import ONE_SIGMA
    from hrgtc.recording import Recording

    files, model, _ = setup
    run = recording.read(files.warmup)
    keep = np.arange(len(run)) % 1000 < 400
    bursts = Recording({k: run[k][keep] for k in run.columns}, run.metadata, source="bursts")
    result = evaluate(model, bursts, max_points=500).axis
    header, *rows = result.allan_csv().splitlines()
    assert header == "series,tau_s,deviation,lower,upper,n,edf"
    table = [r.split(",") for r in rows if r.startswith("compensated,")]
    curve = result.allan["compensated"]
    assert curve.segments > 1 and len(table) == curve.taus_s.size
    # the segments as the evaluation feeds them: bursts less the df/dt filter's settling
    fs = run.metadata.sample_rate_hz
    settled = bursts.time_s - bursts.time_s[0] >= model.drift.settings.warmup_s
    burst = np.flatnonzero(keep) // 1000
    lengths = [int(np.count_nonzero(settled & (burst == b))) for b in np.unique(burst)]
    lengths = [n for n in lengths if n]
    alpha = 1.0 - ONE_SIGMA
    for row, tau in zip(table, curve.taus_s, strict=True):
        dev, low, high, edf = float(row[2]), float(row[3]), float(row[4]), float(row[6])
        assert edf == pytest.approx(pooled_edf("allan", lengths, round(tau * fs)), rel=1e-12)
        assert low == pytest.approx(dev * math.sqrt(edf / chi2.ppf(1 - alpha / 2, edf)), rel=1e-9)
        assert high == pytest.approx(dev * math.sqrt(edf / chi2.ppf(alpha / 2, edf)), rel=1e-9)
