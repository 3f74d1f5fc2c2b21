"""evaluate on a burst recording: every deviation pooled within bursts, N and intervals on
every figure, and the Allan deviation beyond a burst from burst means with its dead time."""

from __future__ import annotations

import json

import numpy as np
import pytest
from tests.bursts import cut_bursts
from typer.testing import CliRunner

from hrgtc import recording
from hrgtc.cli import app
from hrgtc.evaluation import evaluate
from hrgtc.evaluation.allan_segments import pooled_edf
from hrgtc.model import save_model
from hrgtc.pipeline.calibration import calibrate
from hrgtc.settings.compensation import EvaluationSettings

# a 10 s df/dt filter on 600 s bursts is warned about; not what these tests are about
pytestmark = pytest.mark.filterwarnings("ignore::hrgtc.core.errors.RateFilterWarning")


@pytest.fixture(scope="module")
def bursts(tmp_path_factory, paper_campaign):
    files = paper_campaign
    model = calibrate(files.soaks, [files.cooldown]).model
    folder = tmp_path_factory.mktemp("bursts")
    run = cut_bursts(recording.read(files.warmup), burst_s=60.0, period_s=600.0)
    path = folder / "warmup_bursts.parquet"
    recording.write(run, path)
    return run, model, save_model(model, folder / "unit.json"), path


@pytest.mark.parametrize("deviation", ["oadev", "mdev", "hdev", "tdev", "adev"])
def test_every_deviation_is_pooled_within_bursts(bursts, deviation):
    run, model, _, _ = bursts
    result = evaluate(model, run, settings=EvaluationSettings(deviation=deviation)).axis
    curve = result.allan["raw"]
    assert curve.segments > 10
    # no τ longer than a burst (120 samples at 2 Hz): no term reaches across a gap
    span = {"oadev": 2, "adev": 2, "mdev": 3, "hdev": 3, "tdev": 3}[deviation]
    assert curve.taus_s.max() * span <= 60.0
    assert curve.edf is not None and np.all(curve.lower < curve.deviation)
    kind = curve.kind
    lengths = [120] * 3  # a full burst's edf, times the bursts, bounds the pooled edf
    one = pooled_edf(kind, lengths[:1], 1, 0, curve.overlapping)
    assert curve.edf[0] <= curve.segments * one * (1 + 1e-9)
    burst = result.burst_allan["raw"]
    assert burst.period_s == pytest.approx(600.0, rel=1e-3)
    assert burst.dead_time_ratio == pytest.approx(10.0, rel=0.05)
    assert any("dead-time ratio r = " in note for note in result.notes)


def test_figures_carry_n_and_interval_in_json_and_text(bursts):
    _, _, model_path, path = bursts
    out = CliRunner().invoke(app, ["evaluate", str(path), "--model", str(model_path),
                                   "--json", "--gaps", "bridge"])
    assert out.exit_code == 0, out.output
    data = json.loads(out.stdout)
    n = data["bias_stability_n"]["raw"]
    assert n["10"] > 10 and set(n) == set(data["bias_stability_dph"]["raw"])
    curve = data["allan_curve"]["raw"]
    assert len(curve["n"]) == len(curve["lower"]) == len(curve["tau_s"])
    means = data["allan_burst_means"]["raw"]
    assert means["counts"][0] == means["bursts"] - 1
    assert all(lo < d < hi for lo, d, hi in
               zip(means["lower"], means["deviation"], means["upper"], strict=True))
    assert 0.0 < means["bias_random_walk"][0] < 1.0
    text = CliRunner().invoke(app, ["evaluate", str(path), "--model", str(model_path),
                                    "--gaps", "bridge"])
    assert text.exit_code == 0, text.output
    assert "N " in text.stdout and "dead-time ratio" in text.stdout
