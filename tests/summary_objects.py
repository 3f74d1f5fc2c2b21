"""One real object of every class with a ``summary()``, built from the shared campaigns.

``every_result(paper, imu, folder)`` -> {name: object}: the paper-unit's calibration (its
thermometer, drift model, training accounting, plateaus), an evaluation of its held-out
warm-up (Allan curves, noise terms, heating/cooling) and of its cool-down (the demo's
table), the three-axis imu-3's calibration (scale factor, rate-table segments, an
instrument compensator) and an evaluation of its held-out rate table, an in-field update of
the paper-unit's model, a recording's info (validation, time axis), the simulator's units,
profile and written files, and the small results built from arrays (Hald's data for the
stepwise regression, a spike, a slow channel, a temperature map, a thermometer prior, a
transient). ``tests/test_summaries.py`` checks each ``summary()``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

HALD = np.array([
    [7, 26, 6, 60, 78.5], [1, 29, 15, 52, 74.3], [11, 56, 8, 20, 104.3],
    [11, 31, 8, 47, 87.6], [7, 52, 6, 33, 95.9], [11, 55, 9, 22, 109.2],
    [3, 71, 17, 6, 102.7], [1, 31, 22, 44, 72.5], [2, 54, 18, 22, 93.1],
    [21, 47, 4, 26, 115.9], [1, 40, 23, 34, 83.8], [11, 66, 9, 12, 113.3],
    [10, 68, 8, 12, 109.4]], dtype=np.float64)


def every_result(paper: Any, imu: Any, folder: Path) -> dict[str, Any]:
    """Every result kind with a ``summary()``, by a name saying what it is."""
    out: dict[str, Any] = {}
    out.update(_paper(paper))
    out.update(_instrument(imu))
    out.update(_recording(paper, folder))
    out.update(_small())
    return out


def _paper(paper: Any) -> dict[str, Any]:
    from hrgtc.evaluation import evaluate
    from hrgtc.pipeline.calibration import calibrate
    from hrgtc.pipeline.demo import DemoResult
    from hrgtc.pipeline.demo_history import HistoryDemo
    from hrgtc.recording import read
    from hrgtc.thermometry.plateaus import find_plateaus

    result = calibrate(paper.soaks, [paper.cooldown], [paper.warmup])
    model = result.model
    evaluation = evaluate(model, paper.warmup).axis
    training = evaluate(model, paper.cooldown).axis
    plateau = find_plateaus(read(paper.soaks[0]))[0]
    return {"AxisCalibration": result.axis, "DriftModel": model.drift,
            "Thermometer": model.thermometer, "Accounting": model.drift.accounting,
            "Plateau": plateau, "Evaluation": evaluation,
            "AllanResult": evaluation.allan["compensated"],
            "NoiseTerms": evaluation.noise["compensated"],
            "DirectionStats": evaluation.directions,
            # the demo's figures (its files are the demo's business, not the summary's)
            "DemoResult": DemoResult(Path("demo-out"), result, training, evaluation, None,
                                     Path("model.json"), Path("report.html"), ()),
            # the demo's history part: two fits and the held-out run evaluated with each
            # (here the paper-unit's: the summary's figures, not unit-play's campaign)
            "HistoryDemo": HistoryDemo(result, result, True, 2.0, {"2": 0.3, "without": 0.4},
                                       training, evaluation, Path("unit-play.json"),
                                       Path("report.html")),
            "UpdateResult": _update(model)}


def _update(model: Any) -> Any:
    """An in-field update of the paper-unit's model from a field day of the aged unit."""
    from hrgtc.simulate import simulate_run
    from hrgtc.update import UpdateSettings

    from field_ageing import INPUT_RATE_DPH, aged_unit, field_profile

    # seed 8: a day whose update is applied
    day = simulate_run(field_profile(), aged_unit(), sample_rate_hz=2.0, seed=8)
    return model.update(day, UpdateSettings(input_rate_dph=INPUT_RATE_DPH))


def _instrument(imu: Any) -> dict[str, Any]:
    from hrgtc.compensate import Compensator
    from hrgtc.drift.rate_segments import segment_scale_errors
    from hrgtc.evaluation import evaluate
    from hrgtc.pipeline.calibration import RateTables, calibrate
    from hrgtc.recording import axis_view, read

    calibration = calibrate(imu.soaks, [imu.cooldown], [imu.warmup],
                            rate_tables=RateTables([imu.rate_table], [imu.rate_table_heldout]))
    compensator = Compensator(calibration.model)
    compensator.transform(read(imu.warmup))
    table = axis_view(read(imu.rate_table), "x")
    return {"Calibration": calibration,
            "RunEvaluation": evaluate(calibration.model, imu.rate_table_heldout),
            "ScaleFactorModel": calibration.model.axes["x"].scale_factor,
            "SegmentScaleErrors": segment_scale_errors(table),
            "Compensator": compensator}


