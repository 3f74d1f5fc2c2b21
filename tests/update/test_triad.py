"""The offsets of a triad from |Ω| (issue 29, item 4): a three-axis instrument whose offsets
aged, held at rest in several orientations with the Earth rate in its rates, the input rate
unknown."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hrgtc.settings.update import EARTH_RATE_DPH

from field_ageing import AGED_DPH, at_rest_in, target_offsets


@pytest.fixture(scope="module")
def four_faces():
    return at_rest_in((0, 1, 2, 3))


def test_four_orientations_recover_the_aged_offsets(instrument, four_faces, tmp_path):
    """Four orientations, the input rate unknown: the three offsets move to what the data
    call for, each within 3σ of its stated interval, closer than the parent's by most of
    the ageing; the lineage keeps them; the file round-trips."""
    from hrgtc.model import load_model, save_model

    recording, still = four_faces
    result = instrument.update(recording, still_s=still)
    triad = result.triad
    assert result.applied and triad is not None, result.notes
    assert triad.n_orientations == 4 and triad.condition < 10.0
    target = target_offsets(instrument, recording, still)
    for k, axis in enumerate(triad.axes):
        sigma = math.sqrt(triad.covariance_after[k, k])
        assert abs(triad.after[k] - target[axis]) <= 3.0 * sigma, (axis, triad.after[k],
                                                                   target[axis], sigma)
        assert sigma < 0.5 * math.sqrt(triad.covariance_before[k, k]), axis
        assert abs(triad.after[k] - target[axis]) < 0.5 * abs(AGED_DPH[axis]), axis
        assert result.model.axes[axis].drift.intercept_dph == triad.after[k]
    assert triad.heldout_after_dph < triad.heldout_before_dph
    assert "orientations: 4" in result.summary().text()
    change = result.lineage.changes[-1]
    assert change.axis == "triad" and change.after == triad.after
    again = load_model(save_model(result.model, tmp_path / "imu-2.json"))
    assert [again.axes[a].drift.intercept_dph for a in "xyz"] == list(triad.after)


def test_the_solution_puts_the_still_means_on_the_earth_rate_sphere(instrument, four_faces):
    """Two methods agree: the still means less the updated offsets have |Ω_E| within their
    noise, and the offsets solve the same problem as a closed-form sphere fit (the
    algebraic least squares of |m - b|² = Ω_E², linear in b and |b|²)."""
    from hrgtc.recording import axis_view

    recording, still = four_faces
    triad = instrument.update(recording, still_s=still).triad
    means = []
    for start, end in still:
        inside = (recording.time_s >= start) & (recording.time_s <= end)
        means.append([float(np.mean((axis_view(recording, a).rate_dph - instrument.axes[
            a].drift.predict_recording(axis_view(recording, a), instrument.axes[
                a].thermometer))[inside])) for a in triad.axes])
    means = np.array(means)
    step = np.array(triad.after) - np.array(triad.before)
    norms = np.linalg.norm(means - step, axis=1)
    assert np.all(np.abs(norms - EARTH_RATE_DPH) < 0.3), norms
    # |m|² - Ω² = 2 m·b - |b|²: linear in (b, |b|²), four equations, four unknowns
    a = np.column_stack([2.0 * means, -np.ones(len(means))])
    solution = np.linalg.lstsq(a, np.sum(means ** 2, axis=1) - EARTH_RATE_DPH ** 2,
                               rcond=None)[0]
    np.testing.assert_allclose(solution[:3], step, atol=0.15)


def test_one_orientation_leaves_the_offsets_and_says_why(instrument):
    """At rest in one orientation |m - b| = Ω_E does not fix b: nothing is changed and the
    note names the orientations found and how many are needed."""
    recording, still = at_rest_in((0, 0, 0))
    result = instrument.update(recording, still_s=still)
    assert result.triad is None
    assert not result.applied
    assert "1 distinct orientation(s), at least 3 are needed" in result.reason


def test_orientations_about_one_axis_are_too_poor_a_geometry(instrument):
    """Turned about the east axis only (level, then on either side): the Earth rate stays
    in the body's x-z plane, the y offset is not seen (|m - b| does not change with it to
    first order): nothing changed, the condition number said."""
    recording, still = at_rest_in((0, 2, 5))
    result = instrument.update(recording, still_s=still)
    assert result.triad is None and not result.applied
    assert "3 orientations leave the offsets poorly determined (condition number" \
        in result.reason, result.reason


def test_two_orientations_are_too_few(instrument):
    recording, still = at_rest_in((0, 3, 0, 3))
    result = instrument.update(recording, still_s=still)
    assert result.triad is None
    assert "2 distinct orientation(s), at least 3 are needed" in result.reason


def test_a_known_input_rate_or_a_zero_norm_turns_the_triad_off(instrument, four_faces):
    from hrgtc.update import UpdateSettings

    recording, still = four_faces
    off = instrument.update(recording, UpdateSettings(triad_rate_norm_dph=0.0), still_s=still)
    assert off.triad is None and not off.applied
    assert "offset B0 not updated: the input rate is unknown" in off.reason


def test_the_command_updates_a_triad_by_default_and_rolls_back(instrument, four_faces,
                                                                tmp_path):
    """``hrgtc update`` on a triad's model, no input rate given: the offsets from |Ω| by
    default (the figures in --json, the file written), and back with --rollback."""
    import json

    from typer.testing import CliRunner

    from hrgtc.cli import app
    from hrgtc.model import load_model, save_model
    from hrgtc.recording import write

    recording, still = four_faces
    model = save_model(instrument, tmp_path / "imu.json")
    field = write(recording, tmp_path / "field.parquet")
    args = ["update", str(model), str(field), "-o", str(tmp_path / "imu-2.json"), "--json",
            *[a for start, end in still for a in ("--still", f"{start:g}:{end:g}")]]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    figures = {f["name"]: f["value"] for section in data["summary"]["sections"]
               for f in section["figures"]}
    assert data["applied"] and figures["triad.n_orientations"] == 4
    updated = load_model(tmp_path / "imu-2.json")
    library = instrument.update(recording, still_s=still).triad
    assert [updated.axes[a].drift.intercept_dph for a in "xyz"] == list(library.after)
    off = CliRunner().invoke(app, [*args[:4], str(tmp_path / "imu-3.json"),
                                   "--triad-rate-norm-dph", "0", *args[5:]])
    assert off.exit_code == 0 and not json.loads(off.stdout)["applied"], off.output
    back = CliRunner().invoke(app, ["update", "--rollback", str(tmp_path / "imu-2.json"),
                                    "-o", str(tmp_path / "imu-back.json")])
    assert back.exit_code == 0, back.output
    assert (tmp_path / "imu-back.json").read_bytes() == model.read_bytes()
