"""Reads per file per command (issue 22, Deliver 4): a file is read once per command
whatever the number of axes, and the figures of every axis from one reading are those of
each axis's view read alone.

The counts come from :mod:`read_counter` (opens, full passes, heads). On these small
files (fewer rows than the validation's heuristic rows) a head reads the whole file; a
head on a long file reads its first rows only.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.evaluation import evaluate
from hrgtc.model import load_model
from hrgtc.pipeline.calibration import calibrate
from hrgtc.recording import ReadOptions
from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles
from read_counter import count_reads

SETPOINTS_C = (-20.0, 0.0, 20.0, 40.0)


def _campaign(folder: Path, unit: str) -> dict:
    soaks = simulate_files([profiles.soak(s, 5.0) for s in SETPOINTS_C], folder / "soaks",
                           "parquet", unit=unit, sample_rate_hz=1.0, seed=1)
    cool = simulate_files([profiles.cooldown(20.0, -20.0, 3.0)], folder / "cool", "parquet",
                          unit=unit, sample_rate_hz=1.0, seed=2)
    warm = simulate_files([profiles.warmup(-20.0, 20.0, 3.0)], folder / "warm", "parquet",
                          unit=unit, sample_rate_hz=1.0, seed=3)
    files = {"soaks": [Path(w.path) for w in soaks], "cool": Path(cool[0].path),
             "warm": Path(warm[0].path)}
    calibration = calibrate(files["soaks"], [files["cool"]], [files["warm"]])
    files["model"] = folder / "model.json"
    from hrgtc.model import save_model

    save_model(calibration.model, files["model"])
    return files


@pytest.fixture(scope="module", params=["paper-unit", "imu-3"], ids=["1-axis", "3-axis"])
def campaign(request, tmp_path_factory):
    return _campaign(tmp_path_factory.mktemp(request.param), request.param)


def _counts(args: list) -> object:
    with count_reads() as counts:
        result = CliRunner().invoke(app, [str(a) for a in args])
    assert result.exit_code == 0, result.output
    return counts


def test_evaluate_reads_the_run_once_whatever_the_axes(campaign):
    """One pass of the at-rest detector's columns (the detector's window is centred, so a
    sample's place in the figures depends on later samples), one pass that compensates
    and measures every axis, one head (columns, metadata, the noise check); before: the
    two passes and two heads per axis."""
    counts = _counts(["evaluate", campaign["warm"], "-m", campaign["model"]])
    assert counts.table([campaign["warm"]])[campaign["warm"].name] == {
        "opens": 6, "passes": 2, "heads": 1}
    counts = _counts(["evaluate", campaign["warm"], "-m", campaign["model"],
                      "--motion", "keep"])
    assert counts.table([campaign["warm"]])[campaign["warm"].name] == {
        "opens": 5, "passes": 1, "heads": 1}


def test_compensate_reads_the_run_once(campaign):
    """One compensating pass; with the at-rest flags (``--motion exclude``, the default) one
    pass of the detector's columns first, as evaluate (the detector is not local:
    compensate/at_rest.py)."""
    args = ["compensate", campaign["warm"], "-m", campaign["model"], "-o",
            campaign["warm"].with_name("comp.parquet"), "--force"]
    counts = _counts([*args, "--motion", "keep"])
    passes = counts.of(campaign["warm"])[1]
    assert passes == 1 and counts.heads[str(campaign["warm"].resolve())] == 0
    counts = _counts(args)
    passes = counts.of(campaign["warm"])[1]
    assert passes == 2 and counts.heads[str(campaign["warm"].resolve())] == 0


def test_evaluate_of_every_axis_equals_each_axis_view_alone(campaign):
    """The one reading gives each axis the figures of that axis's model evaluated on the
    axis's view of the file (``read_options.axis``), to 1e-12."""
    model = load_model(campaign["model"])
    options = ReadOptions().with_spike_default("drop")
    together = evaluate(model, campaign["warm"], read_options=options, max_points=2000)
    assert list(together.axes) == list(model.axes)
    for axis in model.axes:
        alone = evaluate(model.of_axis(axis), campaign["warm"], max_points=2000,
                         read_options=dataclasses.replace(options, axis=axis or None)).axis
        one = together.axes[axis]
        assert one.n_samples == alone.n_samples and one.n_not_at_rest == alone.n_not_at_rest
        for series, row in alone.bias_stability_dph.items():
            for tau, value in row.items():
                other = one.bias_stability_dph[series][tau]
                assert (math.isnan(value) and math.isnan(other)) or \
                    other == pytest.approx(value, rel=1e-12, abs=0), (axis, series, tau)
        for series, curve in alone.allan.items():
            np.testing.assert_allclose(one.allan[series].deviation, curve.deviation,
                                       rtol=1e-12)
        assert one.mean_dph == pytest.approx(alone.mean_dph, rel=1e-12)
        assert one.rms_dph == pytest.approx(alone.rms_dph, rel=1e-12)
        assert one.out_of_range_fraction == alone.out_of_range_fraction
        for key, values in alone.blocks.items():
            np.testing.assert_allclose(one.blocks[key], values, rtol=1e-12, equal_nan=True)
        assert one.to_dict() == alone.to_dict()
    rows = together.axis_summary()
    assert [r["axis"] for r in rows] == list(model.axes)
    assert rows[0]["improvement_10s"] == together.axes[rows[0]["axis"]].improvement_10s


