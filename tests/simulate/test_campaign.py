"""Physics tests of the chamber-campaign simulator (hrgtc.simulate).

Truth comes from outside the simulator where it can: Table 1 and Section 3-4
of [1] (settled frequencies, ~15,000 s settling, 3.0143 and 0.5848 °/h bias
stabilities), an independent ODE solver for the thermal network, the Allan
analysis of hrgtc.evaluation.metrics (IEEE 952 conventions) for the noise terms, and the
shell model of hrgtc.simulate.shell for unit-b. Reduced sample rates are used wherever
the physics does not depend on the rate.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import itertools
import json
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hrgtc import simulate
from hrgtc.core.errors import InputError, OutputExistsError
from hrgtc.evaluation.metrics import allan_deviation, bias_stability, noise_terms
from hrgtc.recording import read
from hrgtc.simulate import profiles, standard_profiles, units
from hrgtc.simulate.shell import FUSED_QUARTZ, Shell
from hrgtc.simulate.thermal import ThermalNetwork
from hrgtc.thermometry.paper import TABLE1_FREQUENCY_HZ, TABLE1_TEMPERATURE_C

PAPER_RAW_BIAS_STABILITY_RANGE = (2.5, 3.5)  # around 3.0143 °/h, Section 4.2 of [1]
PAPER_CONSTANT_BIAS_STABILITY_RANGE = (0.5, 0.65)  # around 0.5848 °/h, Section 4.2 of [1]


def collect(profile, columns, **kwargs):
    """Only the named columns of a run (keeps memory low at 200 Hz)."""
    parts = {name: [] for name in columns}
    for chunk in simulate.iter_run_chunks(profile, **kwargs):
        for name in columns:
            parts[name].append(chunk[name])
    return {name: np.concatenate(values) for name, values in parts.items()}


def block_means(values, sample_rate_hz, tau_s=10.0):
    m = round(tau_s * sample_rate_hz)
    n = values.size // m
    return values[: n * m].reshape(n, m).mean(axis=1)


# ----------------------------------------------------------------------------- profiles
def test_soak_chamber_slews_at_its_maximum_rate_then_holds():
    p = simulate.soak(-10.0, 5.0)  # Fig. 3(a) of [1]: room temperature -> -10 °C
    times, temps = p.breakpoints()
    # 30 °C at 2 °C/min is 900 s.
    assert times.tolist() == [0.0, 900.0, 18000.0]
    assert temps.tolist() == [20.0, -10.0, -10.0]
    assert p.chamber_c([450.0]).tolist() == [5.0]
    assert p.setpoint_c == -10.0 and p.name == "soak_-10C"


def test_cooldown_ramps_then_holds_and_warmup_mirrors_it():
    cool = simulate.cooldown(20.0, -20.0, 5.0, ramp_c_per_min=1.0)
    assert cool.breakpoints()[0].tolist() == [0.0, 2400.0, 18000.0]
    assert cool.chamber_c([0.0, 1200.0, 2400.0, 17000.0]).tolist() == [20.0, 0.0, -20.0, -20.0]
    warm = simulate.warmup(-20.0, 20.0, 5.0)
    assert warm.chamber_c([0.0, 1200.0, 2400.0]).tolist() == [-20.0, 0.0, 20.0]
    assert warm.duration_s == 18000.0


def test_soak_series_starts_each_soak_from_the_previous_set_point():
    p = simulate.soak_series([-20.0, 40.0], 1.0)
    times, temps = p.breakpoints()
    # 20 -> -20 in 1200 s, hold to 3600 s; -20 -> 40 in 1800 s, hold to 7200 s.
    assert times.tolist() == [0.0, 1200.0, 3600.0, 5400.0, 7200.0]
    assert temps.tolist() == [20.0, -20.0, -20.0, 40.0, 40.0]
    campaign = simulate.soak_campaign([-20.0, 40.0], 1.0)
    assert [q.start_c for q in campaign] == [20.0, 20.0]


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
def test_profile_file_round_trip(tmp_path, suffix):
    data = {
        "start_c": 20,
        "segments": [
            {"setpoint_c": -20, "ramp_c_per_min": 1.0},
            {"setpoint_c": -20, "hold_h": 1},
            {"setpoint_c": 40, "ramp_c_per_min": 0.5},
        ],
    }
    path = tmp_path / f"cycle{suffix}"
    if suffix == ".json":
        path.write_text(json.dumps(data))
    else:
        import yaml

        path.write_text(yaml.safe_dump(data))
    p = profiles.load(path)
    times, temps = p.breakpoints()
    assert times.tolist() == [0.0, 2400.0, 6000.0, 13200.0]
    assert temps.tolist() == [20.0, -20.0, -20.0, 40.0]
    assert p.name == "cycle"
    assert profiles.Profile.from_dict(p.to_dict()) == p


@pytest.mark.parametrize(
    ("segments", "match"),
    [
        ([{"setpoint_c": 1, "hold_h": 1, "ramp_c_per_min": 1}], "exactly one of hold_h"),
        ([{"setpoint_c": 1}], "exactly one of hold_h"),
        ([{"setpoint_c": 1, "hold": 1}], r"segment 0: unknown key\(s\) \['hold'\]"),
        ([{"hold_h": 1}], "segment 0: missing setpoint_c"),
        ([{"setpoint_c": 1, "hold_h": -1}], "hold_h must be > 0"),
        ([{"setpoint_c": 1, "ramp_c_per_min": 5}], "exceeds the chamber's maximum rate 2"),
        ([{"setpoint_c": "warm", "hold_h": 1}], "setpoint_c must be a finite number"),
        ([], "no segments"),
        ({"segment": []}, r"unknown key\(s\) \['segment'\]"),
    ],
)
def test_profile_file_errors_name_file_segment_and_fix(tmp_path, segments, match):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(segments))
    with pytest.raises(InputError, match=match) as info:
        profiles.load(path)
    assert "bad.json" in str(info.value)


def test_profile_file_unparsable_or_unknown_type(tmp_path):
    (tmp_path / "p.yaml").write_text("segments: [unclosed")
    with pytest.raises(InputError, match="cannot parse the profile"):
        profiles.load(tmp_path / "p.yaml")
    (tmp_path / "p.txt").write_text("[]")
    with pytest.raises(InputError, match=r"use \.json, \.yaml or \.yml"):
        profiles.load(tmp_path / "p.txt")


def test_standard_profile_errors():
    with pytest.raises(InputError, match="needs end_c < start_c"):
        simulate.cooldown(-20.0, 20.0)
    with pytest.raises(InputError, match="takes 4 h, not less than hours=3"):
        simulate.cooldown(20.0, -20.0, 3.0, ramp_c_per_min=1 / 6)
    with pytest.raises(InputError, match="unknown profile 'sock'"):
        standard_profiles.build("sock")
    with pytest.raises(InputError, match=r"\['temperature_c'\] do not apply to profile 'soak'"):
        standard_profiles.build("soak", temperature_c=20.0)
    assert len(standard_profiles.build("soak", hours=1.0)) == 7  # Table 1 of [1]
    assert len(standard_profiles.build("soak", hours=1.0, single_file=True)) == 1


# ----------------------------------------------------------------------------- thermal
def test_thermal_network_matches_an_independent_ode_solver():
    net = ThermalNetwork(tau_housing_s=720.0, tau_resonator_s=2400.0)
    p = profiles.from_mapping(
        [
            {"setpoint_c": -10, "hold_h": 1.5},
            {"setpoint_c": 40, "ramp_c_per_min": 0.5},
            {"setpoint_c": 40, "hold_h": 1},
        ]
    )
    times, temps = p.breakpoints()  # corners at whole seconds: exact at 1 Hz
    t = np.arange(0.0, p.duration_s, 1.0)
    chunks, state = [], net.initial_state(p.start_c)
    for part in np.array_split(p.chamber_c(t), 7):
        housing, resonator, state = net.response(part, 1.0, state)
        chunks.append(np.column_stack([housing, resonator]))
    ours = np.concatenate(chunks)

    def rhs(time, y):
        chamber = np.interp(time, times, temps)
        return [(chamber - y[0]) / 720.0, (y[0] - y[1]) / 2400.0]

    ref = solve_ivp(
        rhs, (0.0, t[-1]), [20.0, 20.0], t_eval=t, method="DOP853",
        rtol=1e-11, atol=1e-11, max_step=20.0,
    )
    assert np.max(np.abs(ours - ref.y.T)) < 1e-6


@pytest.mark.parametrize(("start_c", "setpoint_c"), [(20.0, -10.0), (10.0, 40.0)])
def test_resonator_settles_within_0p1_c_after_12000_to_18000_s(start_c, setpoint_c):
    # Section 3 of [1]: after ~15,000 s the frequency (resonator) no longer changes.
    p = simulate.soak(setpoint_c, 6.0, start_c=start_c)
    truth = collect(p, ["time_s", "resonator_c"], sample_rate_hz=10.0)
    outside = np.flatnonzero(np.abs(truth["resonator_c"] - setpoint_c) > 0.1)
    settled_at = truth["time_s"][outside[-1] + 1]
    assert 12_000.0 <= settled_at <= 18_000.0
    assert abs(settled_at - 15_000.0) < 1_000.0


# ----------------------------------------------------------------------------- frequency
def test_soak_frequencies_reproduce_table1():
    # Eq. (18) of [1] at full precision, and its slope.
    eq18 = np.polynomial.Polynomial.fit(TABLE1_TEMPERATURE_C, TABLE1_FREQUENCY_HZ, 3).convert()
    slope = eq18.deriv()
    sample_rate_hz = 10.0
    for k, p in enumerate(simulate.soak_campaign(TABLE1_TEMPERATURE_C, 5.0)):
        table_hz = TABLE1_FREQUENCY_HZ[k]
        run = collect(p, ["freq_hz", "resonator_c"], sample_rate_hz=sample_rate_hz, seed=k)
        last = slice(-int(1800 * sample_rate_hz), None)  # last 30 min of the 5 h soak
        settled = run["freq_hz"][last].mean()
        # Table 2 of [1]: Eq. (18) turns the settled frequency back into the set-point
        # within 0.1 °C.
        roots = (eq18 - settled).roots()
        temperature = roots[np.argmin(np.abs(roots - p.setpoint_c))].real
        assert abs(temperature - p.setpoint_c) < 0.1
        # Against Table 1 itself: that tolerance plus the table's own scatter about Eq. (18).
        scatter = abs(table_hz - eq18(p.setpoint_c))
        assert abs(settled - table_hz) < 0.1 * slope(p.setpoint_c) + scatter
        # The scatter about the true frequency is the configured measurement noise.
        law = units.get("paper-unit").frequency_law.frequency_hz(run["resonator_c"][last])
        assert np.std(run["freq_hz"][last] - law) == pytest.approx(2.0e-3, rel=0.05)


def test_unit_b_frequency_follows_the_shell_model():
    unit = units.get("unit-b")
    shell = Shell(13.0e-3, 0.75e-3, FUSED_QUARTZ)  # the documented geometry of unit-b
    run = collect(simulate.constant(0.0, 0.1), ["freq_hz"], unit="unit-b", sample_rate_hz=10.0)
    assert 5000.0 < run["freq_hz"].mean() < 7000.0
    noise = unit.frequency_noise_hz / np.sqrt(run["freq_hz"].size)
    assert abs(run["freq_hz"].mean() - shell.frequency_hz(0.0)) < 5 * noise


# ----------------------------------------------------------------------------- noise
def test_allan_analysis_recovers_configured_arw_and_bias_instability():
    # 200 h at 1 Hz: many blocks at the flicker floor (~1,000-4,000 s).
    noise = units.get("paper-unit").gyro_noise
    rate = collect(simulate.constant(20.0, 200.0), ["rate_dph"], sample_rate_hz=1.0,
                   seed=3)["rate_dph"]
    allan = allan_deviation(rate, 1.0)
    terms = noise_terms(allan)
    assert terms.arw_deg_per_rt_h == pytest.approx(noise.arw_deg_per_sqrt_h, rel=0.15)
    assert terms.bias_instability_dph == pytest.approx(noise.bias_instability_dph, rel=0.15)
    # The whole curve follows the closed form where it is well determined.
    good = (allan.taus_s >= 1.0) & (allan.taus_s <= 20_000.0)
    ratio = allan.deviation[good] / noise.allan_deviation(allan.taus_s[good])
    assert np.all(np.abs(ratio - 1.0) < 0.15)


def test_paper_unit_bias_stability_raw_and_at_constant_temperature():
    # Section 4.2 of [1]: 3.0143 °/h raw over the cool-down, 0.5848 °/h compensated,
    # "basically the constant temperature precision".
    cool = collect(simulate.cooldown(20.0, -20.0, 5.0), ["rate_dph"], sample_rate_hz=200.0, seed=1)
    raw = bias_stability(cool["rate_dph"], 200.0, 10.0)
    assert PAPER_RAW_BIAS_STABILITY_RANGE[0] <= raw <= PAPER_RAW_BIAS_STABILITY_RANGE[1]
    flat = {
        rate: bias_stability(
            collect(simulate.constant(20.0, 5.0), ["rate_dph"], sample_rate_hz=rate,
                    seed=1)["rate_dph"],
            rate,
            10.0,
        )
        for rate in (200.0, 20.0)
    }
    low, high = PAPER_CONSTANT_BIAS_STABILITY_RANGE
    assert low <= flat[200.0] <= high
    # Noise is specified per root hertz: the 10 s stability does not depend on the rate.
    assert flat[20.0] == pytest.approx(flat[200.0], rel=0.05)
    expected = units.get("paper-unit").gyro_noise.expected_bias_stability(10.0, 5 * 3600.0)
    assert flat[200.0] == pytest.approx(expected, rel=0.1)


# ----------------------------------------------------------------------------- truth
def test_output_is_input_rate_plus_true_bias_plus_noise():
    rec = simulate.simulate_run(simulate.constant(20.0, 1.0), sample_rate_hz=20.0, seed=2)
    law = units.get("paper-unit").bias_law
    # No gradient, at the reference temperature: B0 alone.
    assert np.allclose(rec["bias_dph"], law.bias0_dph, rtol=0.0, atol=1e-9)
    residual = rec.rate_dph - rec.metadata.input_rate_dph - rec["bias_dph"]
    # ARW alone gives a 1 h mean spread of N = 0.024 °/h; flicker adds a little.
    assert abs(residual.mean()) < 0.5
    assert np.std(residual) == pytest.approx(0.024 * 60 * np.sqrt(20.0), rel=0.05)
    meta = rec.metadata
    assert (meta.unit, meta.sample_rate_hz, meta.input_rate_dph) == ("paper-unit", 20.0, 10.0)
    assert meta.profile == "constant 20 C, 1 h"
    assert meta.extra["seed"] == 2 and meta.extra["setpoint_c"] == 20.0


def test_the_papers_drift_model_can_fit_the_paper_unit_bias():
    # The bias law is in T_r and T_h - T_r; the nine terms of Eq. (21) of [1] in
    # f and df/dt must be able to fit it (fitted on 10 s means, as DESIGN.md says).
    unit = units.get("paper-unit")
    run = collect(
        simulate.cooldown(20.0, -20.0, 5.0), ["resonator_c", "bias_dph"], sample_rate_hz=10.0,
        seed=1
    )
    temp, bias = block_means(run["resonator_c"], 10.0), block_means(run["bias_dph"], 10.0)
    f = unit.frequency_law.frequency_hz(temp) - unit.frequency_law.frequency_hz(np.array(20.0))
    df = np.gradient(f, 10.0)
    f, df = f / np.abs(f).max(), df / np.abs(df).max()
    design = np.column_stack(
        [np.ones_like(f), f, f**2, f**3, df, df**2, df**3, f * df, f**2 * df, f * df**2]
    )
    coef, *_ = np.linalg.lstsq(design, bias, rcond=None)
    assert np.std(bias) > 2.5
    assert np.std(bias - design @ coef) < 0.01


def test_unit_b_differs_from_paper_unit():
    paper, other = units.get("paper-unit"), units.get("unit-b")
    assert other.thermal != paper.thermal
    assert other.bias_law != paper.bias_law and other.gyro_noise != paper.gyro_noise
    assert other.frequency_law.to_dict()["kind"] == "shell"
    slopes = {}
    for name in ("paper-unit", "unit-b"):
        run = collect(simulate.cooldown(20.0, -20.0, 5.0), ["bias_dph"], unit=name,
                      sample_rate_hz=1.0)
        slopes[name] = run["bias_dph"][-600:].mean() - run["bias_dph"][:600].mean()
    assert slopes["paper-unit"] < -5.0 and slopes["unit-b"] > 2.0  # opposite trends


def test_unknown_unit_lists_the_names():
    assert units.names()[:2] == ["paper-unit", "unit-b"]
    with pytest.raises(InputError, match="unknown simulated unit 'unit-z'; choose one of paper"):
        units.get("unit-z")


# ----------------------------------------------------------------------------- determinism
def test_same_seed_same_arrays_whatever_the_chunk_size():
    p = simulate.soak(-10.0, 0.05)
    a = simulate.simulate_run(p, sample_rate_hz=200.0, seed=7)
    b = simulate.simulate_run(p, sample_rate_hz=200.0, seed=7, chunk_rows=997)
    c = simulate.simulate_run(p, sample_rate_hz=200.0, seed=8)
    for name in simulate.COLUMNS:
        assert np.array_equal(a[name], b[name]), name
    assert not np.array_equal(a.rate_dph, c.rate_dph)
    assert not np.array_equal(a.freq_hz, c.freq_hz)
    gen = simulate.simulate_run(p, sample_rate_hz=200.0, seed=np.random.default_rng(7))
    again = simulate.simulate_run(p, sample_rate_hz=200.0, seed=np.random.default_rng(7))
    assert np.array_equal(gen.rate_dph, again.rate_dph)


def test_bad_arguments():
    p = simulate.constant(20.0, 0.01)
    with pytest.raises(InputError, match="seed must be a non-negative integer"):
        simulate.simulate_run(p, seed=-1)
    with pytest.raises(InputError, match="sample_rate_hz must be finite and > 0"):
        simulate.simulate_run(p, sample_rate_hz=0.0)


# ----------------------------------------------------------------------------- files
def test_campaign_files_round_trip_and_refuse_to_overwrite(tmp_path):
    runs = simulate.soak_campaign([-20.0, 40.0], 0.05)
    calls = []
    written = simulate.simulate_files(
        runs, tmp_path / "soaks", sample_rate_hz=10.0, seed=4, chunk_rows=500,
        progress=lambda done, total: calls.append((done, total)),
    )
    assert calls[-1] == (3600.0, 3600.0)
    assert all(a[0] <= b[0] for a, b in itertools.pairwise(calls))
    assert [w.path for w in written] == [
        str(tmp_path / "soaks" / "soak_-20C.parquet"),
        str(tmp_path / "soaks" / "soak_40C.parquet"),
    ]
    assert [w.rows for w in written] == [1800, 1800]
    back = read(written[1].path)
    expected = simulate.simulate_run(
        runs[1], sample_rate_hz=10.0, seed=np.random.SeedSequence(4, spawn_key=(1,))
    )
    for name in simulate.COLUMNS:
        assert np.array_equal(back[name], expected[name]), name
    assert back.metadata.extra["setpoint_c"] == 40.0
    assert back.metadata.extra["spawn_key"] == [1]
    before = (tmp_path / "soaks" / "soak_40C.parquet").stat().st_mtime_ns
    with pytest.raises(OutputExistsError, match=r"exist: .*soak_-20C\.parquet.*--force"):
        simulate.simulate_files(runs, tmp_path / "soaks", sample_rate_hz=10.0, seed=5)
    assert (tmp_path / "soaks" / "soak_40C.parquet").stat().st_mtime_ns == before
    simulate.simulate_files(runs, tmp_path / "soaks", sample_rate_hz=10.0, seed=5, force=True)
    assert not np.array_equal(read(written[1].path).rate_dph, back.rate_dph)


def test_campaign_files_take_the_run_settings_whole(tmp_path):
    """``run=SimulatedRun(...)`` and the same fields by keyword write the same file; a
    keyword that is no field of it is refused."""
    runs = [simulate.constant(20.0, 0.01)]
    run = simulate.SimulatedRun(sample_rate_hz=10.0, seed=3, chunk_rows=100)
    (whole,) = simulate.simulate_files(runs, tmp_path / "whole", run=run)
    (keywords,) = simulate.simulate_files(runs, tmp_path / "keywords", sample_rate_hz=10.0,
                                          seed=3, chunk_rows=100)
    for name in simulate.COLUMNS:
        assert np.array_equal(read(whole.path)[name], read(keywords.path)[name]), name
    with pytest.raises(TypeError, match=r"\['sample_rate'\]"):
        simulate.simulate_files(runs, tmp_path / "bad", sample_rate=10.0)


@pytest.mark.parametrize("file_format", ["csv", "h5"])
def test_other_formats(tmp_path, file_format):
    runs = [simulate.constant(20.0, 0.01)]
    (written,) = simulate.simulate_files(runs, tmp_path, file_format, sample_rate_hz=10.0)
    assert written.path.endswith("constant_20C." + file_format)
    back = read(written.path)
    seed = np.random.SeedSequence(0, spawn_key=(0,))
    expected = simulate.simulate_run(runs[0], sample_rate_hz=10.0, seed=seed)
    for name in simulate.COLUMNS:
        assert np.allclose(back[name], expected[name], rtol=1e-15, atol=0.0), name


def test_output_path_errors(tmp_path):
    runs = simulate.soak_campaign([-20.0, 40.0], 0.01)
    with pytest.raises(InputError, match="is a file but 2 runs"):
        simulate.output_paths(runs, tmp_path / "x.parquet")
    with pytest.raises(InputError, match=r"suffix '\.csv' but the format is 'h5'"):
        simulate.output_paths(runs[:1], tmp_path / "x.csv", "h5")


# ----------------------------------------------------------------------------- rate table
def test_rate_table_truth_columns_follow_the_laws():
    # One imu-3 axis alone: a single-axis unit with a scale-factor law.
    gyro = units.get("imu-3").axes["x"]
    fs = 10.0
    table = standard_profiles.rate_table([-10.0, 40.0], [0.0, 100.0, -300.0], hold_s=60.0,
                                         soak_h=0.25)
    rec = simulate.simulate_run(table, gyro, sample_rate_hz=fs, seed=4, input_rate_dph=7.0,
                                chunk_rows=4001)
    assert rec.names == (*simulate.COLUMNS, "scale_ppm", "input_rate_dph")
    assert np.array_equal(rec["scale_ppm"], gyro.scale_factor_law.ppm(rec["resonator_c"]))
    expected_input = table.table_rate_dps(rec.time_s) * 3600.0 + 7.0
    assert np.array_equal(rec["input_rate_dph"], expected_input)
    assert set(np.unique(rec["input_rate_dph"])) == {7.0, 7.0 + 360000.0, 7.0 - 1080000.0}
    residual = rec.rate_dph - rec["input_rate_dph"] * (1 + rec["scale_ppm"] * 1e-6) - rec[
        "bias_dph"]
    # The residual is the gyro noise: its white part has the ARW's per-sample rms
    # N 60 sqrt(fs) (differences remove the slow parts), and it is the very noise of the
    # same seed with the table at rest (the input does not change the noise streams).
    white = np.std(np.diff(residual)) / np.sqrt(2.0)
    assert white == pytest.approx(gyro.gyro_noise.arw_deg_per_sqrt_h * 60 * np.sqrt(fs),
                                  rel=0.03)
    at_rest = simulate.simulate_run(
        profiles.Profile(tuple(replace(s, table_rate_dps=None) for s in table.segments),
                         start_c=table.start_c),
        gyro, sample_rate_hz=fs, seed=4, input_rate_dph=7.0,
    )
    assert np.array_equal(at_rest.freq_hz, rec.freq_hz)
    rest_residual = at_rest.rate_dph - 7.0 * (1 + at_rest["scale_ppm"] * 1e-6) - at_rest[
        "bias_dph"]
    np.testing.assert_allclose(residual, rest_residual, rtol=0, atol=1e-6)
    # At -300 °/s a few hundred ppm are hundreds of °/h of error, far above the noise.
    for hot in (rec["input_rate_dph"] < -1e6) & (rec.time_s < 1100), (
            rec["input_rate_dph"] < -1e6) & (rec.time_s > 1100):
        error = rec.rate_dph[hot] - rec["input_rate_dph"][hot] - rec["bias_dph"][hot]
        ppm = gyro.scale_factor_law.ppm(rec["resonator_c"][hot])
        assert abs(error.mean()) > 50.0
        assert error.mean() == pytest.approx(-1080007.0 * ppm.mean() * 1e-6, rel=0.01)


def test_rate_table_steps_at_the_segment_ends():
    fs = 5.0
    table = standard_profiles.rate_table([20.0], [10.0, -10.0], hold_s=30.0, soak_h=0.05)
    rec = simulate.simulate_run(table, sample_rate_hz=fs, seed=0)
    assert rec.metadata.input_rate_dph == 10.0 and "scale_ppm" not in rec.names
    steps = np.flatnonzero(np.diff(rec["input_rate_dph"])) + 1
    # Soak 180 s, then 30 s at +10 °/s, then -10 °/s to the end (210 s).
    assert rec.time_s[steps].tolist() == pytest.approx([180.0, 210.0], abs=1.0 / fs)
    assert len(rec) == round(240.0 * fs)


# ----------------------------------------------------------------------------- three axes
def test_imu3_axes_resonators_differ_during_a_ramp():
    imu = units.get("imu-3")
    rec = simulate.simulate_run(simulate.cooldown(20.0, -20.0, 3.0), "imu-3", sample_rate_hz=0.2,
                                seed=1)
    x, y, z = (rec[f"resonator_c_{a}"] for a in "xyz")
    ramp = (rec.time_s > 600.0) & (rec.time_s < 2400.0)
    # Cooling, the resonator with the shortest lag is the coldest: tau 2000 < 2700 < 3400 s.
    assert np.all(x[ramp] < y[ramp]) and np.all(y[ramp] < z[ramp])
    assert np.max(z - x) > 3.0
    # Each axis is its own unit behind the shared housing: the same as simulating it alone
    # (resonator and bias are deterministic).
    alone = simulate.simulate_run(simulate.cooldown(20.0, -20.0, 3.0), imu.axes["z"],
                                  sample_rate_hz=0.2, seed=1)
    np.testing.assert_allclose(z, alone["resonator_c"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(rec["bias_dph_z"], alone["bias_dph"], rtol=0, atol=1e-12)
    for axis, gyro in imu.axes.items():
        np.testing.assert_allclose(
            rec[f"freq_hz_{axis}"] - gyro.frequency_law.frequency_hz(rec[f"resonator_c_{axis}"]),
            0.0, atol=6 * gyro.frequency_noise_hz,
        )
    assert rec.metadata.extra["axis_input_rate_dph"] == imu.input_rate_dph
    assert rec.metadata.input_rate_dph == 0.0


def test_imu3_rate_table_rotates_one_axis_at_a_time():
    imu = units.get("imu-3")
    table = standard_profiles.rate_table([0.0], [50.0, -50.0], hold_s=20.0, soak_h=0.02,
                                         axes=imu.axis_names)
    rec = simulate.simulate_run(table, imu, sample_rate_hz=2.0, seed=3)
    assert rec.names == simulate.run_columns(table, imu)
    turning = {}
    for axis in imu.axis_names:
        table_dph = rec[f"input_rate_dph_{axis}"] - imu.input_rate_dph[axis]
        turning[axis] = np.abs(table_dph) > 0
        assert set(np.unique(table_dph)) == {0.0, 180000.0, -180000.0}
        assert turning[axis].sum() == 2 * 20 * 2  # two 20 s holds at 2 Hz
    # The holds are disjoint and in order x, y, z.
    assert not np.any(turning["x"] & turning["y"]) and not np.any(turning["y"] & turning["z"])
    starts = [np.flatnonzero(turning[a])[0] for a in "xyz"]
    assert starts == sorted(starts) and starts[0] == round(0.02 * 3600 * 2)


def test_imu3_same_seed_same_arrays_and_independent_axes():
    p = simulate.constant(20.0, 0.5)
    a = simulate.simulate_run(p, "imu-3", sample_rate_hz=10.0, seed=5)
    b = simulate.simulate_run(p, "imu-3", sample_rate_hz=10.0, seed=5, chunk_rows=1234)
    c = simulate.simulate_run(p, "imu-3", sample_rate_hz=10.0, seed=6)
    for name in a.names:
        assert np.array_equal(a[name], b[name]), name
    assert not np.array_equal(a["rate_dph_x"], c["rate_dph_x"])
    imu = units.get("imu-3")
    noise = {}
    for axis in imu.axis_names:
        k = 1 + a[f"scale_ppm_{axis}"] * 1e-6
        noise[axis] = a[f"rate_dph_{axis}"] - imu.input_rate_dph[axis] * k - a[f"bias_dph_{axis}"]
        white = np.std(np.diff(noise[axis])) / np.sqrt(2.0)
        arw = imu.axes[axis].gyro_noise.arw_deg_per_sqrt_h
        assert white == pytest.approx(arw * 60 * np.sqrt(10.0), rel=0.03)
    # 18,000 samples: independent streams correlate by ~1/sqrt(n) = 0.007.
    for u, v in itertools.combinations("xyz", 2):
        assert abs(np.corrcoef(np.diff(noise[u]), np.diff(noise[v]))[0, 1]) < 0.04
        assert abs(np.corrcoef(np.diff(a[f"freq_hz_{u}"]), np.diff(a[f"freq_hz_{v}"]))[0, 1]) < 0.04


@pytest.mark.parametrize("kind", standard_profiles.KINDS)
def test_imu3_runs_every_standard_profile(kind, tmp_path):
    options = {"hours": 0.7} if kind in ("cooldown", "warmup", "constant") else {}
    if kind == "soak":
        options = {"setpoints_c": [0.0], "hours": 0.05}
    if kind == "ramp":
        options = {"start_c": 20.0, "end_c": 22.0}
    if kind == "ratetable":
        options = {"setpoints_c": [25.0], "hours": 0.05, "rates_dps": [1.0], "rate_hold_s": 10}
    (p,) = standard_profiles.build(kind, axes=("x", "y", "z"), **options)
    written = simulate.simulate_to_file(p, tmp_path / "run.csv", "imu-3", sample_rate_hz=0.5)
    header = next(line for line in (tmp_path / "run.csv").read_text().splitlines()
                  if not line.startswith("#"))
    assert tuple(header.split(",")) == simulate.run_columns(p, "imu-3")
    assert written.rows == simulate.campaign.row_count(p, 0.5)
    assert ("input_rate_dph_y" in header) == (kind == "ratetable")
    assert "rate_dph_z" in header and "scale_ppm_x" in header and "freq_hz," not in header


def test_rate_table_axes_must_match_the_unit():
    single = standard_profiles.rate_table([20.0], [1.0], hold_s=10, soak_h=0.01)
    three = standard_profiles.rate_table([20.0], [1.0], hold_s=10, soak_h=0.01, axes=("x", "w"))
    with pytest.raises(InputError, match="without naming an axis, but unit 'imu-3' has axes"):
        simulate.simulate_run(single, "imu-3", sample_rate_hz=1.0)
    with pytest.raises(InputError, match=r"turns axis\(es\) \['w'\], not axes of unit 'imu-3'"):
        simulate.simulate_run(three, "imu-3", sample_rate_hz=1.0)
    with pytest.raises(InputError, match="has a single axis; drop the segments' axis"):
        simulate.simulate_run(three, "paper-unit", sample_rate_hz=1.0)
    with pytest.raises(InputError, match="must give a rate for each axis of unit 'imu-3'"):
        simulate.simulate_run(single, "imu-3", input_rate_dph={"x": 1.0})
    rec = simulate.simulate_run(simulate.constant(20.0, 0.01), "imu-3", sample_rate_hz=1.0,
                                input_rate_dph=3.0)
    assert rec.metadata.extra["axis_input_rate_dph"] == {"x": 3.0, "y": 3.0, "z": 3.0}


def test_imu3_file_reads_back_axis_by_axis(tmp_path):
    from hrgtc.recording import axis_names, axis_view

    imu = units.get("imu-3")
    table = standard_profiles.rate_table([15.0], [20.0], hold_s=10.0, soak_h=0.01,
                                         axes=imu.axis_names)
    written = simulate.simulate_to_file(table, tmp_path / "t.parquet", imu, sample_rate_hz=2.0,
                                        seed=9)
    rec = read(written.path)
    library = simulate.simulate_run(table, imu, sample_rate_hz=2.0, seed=9)
    assert axis_names(rec.names) == ("x", "y", "z")
    for axis in imu.axis_names:
        view = axis_view(rec, axis)
        assert view.metadata.input_rate_dph == imu.input_rate_dph[axis]
        assert np.array_equal(view["input_rate_dph"], library[f"input_rate_dph_{axis}"])
        assert np.array_equal(view.rate_dph, library[f"rate_dph_{axis}"])
        assert np.array_equal(view["scale_ppm"], library[f"scale_ppm_{axis}"])
