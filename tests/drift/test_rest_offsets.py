"""Training at rest, nuisance offsets, centring on the data, guarded selection (issue 20).

The runs are a MEMS axis with a temperature sensor as its thermometer (f is then a
temperature), generated here with a known bias law, so every assertion is against truth.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.core.errors import CalibrationError
from hrgtc.drift.fit_stages import TrainingReading
from hrgtc.recording import Metadata, Recording
from hrgtc.thermometry import identity

THERMOMETER = identity((-10.0, 40.0))


def mems_run(seed, hours=8.0, fs=1.0, start_c=25.0, end_c=5.0, slope=36.0, curve=0.0,
             noise_dph=30.0, walk_dph=0.0, handling=(), hand_c=27.8, orientations=None):
    """A MEMS axis at rest, 4 °/s from zero: bias = 14400 + slope·(T − 15) + curve·(T − 15)²
    [°/h] (+ a constant per orientation), white noise and an optional random walk.

    ``handling``: start times [s] of 30 s handling bursts, the rate swinging by 300 °/s and
    the sensor reading ``hand_c`` (a warm hand). ``orientations``: (offsets [°/h], unit
    gravity vectors), one per third of the run, logged as accel_x/y/z [m/s²].
    Returns the recording and the truth mask of the handling.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 1.0 / fs)
    x = t / t[-1]
    temperature = start_c + (end_c - start_c) * (1 - np.cos(np.pi * x)) / 2
    bias = 4.0 * 3600.0 + slope * (temperature - 15.0) + curve * (temperature - 15.0) ** 2
    rate = bias + noise_dph * rng.standard_normal(t.size)
    if walk_dph:
        rate += np.cumsum(walk_dph * rng.standard_normal(t.size))
    columns = {}
    if orientations is not None:
        offsets, vectors = orientations
        part = np.minimum((x * len(offsets)).astype(int), len(offsets) - 1)
        rate += np.asarray(offsets)[part]
        gravity = 9.81 * np.asarray(vectors, dtype=float)[part]
        gravity += 0.01 * rng.standard_normal(gravity.shape)
        columns = {f"accel_{a}": gravity[:, k] for k, a in enumerate("xyz")}
    sensor = temperature.copy()
    moving = np.zeros(t.size, dtype=bool)
    for start in handling:
        inside = (t >= start) & (t < start + 30.0)
        rate[inside] += 3600.0 * 300.0 * np.sin(np.linspace(0, 3 * np.pi, inside.sum()))
        sensor[inside] = hand_c
        moving |= inside
    recording = Recording({"time_s": t, "freq_hz": sensor, "rate_dph": rate,
                           "resonator_c": temperature, "bias_dph": bias, **columns},
                          Metadata(sample_rate_hz=fs, unit="mems"), source=f"mems-{seed}")
    return recording, moving


