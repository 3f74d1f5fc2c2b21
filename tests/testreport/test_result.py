"""The test report's figures on a simulated campaign with known truth.

The campaign (conftest.py): the paper-unit of src/hrgtc/simulate/units.py at 1 Hz, five
turn-ons at 20 °C with known turn-on offsets and a warm-up, soaks at -20, 0, 20 and 40 °C
that start settled, a cool-down sweep, and the unit's model (a golden model file);
optionally a rate table of the imu-3's x axis, whose scale-factor law is known.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from hrgtc.recording import read
from hrgtc.simulate.units import get
from hrgtc.testreport import FIGURES, test_report
from hrgtc.testreport.spec import NOT_MEASURED

from testreport_campaign import SOAK_SETPOINTS_C, TURN_ON_OFFSETS_DPH

SETTLE_S = 1200.0  # the manifest's settle_s


def _turn_on_means(paths, earth_dph):
    """Each turn-on's mean output after settle_s less the Earth rate, from the samples."""
    means = []
    for path in paths:
        run = read(path)
        time = run.time_s - run.time_s[0]
        means.append(float(np.mean(run.rate_dph[time >= SETTLE_S])) - earth_dph)
    return np.array(means)


def test_every_figure_is_reported_once(report):
    assert [f.name for f in report.figures] == [n for n in FIGURES if n in
                                               {f.name for f in report.figures}]
    assert {f.name for f in report.figures} == set(FIGURES)


def test_bias_repeatability_is_the_1_sigma_of_the_turn_on_means(campaign, report):
    """An independent numpy computation from the samples (10 °/h: the simulator's input,
    which the manifest's latitude makes the Earth rate on an up axis)."""
    means = _turn_on_means(campaign.turn_ons, 10.0)
    assert report.earth_rate_dph == pytest.approx(10.0, abs=1e-9)
    figure = report.figure("bias_repeatability_dph")
    assert figure.value == pytest.approx(float(np.std(means, ddof=1)), rel=1e-9)
    assert figure.dof == 4
    assert figure.u == pytest.approx(figure.value / math.sqrt(8.0))
    assert report.figure("bias_dph").value == pytest.approx(float(np.mean(means)), rel=1e-9)


def test_the_turn_on_biases_are_the_true_biases_earth_rate_removed(campaign, report):
    """The truth: the simulator's bias (its law plus the offsets added) over the same rows.
    The noise of a 1 h mean (bias instability 0.22 °/h, rate random walk) stays within
    1 °/h; the Earth rate is 10 °/h, so a missing, doubled or reversed subtraction fails."""
    for turn_on, path in zip(report.turn_ons, campaign.turn_ons, strict=True):
        run = read(path)
        time = run.time_s - run.time_s[0]
        truth = float(np.mean(run["bias_dph"][time >= SETTLE_S]))
        assert turn_on.bias_dph == pytest.approx(truth, abs=1.0)
    spread = float(np.std(TURN_ON_OFFSETS_DPH, ddof=1))
    figure = report.figure("bias_repeatability_dph")
    assert figure.interval[0] <= spread <= figure.interval[1]


def test_bias_temperature_sensitivity_is_the_laws_slope(report):
    """The least-squares slope of the simulator's bias law over the soaks' temperatures
    (steady state: no gradient), within the figure's expanded uncertainty."""
    law = get("paper-unit").bias_law
    t = np.array(SOAK_SETPOINTS_C)
    c1, c2, c3 = law.temperature_dph
    d = t - law.reference_c
    truth = float(np.polyfit(t, law.bias0_dph + c1 * d + c2 * d**2 + c3 * d**3, 1)[0])
    figure = report.figure("bias_temperature_sensitivity_dph_per_c")
    assert figure.interval[0] <= truth <= figure.interval[1]
    assert figure.expanded[0] < 0.5 * abs(truth)  # a measurement, not a band of everything
    assert figure.dof == len(SOAK_SETPOINTS_C) - 2


def test_compensation_removes_the_temperature_sensitivity(report):
    raw = report.figure("bias_temperature_sensitivity_dph_per_c").value
    after = report.figure("bias_temperature_sensitivity_compensated_dph_per_c").value
    assert abs(after) < 0.2 * abs(raw)


