"""The fleet tables are long-form, a row per unit × axis (issue 28), on a real Dask cluster.

A fleet of two simulated three-axis instruments gives six rows whose figures are those of
calibrating each instrument alone (:func:`hrgtc.pipeline.calibration.calibrate`
called here, in this process, against the fleet's tasks on the cluster's workers) and
whose thermometers read each axis's true frequency law (its ``truth-<axis>.json``); the
fleet's evaluation gives each axis's held-out figures again by another path. A
single-axis fleet's tables are those of before the long form
(``tests/data/fleet-single-axis/tables.json``, ``make.py`` beside it) with the column
``axis`` "" (null for the unit that failed).
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import pytest

from hrgtc.core.errors import InputError
from hrgtc.fleet import build_prior, calibrate_fleet, evaluate_fleet, report_fleet
from hrgtc.fleet.population import true_frequency_hz
from hrgtc.fleet.results import read_table
from hrgtc.model import load_model, save_model
from hrgtc.pipeline.calibration import calibrate
from hrgtc.settings.fleet import FleetCluster
from hrgtc.thermometry.prior import ThermometerPrior

TABLES = Path(__file__).parents[1] / "data" / "fleet-single-axis" / "tables.json"
UNITS = ("s3-u0000", "s3-u0001")


@pytest.fixture(scope="module")
def instrument_models(instrument_root, cluster, tmp_path_factory) -> Path:
    """The instruments calibrated as a fleet on the cluster."""
    models = tmp_path_factory.mktemp("instrument-models")
    run = calibrate_fleet(instrument_root, models, cluster=cluster)
    assert run.where == cluster.scheduler
    assert run.counts() == {"ok": 2, "skipped": 0, "failed": 0}
    return models


def _alone(folder: Path):
    """One instrument calibrated here, by the library call a single instrument takes."""
    return calibrate(sorted((folder / "soaks").glob("*.parquet")),
                     sorted((folder / "drift").glob("*.parquet")),
                     sorted((folder / "validate").glob("*.parquet")))


def test_a_fleet_of_instruments_has_a_row_per_axis_equal_to_each_calibrated_alone(
        instrument_root, instrument_models):
    rows = read_table(instrument_models / "fleet.parquet")
    assert [(r["unit"], r["axis"]) for r in rows] == [(u, a) for u in UNITS for a in "xyz"]
    for unit in UNITS:
        alone = _alone(instrument_root / unit)
        assert list(alone.model.axes) == ["x", "y", "z"]
        stored = load_model(instrument_models / f"{unit}.json").to_dict()
        expected = json.loads(json.dumps(alone.model.to_dict()))
        for document in (stored, expected):
            document["provenance"].pop("created_utc")
        assert stored == expected  # the fleet's model file is the instrument's
        for row in (r for r in rows if r["unit"] == unit):
            axis, part = row["axis"], alone.model.axes[row["axis"]]
            assert row["status"] == "ok"
            assert row["model_file"] == str(instrument_models / f"{unit}.json")
            assert row["coefficients_high_first"] == list(
                part.thermometer.coefficients_high_first)
            assert row["f20_hz"] == float(part.thermometer.frequency(20.0))
            assert row["terms_kept"] == list(part.drift.selected)
            assert row["soak_temperatures_c"] == [r["chamber_c"] for r in alone.axes[axis].table]
            held_out = alone.axes[axis].validation
            assert row["raw_10s_dph"] == [v.raw_10s for v in held_out]
            assert row["compensated_10s_dph"] == [v.compensated_10s for v in held_out]
            # the ground truth: the axis's drawn frequency law, read at 20 °C
            truth = json.loads((instrument_root / unit / f"truth-{axis}.json").read_text())
            assert row["f20_hz"] == pytest.approx(float(true_frequency_hz(truth, 20.0)),
                                                  abs=2e-3)  # 0.005 °C at 0.37 Hz/°C
            assert row["compensated_10s_dph"][0] < row["raw_10s_dph"][0] / 2
    # the axes of one instrument are different resonators, each with its own law
    assert len({r["f20_hz"] for r in rows}) == 6


def test_the_fleets_evaluation_gives_each_axis_its_held_out_figures_again(
        instrument_root, instrument_models, cluster, tmp_path):
    run = evaluate_fleet(instrument_root, instrument_models, tmp_path / "evaluation.parquet",
                         cluster=cluster)
    assert run.counts()["ok"] == 2
    evaluated = read_table(tmp_path / "evaluation.parquet")
    calibrated = read_table(instrument_models / "fleet.parquet")
    assert [(r["unit"], r["axis"]) for r in evaluated] == [(u, a) for u in UNITS for a in "xyz"]
    for again, first in zip(evaluated, calibrated, strict=True):
        # evaluate with the Allan terms against the calibration's own held-out
        # pass (bias only): the same 10 s figures
        assert again["runs"] == first["runs"]
        assert again["raw_10s_dph"] == pytest.approx(first["raw_10s_dph"], rel=1e-12)
        assert again["compensated_10s_dph"] == pytest.approx(first["compensated_10s_dph"],
                                                             rel=1e-12)


def test_resume_skips_every_axis_of_an_unchanged_instrument(instrument_root, instrument_models):
    before = read_table(instrument_models / "fleet.parquet")
    again = calibrate_fleet(instrument_root, instrument_models, resume=True,
                            cluster=FleetCluster(workers=0))
    assert again.counts() == {"ok": 0, "skipped": 2, "failed": 0}
    after = read_table(instrument_models / "fleet.parquet")
    drop = ("status", "seconds")
    assert [{k: v for k, v in r.items() if k not in drop} for r in after] == [
        {k: v for k, v in r.items() if k not in drop} for r in before]
    assert {r["status"] for r in after} == {"skipped"}


def test_the_report_and_the_prior_are_per_axis(instrument_models, tmp_path):
    report, _ = report_fleet(instrument_models, tmp_path / "fleet.html")
    html = report.read_text()
    assert "2 units of 3 axes (x, y, z): 2 calibrated" in html
    for axis in "xyz":
        assert f"<h2>Distributions, axis {axis}</h2>" in html
    assert html.count("<tr><td>s3-u0000</td><td>") == 3  # a row per axis in the units' table
    with pytest.raises(InputError, match=r"no model file has the axis ''.*x, y, z: pass --axis"):
        build_prior(instrument_models)
    with pytest.raises(InputError, match="no model file has the axis 'w'"):
        build_prior(instrument_models, axis="w")
    with pytest.raises(InputError, match="2 unit"):  # the two x thermometers, not six
        build_prior(instrument_models, axis="x")
    # six instruments whose x axes are the six resonators of the two: the prior of axis x
    # is that of the six thermometers
    folder = tmp_path / "models"
    folder.mkdir()
    parts = [(unit, load_model(instrument_models / f"{unit}.json")) for unit in UNITS]
    thermometers = []
    for unit, model in parts:
        for k, axis in enumerate("xyz"):
            others = [a for a in "xyz" if a != axis]
            turned = dataclasses.replace(model, unit=f"{unit}-{axis}", axes={
                "x": model.axes[axis], "y": model.axes[others[0]], "z": model.axes[others[1]]})
            save_model(turned, folder / f"{unit}-{k}.json")
            thermometers.append(model.axes[axis].thermometer)
    prior = build_prior(folder, axis="x")
    expected = ThermometerPrior.from_thermometers(
        thermometers, [f"{u}-{a}" for u in UNITS for a in "xyz"])
    assert prior.n_units == 6
    assert prior.mean == pytest.approx(expected.mean, rel=1e-12)
    assert prior.nominal_freq_hz == pytest.approx(expected.nominal_freq_hz, rel=1e-12)


def _same(row: dict, expected: dict) -> None:
    """Equal, floats to 1e-9 relative (the pin may have been written on another machine)."""
    assert row.keys() == expected.keys()
    for key, value in expected.items():
        got = row[key]
        if isinstance(value, float) or (isinstance(value, list) and value
                                         and isinstance(value[0], float)):
            assert got == pytest.approx(value, rel=1e-9, abs=1e-12), key
        else:
            assert got == value, key


def _relative(value, root: str):
    if isinstance(value, str):
        return value.replace(root, "ROOT")
    if isinstance(value, list):
        return [_relative(v, root) for v in value]
    return value


def test_a_single_axis_fleets_tables_are_those_of_before_with_the_axis_column(
        fleet_root, cluster, tmp_path):
    truth = json.loads(TABLES.read_text(encoding="utf-8"))
    # the pin's paths are relative to the folder holding data/ and models/
    data, models = fleet_root, tmp_path / "models"
    run = calibrate_fleet(data, models, cluster=cluster)
    assert run.counts() == {"ok": 3, "skipped": 0, "failed": 1}
    evaluate_fleet(data, models, cluster=cluster)
    for name, table in (("calibrate", "fleet.parquet"), ("evaluate", "evaluation.parquet")):
        rows = read_table(models / table)
        assert [r["axis"] for r in rows] == [None, "", "", ""]  # s5-bad failed
        for row, expected in zip(rows, truth[name], strict=True):
            assert not math.isnan(row["seconds"])
            written = {k: _relative(_relative(v, str(data.parent)), str(tmp_path))
                       for k, v in row.items() if k not in ("seconds", "axis")}
            _same(written, expected)