def quiet_fit(*args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return drift.fit(*args, **kwargs)


TERMS = ("f", "f^2", "f^3", "df")


def test_a_recording_with_handling_gives_the_model_of_its_still_samples():
    handled, moving = mems_run(1, handling=np.arange(1800.0, 27000.0, 3600.0))
    model = quiet_fit([handled], THERMOMETER, terms=TERMS)
    assert model.selected == ("f",)
    assert model.coefficients["f"] == pytest.approx(36.0, abs=3 * model.standard_errors["f"])
    # every handled sample and its guard time left out, and counted
    # (at 1 Hz a variance block is 32 s: a burst marks at most two partial blocks)
    assert moving.sum() <= model.n_not_at_rest <= moving.sum() + 7 * (5 + 1 + 2 * 32)
    # the trained range is that of the still samples (25 °C at the start), not the hand's 27.8
    top = model.ranges["f"][1] + model.settings.reference_freq_hz
    assert top == pytest.approx(25.0, abs=0.05)
    # the same file without the check: the handling drives the fit and the range
    kept = quiet_fit([handled], THERMOMETER, terms=TERMS, reading=TrainingReading(motion="keep"))
    assert kept.ranges["f"][1] + kept.settings.reference_freq_hz > 27.0
    assert abs(kept.coefficients.get("f", 0.0) - 36.0) > 10 * model.standard_errors["f"]
    with pytest.raises(CalibrationError, match="not at rest"):
        quiet_fit([handled], THERMOMETER, terms=TERMS, reading=TrainingReading(motion="error"))


def test_the_still_model_matches_the_fit_of_the_same_run_without_handling():
    clean, _ = mems_run(4)
    handled, _ = mems_run(4, handling=(5000.0, 15000.0))
    a = quiet_fit([clean], THERMOMETER, terms=TERMS)
    b = quiet_fit([handled], THERMOMETER, terms=TERMS)
    assert a.selected == b.selected
    assert b.coefficients["f"] == pytest.approx(a.coefficients["f"], abs=a.standard_errors["f"])


def test_three_orientations_with_different_offsets_leave_the_slope_unbiased():
    orientations = ([300.0, -200.0, 100.0], [[0, 0, 1], [1, 0, 0], [0, -1, 0]])
    run, _ = mems_run(2, orientations=orientations)
    model = quiet_fit([run], THERMOMETER, terms=("f", "f^2", "df"))
    assert model.offset_mode == "orientation"
    assert model.selected == ("f",)
    assert model.coefficients["f"] == pytest.approx(36.0, abs=3 * model.standard_errors["f"])
    offsets = model.offsets_dph
    assert len(offsets) == 3 and len(model.orientations) == 3
    assert offsets["orientation 0"] - offsets["orientation 1"] == pytest.approx(500.0, abs=5.0)
    assert offsets["orientation 0"] - offsets["orientation 2"] == pytest.approx(200.0, abs=5.0)
    # a known orientation gives its offset back; one never seen in training is unknown
    assert model.orientation_offset([0.0, 0.0, 9.81]) == pytest.approx(offsets["orientation 0"])
    assert model.orientation_offset([0.0, 9.81, 0.0]) is None
    back = drift.DriftModel.from_dict(model.to_dict())
    assert back.offsets_dph == offsets and back.orientations == model.orientations
    # one intercept for all: the temperature terms absorb the orientation offsets
    single = quiet_fit([run], THERMOMETER, terms=("f", "f^2", "df"), offsets="none")
    assert abs(single.coefficients.get("f", 0.0) - 36.0) > 10 * model.standard_errors["f"]


def test_an_offset_per_run_keeps_restarts_out_of_the_slope():
    a, _ = mems_run(5, start_c=25.0, end_c=15.0, hours=4.0)
    b, _ = mems_run(6, start_c=15.0, end_c=5.0, hours=4.0)
    b = Recording({**b.columns, "rate_dph": b.rate_dph + 400.0}, b.metadata, "restart")
    model = quiet_fit([a, b], THERMOMETER, terms=("f",), offsets="run")
    assert model.coefficients["f"] == pytest.approx(36.0, abs=3 * model.standard_errors["f"])
    assert model.offsets_dph["run restart"] - model.offsets_dph["run mems-5"] == \
        pytest.approx(400.0, abs=5.0)


@pytest.mark.parametrize("scale, offset", [(1.0, 273.15), (1.8, 32.0), (-40.0, 26000.0)])
def test_an_arbitrary_temperature_offset_and_scale_give_the_same_compensation(scale, offset):
    run, _ = mems_run(3, curve=1.5)
    moved = Recording({**run.columns, "freq_hz": run.freq_hz * scale + offset}, run.metadata,
                      run.source)
    low, high = sorted((-10.0 * scale + offset, 40.0 * scale + offset))
    terms = ("f", "f^2", "f^3", "df", "f*df")
    a = quiet_fit([run], THERMOMETER, terms=terms)
    b = quiet_fit([moved], identity((low, high)), terms=terms)
    assert a.selected == b.selected and "f^2" in a.selected
    np.testing.assert_allclose(b.predict_recording(moved), a.predict_recording(run),
                               rtol=0, atol=1e-9)


def test_guarded_selection_does_not_extrapolate_high_order_terms():
    # truth linear in T; the training run spans 12-18 °C with a random walk in the bias,
    # which F-tests on 10 s means read as curvature; the validation spans 5-25 °C
    wide = identity((0.0, 30.0))
    check, _ = mems_run(99, start_c=25.0, end_c=5.0, hours=8.0)
    truth = check["bias_dph"]

    def error(model):
        residual = model.predict_recording(check) - truth
        return float(np.std(residual))

    gains = []
    for seed in range(11, 19):
        train, _ = mems_run(seed, start_c=18.0, end_c=12.0, hours=8.0, walk_dph=1.0)
        # plain MATLAB stepwise: no marginality either (a square may enter without its line)
        plain = quiet_fit([train], wide, terms=TERMS, select="stepwise", hierarchical=False)
        guarded = quiet_fit([train], wide, terms=TERMS)
        assert set(guarded.selected) <= set(plain.selected)
        assert error(guarded) <= error(plain) * 1.001  # never worse held out
        gains.append(error(plain) / error(guarded))
        if seed in (12, 15):  # the trap is real, and the guard gets out of it
            assert {"f^2", "f^3"} & set(plain.selected)
            assert not {"f^2", "f^3"} & set(guarded.selected)
            assert guarded.pruning["folds"] == "coldest and hottest time blocks"
            assert error(guarded) < 0.6 * error(plain)
    assert sum(g > 1.2 for g in gains) >= 4


def test_compensation_applies_known_orientations_and_reports_an_unknown_one():
    from hrgtc.compensate import Compensator
    from hrgtc.core.errors import HrgtcWarning
    from hrgtc.model import AxisModel, Model

    orientations = ([300.0, -200.0, 100.0], [[0, 0, 1], [1, 0, 0], [0, -1, 0]])
    run, _ = mems_run(2, orientations=orientations)
    model = Model.single(
        AxisModel(thermometer=THERMOMETER, drift=quiet_fit([run], THERMOMETER, terms=("f", "f^2",
            "df"))), unit="mems")
    later, _ = mems_run(7, orientations=orientations)
    out = Compensator(model).transform(later)
    residual = out["bias_model_dph"] - later["bias_dph"]
    parts = np.array_split(residual[600:], 3)  # after the df/dt filter settles
    for part, offset in zip(parts, orientations[0], strict=True):
        assert np.median(part) == pytest.approx(offset, abs=3.0)  # each orientation's own
    # a fourth orientation never seen: the training mean, counted and warned about
    turned, _ = mems_run(8, orientations=([0.0], [[0, 1, 0]]))
    compensator = Compensator(model)
    with pytest.warns(HrgtcWarning, match="never seen in training"):
        compensator.transform(turned)
    assert compensator.axis.unknown_orientation == len(turned)
    # a mask of the samples at rest (the motion detector's) leaves the others out of the
    # count: a unit mid-rotation is in no orientation; the rest are still reported
    at_rest = np.arange(len(turned)) % 3 != 0
    compensator = Compensator(model)
    with pytest.warns(HrgtcWarning, match="never seen in training"):
        masked = compensator.transform(turned, at_rest)
    assert compensator.axis.unknown_orientation == np.count_nonzero(at_rest)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HrgtcWarning)
        unmasked = Compensator(model).transform(turned)
    np.testing.assert_array_equal(masked["bias_model_dph"], unmasked["bias_model_dph"])
    # nothing at rest in an unknown orientation: no warning, no count
    compensator = Compensator(model)
    with warnings.catch_warnings():
        warnings.simplefilter("error", HrgtcWarning)
        compensator.transform(turned, np.zeros(len(turned), dtype=bool))
    assert compensator.axis.unknown_orientation == 0