def test_scale_factor_is_not_measured_without_a_rate_table(campaign, tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text("[limits.scale_factor_error_ppm]\nmax = 100\n"
                    "[limits.scale_factor_temperature_sensitivity_ppm_per_c]\nmax = 1\n",
                    encoding="utf-8")
    judged = test_report(campaign.manifest, spec)
    for name in ("scale_factor_error_ppm", "scale_factor_temperature_sensitivity_ppm_per_c"):
        figure = judged.figure(name)
        assert figure.value is None and figure.verdict == NOT_MEASURED
        assert "no rate-table run" in figure.reason
        assert figure.to_dict()["verdict"] == "not measured"
    assert judged.verdict == NOT_MEASURED  # limited figures not measured: no accept, no fail


def test_scale_factor_from_a_rate_table_is_the_laws(table_campaign):
    """The imu-3 x axis's scale-factor truth (its ``scale_ppm`` column) over the holds of
    the plateau nearest 20 °C, and its slope over the plateaus."""
    report = test_report(table_campaign.manifest)
    run = read(table_campaign.rate_table)
    figure = report.figure("scale_factor_error_ppm")
    plateau = min(report.plateaus, key=lambda p: abs(p.temperature_c - 20.0))
    near = np.abs(run["housing_c"] - plateau.temperature_c) < 1.0
    moving = np.abs(run["input_rate_dph"] - 10.0) > 1.0
    truth = float(np.mean(run["scale_ppm"][near & moving]))
    assert figure.value == pytest.approx(truth, abs=max(figure.expanded[1], 1.0))
    temperatures = [p.temperature_c for p in report.plateaus]
    truths = [float(np.mean(run["scale_ppm"][(np.abs(run["housing_c"] - t) < 1.0) & moving]))
              for t in temperatures]
    slope = report.figure("scale_factor_temperature_sensitivity_ppm_per_c")
    assert slope.value == pytest.approx(float(np.polyfit(temperatures, truths, 1)[0]),
                                        abs=max(slope.expanded[1], 0.05))


def test_allan_figures_carry_the_chi_squared_interval_at_ks_coverage(report):
    arw = report.figure("angle_random_walk_deg_per_rt_h")
    assert arw.value is not None
    low, high = arw.interval
    assert low < arw.value < high and arw.expanded[0] != arw.expanded[1]
    assert report.allan["raw"].confidence == pytest.approx(math.erf(2.0 / math.sqrt(2.0)))
    # the simulator's ARW (units.py: 0.024 °/√h) inside the interval
    assert low <= get("paper-unit").gyro_noise.arw_deg_per_sqrt_h <= high


def test_one_axis_of_a_multi_axis_file(tmp_path):
    """``file_axis`` reads one axis of the imu-3 (x north at 40° N: Ω cos 40°); its turn-on
    biases are that axis's true bias."""
    from hrgtc.recording import write
    from hrgtc.simulate import simulate_run
    from hrgtc.simulate.standard_profiles import constant

    runs = []
    for seed in (1, 2):
        path = write(simulate_run(constant(20.0, 1.0), "imu-3", sample_rate_hz=1.0, seed=seed),
                     tmp_path / f"day{seed}.parquet")
        runs.append(f'[[runs]]\nfile = "{path.name}"\nrole = "turn-on"\n')
    manifest = tmp_path / "campaign.toml"
    manifest.write_text('[unit]\nserial = "IMU-1"\nfirmware = "1"\nfile_axis = "x"\n'
                        '[site]\nlatitude_deg = 40.0\naxis = "north"\n[settings]\n'
                        'settle_s = 600\n' + "".join(runs), encoding="utf-8")
    report = test_report(manifest)
    assert report.earth_rate_dph == pytest.approx(15.041067 * math.cos(math.radians(40.0)),
                                                  rel=1e-6)
    for turn_on, seed in zip(report.turn_ons, (1, 2), strict=True):
        run = read(tmp_path / f"day{seed}.parquet")
        time = run.time_s - run.time_s[0]
        truth = float(np.mean(run["bias_dph_x"][time >= 600.0]))
        assert turn_on.bias_dph == pytest.approx(truth, abs=1.0)