def test_calibrate_reads_each_file_once_for_every_axis(campaign):
    """A multi-axis calibration reads each file once (:class:`hrgtc.recording.read_once.
    ReadOnce`), with --cross-axis too; before: 5-6 passes per axis of each file (15-18 for
    three axes, 33-39 with --cross-axis). A single-axis calibration still streams each
    file several times (plateaus, at-rest pass, window means, held-out evaluation),
    holding none of them whole; the housing baseline takes the drift fit's at-rest pass
    (issue 27: one pass fewer of each training file than the 5 and 6 before), and the
    rate-free refit's window means come from the fit's own window pass (issue 27 item 8:
    6 and 7 before when the terms chosen use no rate), and the housing baseline's window
    means from the drift fit's window pass (issue 27 item 8: 4 and 5 before), and a soak's
    at-rest pass is run on its plateaus' reading (3 before)."""
    args = ["calibrate", "--soak", *campaign["soaks"], "--drift", campaign["cool"],
            "--validate", campaign["warm"], "-o", campaign["model"].with_name("m.json"),
            "--force"]
    counts = _counts(args)
    files = [campaign["soaks"][0], campaign["cool"], campaign["warm"]]
    passes = [counts.of(f)[1] for f in files]
    if "imu" in str(campaign["cool"]):
        assert passes == [1, 1, 1]
        counts = _counts([*args, "--cross-axis"])
        assert [counts.of(f)[1] for f in files] == [1, 1, 1]
    else:  # also when the terms chosen use no rate and the warm-up samples are trained
        # on too (docs/real-loggers/corpus.md): those windows come from the same pass
        assert passes == [2, 4, 2]


def test_calibrate_checks_each_training_file_for_a_mark_once(campaign, monkeypatch):
    """Whether a training file is a compensated output is asked once per command, whatever
    the number of axes (``refuse_compensated_training`` in ``calibrate``, then no check in
    ``fit_axis`` for each axis); before: once more per axis (2
    for one axis, 4 for three, each an open of the file's metadata). With three axes a
    soak file is opened twice: that check and the one reading every axis shares."""
    import hrgtc.recording.marks as marks

    checked: list[str] = []
    real = marks.refuse_compensated

    def counted(path, training=False):
        checked.append(Path(path).name)
        return real(path, training)

    monkeypatch.setattr(marks, "refuse_compensated", counted)
    args = ["calibrate", "--soak", *campaign["soaks"], "--drift", campaign["cool"],
            "--validate", campaign["warm"], "-o", campaign["model"].with_name("m.json"),
            "--force"]
    counts = _counts(args)
    files = [*campaign["soaks"], campaign["cool"], campaign["warm"]]
    assert sorted(checked) == sorted(f.name for f in files)
    if "imu" in str(campaign["cool"]):
        assert counts.of(campaign["soaks"][0])[0] == 2
        checked.clear()
        _counts([*args, "--cross-axis"])
        assert sorted(checked) == sorted(f.name for f in files)


def test_reading_once_gives_the_same_instrument_model(campaign, monkeypatch):
    """The model from one reading of each file equals the model from reading them per
    axis, as before (the cached chunks are the streamed chunks)."""
    import hrgtc.pipeline.calibration as chain

    once = calibrate(campaign["soaks"], [campaign["cool"]], [campaign["warm"]])
    monkeypatch.setattr(chain, "ReadOnce", lambda **words: ReadOptions(**words))
    streamed = calibrate(campaign["soaks"], [campaign["cool"]],
                                    [campaign["warm"]])

    def plain(model):
        data = model.to_dict()
        data.pop("provenance", None)
        for axis in data.get("axes", {}).values():
            axis.pop("provenance", None)
        return data

    assert plain(once.model) == plain(streamed.model)
    for axis, result in once.axes.items():
        assert [v.to_dict() for v in result.validation] == \
            [v.to_dict() for v in streamed.axes[axis].validation]


