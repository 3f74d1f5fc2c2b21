"""A three-axis unit calibrated, compensated and checked end to end (issue 14).

The simulated ``imu-3`` has three resonators (x ~4.4 kHz, y ~5.7 kHz, z ~8.5 kHz) with
their own bias laws, lags and scale-factor laws (truth in the files). Held-out: a
warm-up and a rate table at two temperatures between the training ones.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hrgtc.compensate import Compensator, compensate_file
from hrgtc.core.errors import InputError, ModelFileError, RecordingError
from hrgtc.drift import find_rate_segments
from hrgtc.evaluation.scale_check import steady_segments
from hrgtc.model import Model, load_model, save_model
from hrgtc.model_schema import strict
from hrgtc.pipeline.calibration import RateTables, calibrate, summary_rows
from hrgtc.recording import ReadOptions, axis_view, read
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.compensation import CompensateSettings
from hrgtc.settings.drift import DriftSettings

AXES = ("x", "y", "z")


@pytest.fixture(scope="module")
def calibration(imu_campaign):
    files = imu_campaign
    return calibrate(files.soaks, [files.cooldown], [files.warmup],
                     rate_tables=RateTables([files.rate_table], [files.rate_table_heldout]))


def test_every_axis_has_its_own_thermometer_drift_and_scale_factor(calibration):
    model = calibration.model
    assert model.names == AXES and not model.is_single_axis
    centres = [model.axes[a].drift.settings.reference_freq_hz for a in AXES]
    assert centres[0] < 4500 < centres[1] < 6000 < centres[2]  # three different resonators
    for axis in AXES:
        assert model.axes[axis].scale_factor is not None
        assert len(calibration.axes[axis].plateaus) == 7


def test_held_out_warmup_improves_on_every_axis(calibration):
    rows = {row["axis"]: row for row in summary_rows(calibration)}
    for axis in AXES:
        raw, comp = rows[axis]["raw_10s_dph"], rows[axis]["compensated_10s_dph"]
        assert raw / comp > 1.3, (axis, raw, comp)
    # x and y are compensated to within ~1.5x of their noise floor (0.2 and 0.15 °/h BI)
    assert rows["x"]["raw_10s_dph"] / rows["x"]["compensated_10s_dph"] > 3.0
    assert rows["y"]["raw_10s_dph"] / rows["y"]["compensated_10s_dph"] > 3.0


def test_scale_factor_residual_on_held_out_temperatures(calibration):
    """At -5 and 22 °C (not trained on): raw tens to hundreds of ppm, compensated <= 20."""
    checks = {c.axis: c for c in calibration.scale_checks}
    assert set(checks) == set(AXES)
    for axis, check in checks.items():
        assert len(check.freq_hz) == 2, axis
        assert check.raw_max_ppm > 60.0, axis
        assert check.compensated_max_ppm <= 20.0, (axis, check.compensated_ppm)
        assert check.compensated_max_ppm < check.raw_max_ppm / 5, axis


def test_scale_factor_model_against_the_simulators_truth(calibration, imu_campaign):
    """k(f) at the held-out holds' frequencies against the true scale_ppm of those holds."""
    run = read(imu_campaign.rate_table_heldout)
    for axis in AXES:
        view = axis_view(run, axis)
        unit = calibration.model.axes[axis]
        segments = steady_segments(view, find_rate_segments(view), unit)
        assert len(segments) >= 12
        for s in segments:
            truth = float(np.mean(view["scale_ppm"][s.first_row:s.first_row + s.rows]))
            model = float(unit.scale_factor.ppm(np.array([s.freq_hz]))[0])
            assert abs(model - truth) < 6.0, (axis, s.freq_hz, model, truth)


def test_instrument_compensator_equals_each_axis_alone(calibration, imu_campaign):
    run = read(imu_campaign.warmup)
    together = Compensator(calibration.model).transform(run)
    for axis in AXES:
        alone = Compensator(calibration.model.of_axis(axis)).transform(axis_view(run, axis))
        for name in ("rate_comp_dph", "bias_model_dph", "resonator_c_est", "in_range",
                     "scale_model_ppm"):
            np.testing.assert_array_equal(together[f"{name}_{axis}"], alone[name])
        # rate = input (1 + k) + bias: the output undoes both
        k = together[f"scale_model_ppm_{axis}"] * 1e-6
        np.testing.assert_allclose(
            together[f"rate_comp_dph_{axis}"] * (1 + k) + together[f"bias_model_dph_{axis}"],
            run[f"rate_dph_{axis}"], rtol=0, atol=1e-9)