def test_windows_never_span_left_out_samples_across_chunks():
    from hrgtc.drift.features import FeatureSettings, parse_terms
    from hrgtc.drift.windows import Windowing, window_means

    run, _ = mems_run(9, hours=1.0)
    n = len(run)
    keep = np.ones(n, dtype=bool)
    keep[1005:1012] = False  # inside the 11th window of 100 samples
    keep[2995:3005] = False  # across the 30th/31st boundary
    settings = FeatureSettings(reference_freq_hz=15.0, sample_rate_hz=1.0, warmup_s=0.0)
    chunks = [run.slice(a, a + 777) for a in range(0, n, 777)]
    windows = window_means([lambda: iter(chunks)], settings, parse_terms(["f"]), Windowing(100.0),
                           keep=[keep])
    t = run.time_s
    # the run ends in a partial window of 95 samples (3505 to 3599 s): at least half a
    # window, so it is kept (hrgtc.core.timeline's rule at a segment's end); a partial
    # window before a left-out stretch is dropped
    assert windows.time_s[-1] == pytest.approx(np.mean(t[3505:]))
    starts = windows.time_s[:-1] - 49.5  # each whole window's first sample (1 Hz, 100)
    for start in starts:
        rows = (t >= start) & (t < start + 100.0)
        assert rows.sum() == 100 and keep[rows].all()
    # 36 whole windows less the two that held a left-out stretch, plus the partial ones dropped
    assert starts.size == 34
    assert windows.n_not_at_rest == 17
    expected = [run.rate_dph[(t >= s) & (t < s + 100.0)].mean() for s in starts]
    np.testing.assert_allclose(windows.bias_dph[:-1], expected, rtol=1e-12)
    assert windows.bias_dph[-1] == pytest.approx(run.rate_dph[3505:].mean(), rel=1e-12)


def test_user_orientation_labels_give_an_offset_each_like_an_hrg_turned_on_its_table():
    # an HRG turned between two positions: the Earth-rate component on its axis changes by
    # 12 °/h, logged only as the operator's label
    a, _ = mems_run(13, noise_dph=1.0, slope=0.4)
    label = np.where(a.time_s < a.time_s[-1] / 2, 1.0, 2.0)
    rate = a.rate_dph + np.where(label == 2.0, 12.0, 0.0)
    run = Recording({**a.columns, "rate_dph": rate, "orientation": label}, a.metadata, a.source)
    model = quiet_fit([run], THERMOMETER, terms=("f",))
    assert model.offset_mode == "orientation" and model.orientations == ()
    assert model.coefficients["f"] == pytest.approx(0.4, abs=3 * model.standard_errors["f"])
    assert model.offsets_dph["orientation 2"] - model.offsets_dph["orientation 1"] == \
        pytest.approx(12.0, abs=0.2)
    # compensation reads the label; a label never trained is unknown, counted, not guessed
    from hrgtc.compensate import Compensator
    from hrgtc.model import AxisModel, Model

    unit = Model.single(AxisModel(thermometer=THERMOMETER, drift=model), unit="hrg")
    out = Compensator(unit).transform(run)
    step = out["rate_comp_dph"][label == 2.0].mean() - out["rate_comp_dph"][label == 1.0].mean()
    assert abs(step) < 0.2  # the 12 °/h step is taken out
    relabelled = Recording({**run.columns, "orientation": np.full(len(run), 3.0)},
                           run.metadata, run.source)
    compensator = Compensator(unit)
    with pytest.warns(UserWarning, match="never seen in training"):
        compensator.transform(relabelled)
    assert compensator.axis.unknown_orientation == len(run)