def _recording(paper: Any, folder: Path) -> dict[str, Any]:
    from hrgtc.core.timeline import Timeline
    from hrgtc.recording import describe, read
    from hrgtc.recording.motion import recording_motion
    from hrgtc.simulate import simulate_files, units
    from hrgtc.simulate import standard_profiles as profiles

    info = describe(paper.warmup)
    run = read(paper.warmup)
    burst = np.concatenate([np.arange(5.0) + 60.0 * k for k in range(25)])
    written = simulate_files([profiles.soak(20.0, 0.05)], folder / "written", "csv",
                             unit="paper-unit", sample_rate_hz=1.0, seed=3)
    return {"RecordingInfo": info, "ValidationReport": info.validation,
            "Timeline": Timeline.from_time(burst), "MotionMask": recording_motion(run),
            "Unit": units.get("paper-unit"), "MultiAxisUnit": units.get("imu-3"),
            "Profile": profiles.warmup(-20.0, 20.0, 5.0), "WrittenFile": written[0],
            "TestReport": _test_report(paper, folder)}


def _test_report(paper: Any, folder: Path) -> Any:
    """A test report of the paper campaign's files: a soak at 20 °C as the turn-on, three
    soaks, the cool-down as the sweep (docs/guide/test-report.md)."""
    from hrgtc.testreport import test_report

    runs = [(paper.soaks[4], "turn-on", 1200), *((paper.soaks[k], "soak", 14400)
                                                 for k in (0, 2, 4)),
            (paper.cooldown, "sweep", 0)]
    manifest = folder / "campaign.toml"
    manifest.write_text('[unit]\nserial = "SN-1"\nfirmware = "1"\n[site]\nlatitude_deg = '
                        '41.6705\naxis = "up"\n' + "".join(
                            f'[[runs]]\nfile = "{path}"\nrole = "{role}"\nsettle_s = {settle}\n'
                            for path, role, settle in runs), encoding="utf-8")
    return test_report(manifest)


def _small() -> dict[str, Any]:
    from hrgtc.drift.cross_validation import CrossValidation
    from hrgtc.drift.stepwise import StepwiseRules, stepwise
    from hrgtc.evaluation.allan import allan_deviation
    from hrgtc.evaluation.metrics import residual_against_truth
    from hrgtc.evaluation.noise_model import fit_noise_model
    from hrgtc.fleet.run import FleetRun
    from hrgtc.fleet.tasks import UnitOutcome
    from hrgtc.recording.resample import fill_slow_channels
    from hrgtc.recording.spikes import RobustSpikeFilter
    from hrgtc.thermometry.prior import ThermometerPrior
    from hrgtc.thermometry.reference import TemperatureMap
    from hrgtc.thermometry.settling import fit_transient
    from hrgtc.thermometry.thermometer import fit

    hald = stepwise(HALD[:, :4], HALD[:, 4], rules=StepwiseRules(penter=0.06))
    t = np.arange(1000) / 10.0
    housing = 20.0 - 0.01 * t
    housing[np.arange(1000) % 10 != 0] = np.nan
    _, slow = fill_slow_channels({"time_s": t, "rate_dph": np.sin(t), "freq_hz": 4424.0 + 0 * t,
                                  "housing_c": housing}, "hold")
    rng = np.random.default_rng(5)
    truth = rng.normal(size=4000)
    residual = residual_against_truth(bias_model_dph=truth + 0.01 * rng.normal(size=4000),
                                      true_bias_dph=truth, sample_rate_hz=10.0)
    spikes = RobustSpikeFilter("drop", source="run.csv")
    freq = 4424.0 + 0.001 * rng.normal(size=2000)
    freq[700] += 5.0
    spikes.apply({"time_s": np.arange(2000) / 10.0, "freq_hz": freq}, 0)
    setpoints = np.array([-20.0, -10.0, 0.0, 10.0, 20.0, 30.0, 40.0])
    thermometers = [fit(setpoints, 4424.0 - (0.5 + 0.01 * k) * setpoints
                        + 1e-4 * k * setpoints ** 2) for k in range(8)]
    tau = np.arange(0.0, 20000.0, 10.0)
    return {
        "StepwiseResult": hald, "OLSResult": hald.result,
        "CrossValidation": CrossValidation(("f", "df"), {"cool": 0.0123, "warm": 0.0456}, 0.02,
                                           0.03, 0.0333, sources=("cool", "warm")),
        "ResidualResult": residual, "SlowChannels": slow, "RobustSpikeFilter": spikes,
        "TemperatureMap": TemperatureMap(0.005, 24.0, 16, 120.0, 0.2, 0.4, 25,
                                         (-2400.0, -300.0), "log.csv"),
        "ThermometerPrior": ThermometerPrior.from_thermometers(thermometers),
        "TransientFit": fit_transient(tau, 4424.0 + 0.2 * np.exp(-tau / 3000.0)),
        "FleetRun": FleetRun((UnitOutcome("a", "ok"), UnitOutcome("b", "failed")), 12.5,
                             "local cluster of 2 workers", workers_died=1, retried=("b",)),
        "NoiseModel": fit_noise_model(allan_deviation(rng.normal(size=4096), 1.0,
                                                      confidence=0.683), bootstrap=50),
    }