def test_file_to_file_in_chunks_equals_batch(calibration, imu_campaign, tmp_path):
    output = tmp_path / "warm_comp.parquet"
    summary = compensate_file(imu_campaign.warmup, output, calibration.model,
                                         settings=CompensateSettings(chunk_rows=7_001))
    written = read(output)
    batch = Compensator(calibration.model).transform(read(imu_campaign.warmup))
    assert summary.rows == len(batch)
    for name in batch.names:
        np.testing.assert_array_equal(written[name], batch[name])


def test_a_single_axis_file_is_refused_by_a_three_axis_model(calibration, campaign_factory):
    single = campaign_factory("paper-unit", sample_rate_hz=2.0)
    with pytest.raises(RecordingError, match="no columns of axis x, y, z"):
        Compensator(calibration.model).transform(read(single.warmup))


def test_model_file_round_trip_and_checks(calibration, tmp_path):
    path = save_model(calibration.model, tmp_path / "imu.json")
    loaded = load_model(path)
    assert loaded.sha256 == calibration.model.sha256
    assert strict(loaded.to_dict()) == strict(calibration.model.to_dict())  # NaN -> None
    for axis in AXES:
        f = np.linspace(*loaded.axes[axis].scale_factor.freq_range_hz, 7)
        np.testing.assert_array_equal(loaded.axes[axis].scale_factor.ppm(f),
                                      calibration.model.axes[axis].scale_factor.ppm(f))
    with pytest.raises(InputError, match=r"has axes x, y, z: pick one: model.axes\['x'\]"):
        loaded.thermometer  # noqa: B018 (one axis's part of a multi-axis model)
    document = json.loads(path.read_text())
    document.pop("parameters_sha256")
    term = document["axes"]["y"]["drift"]["selected"][0]
    document["axes"]["y"]["drift"]["coefficients"][term] *= 1.01
    path.write_text(json.dumps(document))
    with pytest.raises(ModelFileError, match=r"axes\.y\.drift\.coefficients"):
        load_model(path)


def test_single_axis_model_is_the_one_axis_case(calibration):
    unit = calibration.model.axes["x"]
    plain = Model.single(unit)
    assert plain.is_single_axis and plain.names == ("",)
    document = plain.to_dict()
    assert "axes" not in document and document["schema_version"] == 3  # it has a scale factor
    bare = Model.single(unit.__class__(unit.thermometer, unit.drift, unit.housing),
                        calibration.model.unit)
    assert bare.to_dict()["schema_version"] == 2  # unchanged files stay version 2


def test_axis_read_options_check_that_axis_only(calibration, imu_campaign):
    """The plausible band of axis y's model is checked on freq_hz_y, not on x's column."""
    from hrgtc.model_fit import plausible_frequency_band

    band = plausible_frequency_band(calibration.model.axes["y"])
    options = ReadOptions(axis="y", freq_band_hz=band, freq_span_hz=band)
    assert len(options.read(imu_campaign.warmup)) > 0
    wrong = ReadOptions(axis="x", freq_band_hz=band, freq_span_hz=band)
    with pytest.raises(RecordingError, match="column freq_hz_x, row 0"):
        wrong.read(imu_campaign.warmup)


def test_cross_axis_candidates_are_judged_on_held_out_runs(imu_campaign):
    """Each axis is refitted with the other resonators' frequencies as candidates; the
    trial is kept only if the held-out warm-up improves by more than 2 %."""
    files = imu_campaign
    result = calibrate(files.soaks, [files.cooldown], [files.warmup],
                       settings=CalibrationSettings(cross_axis=True))
    assert set(result.cross_axis) == set(AXES)
    for axis, trial in result.cross_axis.items():
        assert trial["channels"] == {f"f{b}": f"freq_hz_{b}" for b in AXES if b != axis}
        gain = trial["held_out_10s_dph_with"] < 0.98 * trial["held_out_10s_dph_without"]
        assert trial["kept"] == gain
        (held_out,) = result.axes[axis].validation
        chosen = trial["held_out_10s_dph_with" if gain else "held_out_10s_dph_without"]
        assert held_out.compensated_10s == pytest.approx(chosen, rel=1e-12)
        uses = any("a_f" in t for t in result.model.axes[axis].drift.selected)
        assert uses == (gain and bool(trial["selected"]))
        figures = result.summary().figures()  # the trial, as hrgtc calibrate prints it
        for which in ("with", "without"):
            key = f"held_out_10s_dph_{which}"
            assert figures[f"cross_axis.{axis}.{key}"].value == trial[key]
        assert figures[f"cross_axis.{axis}.kept"].value == ("kept" if gain else "not kept")


