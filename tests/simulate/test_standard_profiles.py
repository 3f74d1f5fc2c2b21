"""The rate-table profile (hrgtc.simulate.standard_profiles.rate_table): segment timing,
one axis at a time, profile files round trip, and its errors."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from hrgtc.core.errors import InputError
from hrgtc.simulate import profiles, standard_profiles
from hrgtc.simulate.profiles import Segment


def test_rate_table_segment_timing():
    p = standard_profiles.rate_table([-10.0, 30.0], [0.0, 10.0, -300.0], hold_s=30.0,
                                     soak_h=0.5)
    ends = p.segment_ends_s()
    # Per plateau: a 1800 s soak (slew included), then three 30 s rate holds.
    expected = np.cumsum([1800.0, 30.0, 30.0, 30.0] * 2)
    np.testing.assert_allclose(ends, expected, rtol=0, atol=1e-9)
    assert p.duration_s == pytest.approx(2 * (1800.0 + 3 * 30.0), abs=1e-9)
    # 20 -> -10 °C at 2 °C/min: 900 s; -10 -> 30 °C: 1200 s after the first plateau ends,
    # the chamber holding its plateau while the table turns.
    chamber = p.chamber_c([450.0, 900.0, 1890.0, 1890.0 + 600.0, 1890.0 + 1200.0, 3779.0])
    np.testing.assert_allclose(chamber, [5.0, -10.0, -10.0, 10.0, 30.0, 30.0], atol=1e-9)
    middles = np.concatenate([[0.0], ends[:-1]]) + np.diff(np.concatenate([[0.0], ends])) / 2
    assert p.table_rate_dps(middles).tolist() == [0.0, 0.0, 10.0, -300.0] * 2
    # A sample at a segment's end belongs to the next segment; after the end the last holds.
    assert p.table_rate_dps([ends[1], ends[2], ends[-1] + 10.0]).tolist() == [10.0, -300.0,
                                                                               -300.0]
    assert p.has_rate_table and p.table_axes == (None,)
    assert p.name == "ratetable_-10C_to_30C"


def test_rate_table_turns_one_axis_at_a_time():
    p = standard_profiles.rate_table([20.0], [5.0, -5.0], hold_s=10.0, soak_h=0.1,
                                     axes=("x", "y", "z"))
    assert p.table_axes == ("x", "y", "z")
    t = 360.0 + 10.0 * np.arange(6) + 5.0  # the middles of the six rate holds
    assert p.table_rate_dps(t, "x").tolist() == [5.0, -5.0, 0, 0, 0, 0]
    assert p.table_rate_dps(t, "y").tolist() == [0, 0, 5.0, -5.0, 0, 0]
    assert p.table_rate_dps(t, "z").tolist() == [0, 0, 0, 0, 5.0, -5.0]
    assert p.table_rate_dps(t).tolist() == [0.0] * 6  # no single-axis segment
    assert "on axes x, y, z in turn" in p.description


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_rate_table_profile_file_round_trip(tmp_path, suffix):
    p = standard_profiles.rate_table([-10.0, 50.0], [0.0, 100.0, -100.0], hold_s=45.0,
                                     soak_h=1.5, axes=("x", "z"))
    path = tmp_path / f"table{suffix}"
    dump = json.dumps if suffix == ".json" else yaml.safe_dump
    path.write_text(dump(p.to_dict()))
    again = profiles.load(path)
    assert again == p
    assert np.array_equal(again.segment_ends_s(), p.segment_ends_s())
    assert profiles.Profile.from_dict(json.loads(json.dumps(p.to_dict()))) == p


def test_segments_without_table_keep_their_file_form():
    # Profiles of earlier files (no table) write exactly the keys they had.
    assert Segment(5.0, hold_h=1.0).to_dict() == {"setpoint_c": 5.0, "hold_h": 1.0}
    assert Segment(5.0, hold_h=1.0, table_rate_dps=-10, axis="b2").to_dict() == {
        "setpoint_c": 5.0, "hold_h": 1.0, "table_rate_dps": -10.0, "axis": "b2"
    }


def test_build_ratetable_defaults_and_options():
    (p,) = standard_profiles.build("ratetable")
    plateaus = standard_profiles.DEFAULT_PLATEAUS_C
    rates = standard_profiles.DEFAULT_TABLE_RATES_DPS
    assert len(p.segments) == len(plateaus) * (1 + len(rates))
    assert p.duration_s == pytest.approx(len(plateaus) * (3 * 3600.0 + len(rates) * 60.0))
    (q,) = standard_profiles.build("ratetable", setpoints_c=[0.0], rates_dps=[1.0, 2.0],
                                   rate_hold_s=20.0, hours=0.25, axes=("x", "y"))
    assert q.duration_s == pytest.approx(900.0 + 2 * 2 * 20.0)
    assert [s.axis for s in q.segments] == [None, "x", "x", "y", "y"]
    # axes is ignored by the other kinds (the CLI passes the unit's axes always).
    (soak,) = standard_profiles.build("soak", setpoints_c=[0.0], hours=1, axes=("x",))
    assert not soak.has_rate_table


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: standard_profiles.build("ratetable", ramp_c_per_min=1.0),
         r"\['ramp_c_per_min'\] do not apply to profile 'ratetable'"),
        (lambda: standard_profiles.build("soak", rates_dps=[1.0]),
         r"\['rates_dps'\] do not apply to profile 'soak'"),
        (lambda: standard_profiles.rate_table(rates_dps=[]), "rates_dps is empty"),
        (lambda: standard_profiles.rate_table(hold_s=0.0), r"hold_s must be > 0 \[s\]"),
        (lambda: standard_profiles.rate_table(rates_dps=[1.0, "fast"]),
         r"rates_dps\[1\] must be a finite number \[°/s\]"),
        (lambda: standard_profiles.rate_table(axes=()), "axes is empty"),
        (lambda: Segment(1.0, hold_h=1.0, table_rate_dps=1.0, axis="x_1"),
         "axis must be a letter then letters or digits"),
        (lambda: Segment(1.0, hold_h=1.0, axis="x"), "without table_rate_dps"),
        (lambda: profiles.from_mapping([{"setpoint_c": 1, "hold_h": 1, "rate": 3}]),
         r"unknown key\(s\) \['rate'\].*table_rate_dps and axis"),
    ],
)
def test_rate_table_errors(call, match):
    with pytest.raises(InputError, match=match):
        call()


def test_each_kind_takes_its_defaults_from_the_one_table(monkeypatch):
    """``build`` takes a kind's defaults from settings.simulation.PROFILE_DEFAULTS, the
    table the help of ``hrgtc simulate`` is generated from: the explicit values of the
    table give the same runs, and a value changed in the table changes the run."""
    from hrgtc.settings.simulation import PROFILE_DEFAULTS, REQUIRED, per_kind

    for kind, defaults in PROFILE_DEFAULTS.items():
        required = {k: 20.0 - 40.0 * i for i, k in enumerate(
            k for k, v in defaults.items() if v == REQUIRED)}  # a ramp: 20 -> -20 °C
        given = {k: v for k, v in defaults.items() if v != REQUIRED}
        default = standard_profiles.build(kind, **required)
        explicit = standard_profiles.build(kind, **given, **required)
        assert [p.duration_s for p in default] == [p.duration_s for p in explicit], kind
    (cooldown,) = standard_profiles.build("cooldown")
    assert cooldown.duration_s == pytest.approx(5.0 * 3600.0)  # Fig. 6 of [1]: 5 h
    assert [p.duration_s for p in standard_profiles.build("soak")] == [5.0 * 3600.0] * 7
    monkeypatch.setitem(PROFILE_DEFAULTS, "soak", {**PROFILE_DEFAULTS["soak"], "hours": 2.0})
    assert [p.duration_s for p in standard_profiles.build("soak")] == [2.0 * 3600.0] * 7
    assert "soak 2.0" in per_kind("hours") and "ratetable 3.0" in per_kind("hours")
    with pytest.raises(InputError, match=r"a ramp needs start_c \(--start\)"):
        standard_profiles.build("ramp", end_c=5.0)


def test_build_takes_the_simulation_settings_whole():
    """``build(kind, SimulationSettings(...))`` is ``build(kind, **the same fields)``; a
    keyword overrides the settings' field; a keyword that is no profile option is refused."""
    from hrgtc.settings.simulation import SimulationSettings

    settings = SimulationSettings(setpoints_c=(-10.0, 30.0), hours=1.0, single_file=True)
    (whole,) = standard_profiles.build("soak", settings)
    (keywords,) = standard_profiles.build("soak", setpoints_c=[-10.0, 30.0], hours=1.0,
                                          single_file=True)
    assert whole == keywords
    assert [p.duration_s for p in standard_profiles.build("soak", settings, hours=2.0,
                                                          single_file=False)] == [7200.0] * 2
    with pytest.raises(TypeError, match=r"\['seed'\]"):
        standard_profiles.build("soak", seed=1)