def test_report_reads_each_run_and_soak_once(campaign):
    """``hrgtc report`` evaluates every axis of a run from one reading
    (:func:`hrgtc.evaluation.evaluate`) and traces every axis of a soak
    from one reading: two passes over a run (the at-rest detector's columns, then the
    measuring pass) and one over a soak; before: 2 passes and 2 heads of a run per axis
    (6 and 6 for three axes), one pass of a soak per axis (3 for three axes)."""
    output = campaign["model"].with_name("report.html")
    counts = _counts(["report", campaign["warm"], "-m", campaign["model"], "--soak",
                      campaign["soaks"][0], "-o", output, "--force"])
    table = counts.table([campaign["warm"], campaign["soaks"][0]])
    assert {k: table[campaign["warm"].name][k] for k in ("passes", "heads")} == {
        "passes": 2, "heads": 1}
    assert table[campaign["soaks"][0].name]["passes"] == 1


@pytest.fixture(scope="module")
def imu_campaign(tmp_path_factory):
    """A 3-axis campaign only: cross-axis terms need the other axes' resonators."""
    return _campaign(tmp_path_factory.mktemp("imu-3-cross"), "imu-3")


def test_cross_axis_fits_the_thermometer_once(imu_campaign, monkeypatch):
    """``--cross-axis`` reuses each axis's thermometer (plateaus, Tables 1-2) for the trial
    with the other resonators' frequencies: one thermometer fit and one plateau search per
    axis and soak (before: two), and the same model as the old path that calibrated each
    axis twice from scratch (coefficients to 1e-12)."""
    import hrgtc.pipeline.axis_calibration as calibration
    import hrgtc.pipeline.calibration as chain
    import hrgtc.pipeline.soak_pass as soak_pass
    from hrgtc.settings.calibration import CalibrationSettings

    campaign = imu_campaign
    calls = {"thermometer": 0, "plateaus": 0}

    def counted(name, function):
        def wrapper(*args, **words):
            calls[name] += 1
            return function(*args, **words)
        return wrapper

    monkeypatch.setattr(calibration, "fit_thermometer",
                        counted("thermometer", calibration.fit_thermometer))
    monkeypatch.setattr(soak_pass, "plateaus_from_recordings",  # each soak's pass
                        counted("plateaus", soak_pass.plateaus_from_recordings))
    settings = CalibrationSettings(cross_axis=True)
    args = (campaign["soaks"], [campaign["cool"]], [campaign["warm"]])
    once = calibrate(*args, settings=settings)
    axes = len(once.model.axes)
    assert calls == {"thermometer": axes, "plateaus": axes * len(campaign["soaks"])}
    plain = chain.fit_axis

    def from_scratch(*words, soak_fit=None, **more):  # the old path: calibrate everything
        return plain(*words, **more)

    monkeypatch.setattr(chain, "fit_axis", from_scratch)
    twice = calibrate(*args, settings=settings)
    assert calls["thermometer"] == 3 * axes
    assert once.cross_axis == twice.cross_axis
    for axis, model in once.model.axes.items():
        other = twice.model.axes[axis]
        np.testing.assert_allclose(model.thermometer.coefficients_high_first,
                                   other.thermometer.coefficients_high_first, rtol=1e-12)
        assert model.drift.selected == other.drift.selected
        assert model.drift.coefficients == pytest.approx(other.drift.coefficients,
                                                         rel=1e-12)
        assert model.drift.intercept_dph == pytest.approx(other.drift.intercept_dph,
                                                          rel=1e-12)
    assert once.to_dict() == twice.to_dict()


@pytest.mark.parametrize("campaign", ["paper-unit"], indirect=True, ids=["1-axis"])
def test_soak_at_rest_passes_on_the_plateau_reading_change_no_figure(campaign, monkeypatch):
    """A single-axis calibration runs the drift fit's at-rest detector on each soak's
    plateau reading (one pass fewer per soak): the model is the one of the fit's own
    passes, every field (the provenance's creation time apart), and the drift fit then
    reads each soak once (its window pass), the plateaus once."""
    from hrgtc.pipeline import axis_calibration

    # (a multi-axis calibration reads each file once, held in memory: single-axis only)

    def model_of() -> tuple[dict, object]:
        with count_reads() as counts:
            found = calibrate(campaign["soaks"], [campaign["cool"]]).model.to_dict()
        found["provenance"].pop("created_utc", None)
        return found, counts

    fused, counts = model_of()
    assert counts.of(campaign["soaks"][0])[1] == 2
    monkeypatch.setattr(axis_calibration, "_likely_warmups", lambda *args: ())
    alone, counts = model_of()
    assert counts.of(campaign["soaks"][0])[1] == 3
    assert fused == alone