def test_an_axis_model_reads_another_axis_frequency(imu_campaign):
    """A model of axis x with y's frequency as a term compensates from the instrument's
    file: the view of axis x keeps freq_hz_y, the numpy and fused engines agree."""
    from hrgtc.settings.inputs import CalibrationInputs

    files = imu_campaign
    options = ReadOptions(axis="x")
    drift = DriftSettings(terms=("f", "f^2", "g", "a_fy", "f*a_fy"), penter=0.5, premove=0.6)
    result = calibrate(files.soaks, [files.cooldown], read_options=options,
                       settings=CalibrationSettings(drift=drift),
                       inputs=CalibrationInputs(aux=("fy=freq_hz_y",)))
    assert any("a_fy" in t for t in result.model.drift.selected)
    run = read(files.warmup)
    view = axis_view(run, "x")
    fused = Compensator(result.model).transform(view)
    reference = Compensator(result.model, engine="numpy").transform(view)
    np.testing.assert_allclose(fused["rate_comp_dph"], reference["rate_comp_dph"], atol=1e-9)
    centre = result.model.drift.settings.aux_centres["fy"]
    assert abs(centre - np.mean(axis_view(read(files.cooldown), "y").freq_hz)) < 10.0


def test_the_instrument_summary_shows_the_rate_tables_and_the_axes(calibration, monkeypatch):
    """``Calibration.summary()``: the held-out rate tables' errors (places of the
    ``--json`` document), each axis's held-out medians (``summary_rows``), and
    ``hrgtc calibrate`` prints every one of its figures in its table."""
    import io
    import re

    from rich.console import Console

    import hrgtc.cli.calibrate_cmd as calibrate_cmd

    summary = calibration.summary()
    document = json.loads(json.dumps(calibration.to_dict()))
    checks = [f for f in summary.figures().values() if f.name.startswith("scale_factor_")]
    assert len(checks) >= 2 * sum(len(c.raw_ppm) for c in calibration.scale_checks) + 2
    for figure in checks:
        if figure.name.endswith(".n_temperatures"):  # a count, not a place of the document
            index = int(re.search(r"\[(\d+)\]", figure.name).group(1))
            assert figure.value == len(calibration.scale_checks[index].raw_ppm) >= 2
            continue
        node = document
        for token in re.findall(r"[^.\[\]]+|\[\d+\]", figure.name):
            node = node[int(token[1:-1])] if token.startswith("[") else node[token]
        assert node == pytest.approx(figure.value, rel=1e-12), figure
    for row in summary_rows(calibration):
        for field in ("raw_10s_dph", "compensated_10s_dph", "scale_raw_max_ppm",
                      "scale_residual_max_ppm"):
            assert summary[f"axes.{row['axis']}.{field}"].value == pytest.approx(row[field])
        assert summary[f"axes.{row['axis']}.drift_terms"].value == ", ".join(row["terms"])
    out = io.StringIO()
    monkeypatch.setattr(calibrate_cmd, "console", Console(file=out, width=400))
    calibrate_cmd.render_instrument(calibration)
    lines = [[c.strip() for c in line.split("│")[1:-1]] for line in out.getvalue().splitlines()]
    for heading, label, value, unit, interval in summary.rows():
        assert [label, value, unit, interval] in lines, (heading, label)


def test_the_one_axis_readings_name_the_axes_of_an_instrument(calibration, imu_campaign):
    """``calibrate`` and ``evaluate`` return one type for one axis or many: the readings of
    the only axis (``.axis``, ``.validation``, ...) raise on three axes, naming them, and
    the axis's own is in ``.axes``; one axis evaluated (``--axes y``) is the ``.axis``."""
    from hrgtc.evaluation import evaluate
    from hrgtc.settings.compensation import BIAS_ONLY

    for reading in ("axis", "plateaus", "table", "validation", "prior_fit"):
        with pytest.raises(InputError, match=r"has axes x, y, z: pick one: "
                                             r"calibration.axes\['x'\]"):
            getattr(calibration, reading)
    assert calibration.axes["y"].model.axis is calibration.model.axes["y"]
    assert calibration.axes["y"].validation[0].file == Path(imu_campaign.warmup).name
    run = evaluate(calibration.model, imu_campaign.warmup, settings=BIAS_ONLY)  # as held out
    with pytest.raises(InputError, match=r"axes x, y, z: pick one: result.axes\['x'\]"):
        run.axis  # noqa: B018 (the property raises)
    assert run.axes["y"].to_dict() == calibration.axes["y"].validation[0].to_dict()
    alone = evaluate(calibration.model, imu_campaign.warmup, settings=BIAS_ONLY, axes=("y",))
    assert list(alone.axes) == ["y"] and alone.axis.to_dict() == run.axes["y"].to_dict()
