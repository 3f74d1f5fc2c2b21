"""Tests of hrgtc.compensate: batch and streaming compensation agree."""

from __future__ import annotations

import dataclasses
import itertools
import json
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

from hrgtc import drift
from hrgtc import recording as recording_io
from hrgtc.compensate import (
    OUTPUT_COLUMNS,
    Compensator,
    compensate,
    compensate_file,
)
from hrgtc.core.errors import InputError, RecordingError
from hrgtc.model import AxisModel, Model
from hrgtc.recording import concatenate
from hrgtc.settings.compensation import CompensateSettings

from synthetic import THERMOMETER, ramp_run, with_heating_extra


@pytest.fixture(scope="module")
def unit_model():
    return Model.single(
        AxisModel(THERMOMETER, drift.fit([ramp_run(seed=21, hours=3.0)], THERMOMETER)))


@pytest.fixture(scope="module")
def run():
    return ramp_run(seed=22, start_c=-15.0, end_c=15.0, hours=1.0)


@settings(max_examples=25, deadline=None)
@given(cuts=st.lists(st.integers(1, 35_999), min_size=1, max_size=8, unique=True))
def test_any_chunking_equals_batch(unit_model, run, cuts):
    batch = compensate(unit_model, run)
    compensator = Compensator(unit_model)
    bounds = [0, *sorted(cuts), len(run)]
    parts = [compensator.transform(run.slice(a, b)) for a, b in itertools.pairwise(bounds)]
    streamed = concatenate(parts)
    for name in ("rate_comp_dph", "bias_model_dph", "resonator_c_est", "in_range"):
        np.testing.assert_allclose(streamed[name], batch[name], rtol=0, atol=1e-12)


def test_compensated_is_raw_minus_model(unit_model, run):
    out = compensate(unit_model, run)
    np.testing.assert_array_equal(out["rate_comp_dph"], run.rate_dph - out["bias_model_dph"])
    # frequency noise 2 mHz at 0.37 Hz/°C is 0.0054 °C per sample: 6 sigma
    np.testing.assert_allclose(out["resonator_c_est"], run["resonator_c"], atol=0.033)
    np.testing.assert_array_equal(out["bias_model_dph"], unit_model.drift.predict_recording(run))


def test_out_of_range_samples_are_counted(unit_model):
    hot = ramp_run(seed=23, start_c=20.0, end_c=60.0, hours=1.0)
    compensator = Compensator(unit_model)
    out = compensator.transform(hot)
    assert compensator.out_of_range_fraction > 0.2
    assert compensator.axis.settling == round(unit_model.drift.settings.warmup_s
                                              * hot.sample_rate_hz)
    # in_range is 0 beyond the trained temperature, beyond the trained df/dt, and while
    # the filter settles; the kinds are counted apart
    assert 1 - out["in_range"].mean() >= max(compensator.out_of_range_fraction,
                                             compensator.rate_out_of_range_fraction)
    assert not out["in_range"][: compensator.axis.settling].any()
    report = compensator.ranges()
    assert report.temperature_fraction == compensator.out_of_range_fraction
    assert report.seen_c[1] > 25.0 and report.temperature_excess_c > 5.0
    assert any("beyond the trained temperature" in line for line in report.warnings())


@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_range_report_says_how_far_df_dt_went(unit_model, engine):
    """A warm-up at 4x the training rate: in_range 0 there, the ratio of rates reported."""
    fast = ramp_run(seed=24, start_c=0.0, end_c=10.0, hours=1.0, ramp_hours=0.1)
    compensator = Compensator(unit_model, engine=engine)
    out = compensator.transform(fast)
    report = compensator.ranges()
    assert report.rate_fraction > 0.0
    assert report.rate_excess_ratio > 1.0
    assert (out["in_range"] == 0).mean() >= report.rate_fraction
    assert any("beyond the trained df/dt" in line for line in report.warnings())
    assert json.loads(json.dumps(report.to_dict()))["rate_fraction"] == report.rate_fraction


@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_samples_beyond_the_df_range_are_never_in_range(unit_model, engine):
    # issue 11: a faster warm-up leaves the training range of df/dt (the model was fitted
    # on a cool-down); those samples are extrapolated and must not be flagged in range
    fast = ramp_run(seed=29, start_c=-10.0, end_c=15.0, hours=0.5)
    compensator = Compensator(unit_model, engine=engine)
    out = compensator.transform(fast)
    low, high = unit_model.drift.ranges["df"]
    from hrgtc.drift.features import FeatureStream

    values = FeatureStream(unit_model.drift.settings, ("f", "df")).transform(fast)
    beyond = (values["df"] < low) | (values["df"] > high)
    assert beyond.mean() > 0.5
    # counted on the settled samples (a settling one is counted as such only, issue 20)
    settled = fast.time_s - fast.time_s[0] >= unit_model.drift.settings.warmup_s
    assert compensator.axis.rate_out_of_range == int(np.count_nonzero(beyond & settled))
    assert compensator.axis.settling == int(np.count_nonzero(~settled))
    assert not np.any(out["in_range"][beyond])


def test_housing_baseline_missing_is_a_clear_error(unit_model):
    with pytest.raises(InputError, match="no housing-thermistor baseline"):
        Compensator(unit_model, drift="housing")


# -- the fused engine against the numpy reference ------------------------------------------
def housing_run(seed, **kwargs):
    """A ramp with a housing thermistor lagging the chamber by 900 s."""
    run = ramp_run(seed, **kwargs)
    a = -np.expm1(-1.0 / (900.0 * run.sample_rate_hz))
    housing = signal.lfilter([a], [1.0, a - 1.0], run["chamber_c"],
                             zi=[(1.0 - a) * run["chamber_c"][0]])[0]
    return run.with_columns(housing_c=housing)


def assert_engines_agree(model, recording, drift_kind="frequency", temperature_atol=1e-12):
    fused, numpy_ = Compensator(model, drift_kind), Compensator(model, drift_kind, "numpy")
    a, b = fused.transform(recording), numpy_.transform(recording)
    for name in ("rate_comp_dph", "bias_model_dph"):
        np.testing.assert_allclose(a[name], b[name], rtol=0, atol=1e-9)
    np.testing.assert_allclose(a["resonator_c_est"], b["resonator_c_est"], rtol=0,
                               atol=temperature_atol)
    np.testing.assert_array_equal(a["in_range"], b["in_range"])
    assert (fused.samples, fused.axis.out_of_range, fused.axis.rate_out_of_range) == (
        numpy_.samples, numpy_.axis.out_of_range, numpy_.axis.rate_out_of_range)
    return fused


@pytest.mark.parametrize("start_c, end_c", [(-15.0, 15.0), (20.0, 60.0), (25.0, -25.0)],
                         ids=["inside", "hot", "deep-cooldown"])
def test_fused_engine_equals_numpy_reference(unit_model, start_c, end_c):
    run = ramp_run(seed=24, start_c=start_c, end_c=end_c, hours=1.0)
    assert_engines_agree(unit_model, run)


GRAMMAR = ("f", "f^2", "f^3", "df", "f*df", "f^2*df", "h", "h^2", "h^3", "dh", "f*dh",
           "f^4*dh", "h*df", "df^2", "f*h*dh", "g", "f*g", "f^2*g", "g^2", "dh*g")


@settings(max_examples=20, deadline=None)
@given(selected=st.lists(st.sampled_from(GRAMMAR), max_size=6, unique=True),
       coefficients=st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6),
       quantiles=st.tuples(st.floats(0.0, 0.4), st.floats(0.6, 1.0)))
def test_fused_engine_is_generic_over_the_term_grammar(unit_model, hot_housing_run, selected,
                                                       coefficients, quantiles):
    # any terms of the grammar, ranges cut inside the data: the tangent extension is exercised
    from hrgtc.drift.features import compute_variables

    values = compute_variables(hot_housing_run, unit_model.drift.settings,
                               ("f", "df", "h", "dh", "g"), THERMOMETER)
    ranges = {v: tuple(float(q) for q in np.quantile(x, quantiles)) for v, x in values.items()}
    scales = {"f": 10.0, "df": 1e-3, "h": 20.0, "dh": 1e-2, "g": 2.0}
    settings_ = dataclasses.replace(unit_model.drift.settings, scales=scales)
    fitted = dataclasses.replace(
        unit_model.drift, selected=tuple(selected), settings=settings_, ranges=ranges,
        scaled_coefficients=tuple(coefficients[: len(selected)]),
        coefficients=dict.fromkeys(selected, 1.0))
    assert_engines_agree(Model.single(AxisModel(THERMOMETER, fitted)), hot_housing_run)


@pytest.fixture(scope="module")
def hot_housing_run():
    return housing_run(seed=25, start_c=30.0, end_c=-25.0, hours=0.5)


@settings(max_examples=25, deadline=None)
@given(cuts=st.lists(st.integers(1, 17_999), min_size=1, max_size=8, unique=True))
def test_fused_streaming_is_exact_across_any_chunk_boundaries(unit_model, hot_housing_run, cuts):
    # the filter state is handed over exactly: any chunking gives the batch's bits
    fitted = dataclasses.replace(unit_model.drift, selected=("f", "df", "h", "dh"),
                                 scaled_coefficients=(0.4, 2.0, -0.3, 1.5),
                                 settings=dataclasses.replace(
                                     unit_model.drift.settings,
                                     scales={"f": 10.0, "df": 1e-3, "h": 20.0, "dh": 1e-2}))
    model = Model.single(AxisModel(THERMOMETER, fitted))
    batch = compensate(model, hot_housing_run)
    compensator = Compensator(model)
    bounds = [0, *sorted(cuts), len(hot_housing_run)]
    streamed = concatenate([compensator.transform(hot_housing_run.slice(a, b))
                            for a, b in itertools.pairwise(bounds)])
    for name in ("rate_comp_dph", "bias_model_dph", "resonator_c_est", "in_range"):
        np.testing.assert_array_equal(streamed[name], batch[name])


def test_fused_slow_path_of_the_thermometer(unit_model, run):
    # with a zero tolerance (almost) no Newton step "converges": the samples take the slow
    # path; the few whose step rounds to exactly 0 stop a step earlier than the numpy path's
    # block-wide iteration does, a difference far below the inverse's own tolerance (5e-11 °C)
    from hrgtc.compensate import _kernel as kernel

    compensator = Compensator(unit_model)
    plan = kernel.plan(unit_model.drift, THERMOMETER, compensator.axis._variables)
    strict = plan.thermometer.copy()
    strict[10:12] = 0.0  # one_step_limit, tolerance
    compensator.axis._plan = dataclasses.replace(plan, thermometer=strict)
    out = compensator.transform(run.slice(0, 2000))
    np.testing.assert_allclose(out["resonator_c_est"],
                               THERMOMETER.temperature(run.freq_hz[:2000], warn=False),
                               rtol=0, atol=1e-11)


# -- the gradient g = housing_c - T(freq_hz) in the fused kernel ---------------------------
#: The default candidates with a housing thermistor (hrgtc.pipeline.calibration.GRADIENT_TERMS).
GRADIENT_TERMS = ("f", "f^2", "f^3", "g", "f*g", "f^2*g")


@pytest.fixture(scope="module")
def gradient_model():
    from synthetic import lagged_run

    fitted = drift.fit([lagged_run(seed=5), lagged_run(seed=6, start_c=-20.0, end_c=20.0)],
                       THERMOMETER, terms=GRADIENT_TERMS, initial=GRADIENT_TERMS,
                       premove=0.999999)
    assert fitted.selected == GRADIENT_TERMS and "g" in fitted.ranges
    return Model.single(AxisModel(THERMOMETER, fitted))


@pytest.fixture(scope="module")
def steep_gradient_run():
    # hotter, colder and three times faster than training, down then up: f and g leave
    # their ranges on both sides (one run for the compensator: the halves are joined)
    from synthetic import lagged_run

    down = lagged_run(seed=13, start_c=40.0, end_c=-35.0, hours=1.0)
    up = lagged_run(seed=14, start_c=-35.0, end_c=40.0, hours=1.0)
    return concatenate([down, up.with_columns(time_s=up.time_s + down.time_s[-1] + 0.1)])


def test_fused_engine_computes_the_gradient_as_numpy(gradient_model, steep_gradient_run):
    from hrgtc.compensate import _kernel as kernel
    from hrgtc.drift.features import compute_variables

    assert kernel.supports_variables(("f", "df", "g"))
    g = compute_variables(steep_gradient_run, gradient_model.drift.settings, ("g",),
                          THERMOMETER)["g"]
    low, high = gradient_model.drift.ranges["g"]
    assert np.count_nonzero(g < low) > 100 and np.count_nonzero(g > high) > 100
    # beyond 40 °C some blocks need a second Newton step: numpy's block-wide iteration then
    # polishes every sample of the block once more, the kernel only those samples; both are
    # within the inverse's tolerance (5e-11 °C), as with a model without g
    fused = assert_engines_agree(gradient_model, steep_gradient_run, temperature_atol=5e-11)
    assert fused.axis._plan is not None and fused.axis._plan.uses_gradient  # no fallback
    out = compensate(gradient_model, steep_gradient_run)
    assert np.all(out["in_range"][(g < low) | (g > high)] == 0.0)
    # the bias law has 0.4 (housing - resonator): the model follows it beyond the range too
    assert np.all(np.isfinite(out["bias_model_dph"]))


@settings(max_examples=15, deadline=None)
@given(cuts=st.lists(st.integers(1, 71_999), min_size=1, max_size=8, unique=True))
def test_fused_gradient_chunked_equals_batch(gradient_model, steep_gradient_run, cuts):
    batch = compensate(gradient_model, steep_gradient_run)
    compensator = Compensator(gradient_model)
    bounds = [0, *sorted(cuts), len(steep_gradient_run)]
    streamed = concatenate([compensator.transform(steep_gradient_run.slice(a, b))
                            for a, b in itertools.pairwise(bounds)])
    for name in OUTPUT_COLUMNS:
        np.testing.assert_array_equal(streamed[name], batch[name])


def test_fused_gradient_on_two_threads_gives_the_bits_of_one_call(gradient_model,
                                                                  steep_gradient_run,
                                                                  monkeypatch):
    from hrgtc.compensate import _kernel as kernel

    whole = compensate(gradient_model, steep_gradient_run)
    monkeypatch.setattr(kernel, "PARALLEL_ROWS", 1 << 12)
    split = compensate(gradient_model, steep_gradient_run)
    for name in OUTPUT_COLUMNS:
        np.testing.assert_array_equal(split[name], whole[name])


def test_fused_gradient_through_the_slow_path_of_the_thermometer(gradient_model,
                                                                 steep_gradient_run):
    # every sample's temperature from the kernel's bracketed Newton, before the bias needs it
    from hrgtc.compensate import _kernel as kernel

    compensator = Compensator(gradient_model)
    plan = kernel.plan(gradient_model.drift, THERMOMETER, compensator.axis._variables)
    strict = plan.thermometer.copy()
    strict[10:12] = 0.0  # one_step_limit, tolerance
    compensator.axis._plan = dataclasses.replace(plan, thermometer=strict)
    part = steep_gradient_run.slice(0, 3000)
    out = compensator.transform(part)
    reference = compensate(gradient_model, part, engine="numpy")
    np.testing.assert_allclose(out["resonator_c_est"], reference["resonator_c_est"],
                               rtol=0, atol=1e-11)
    np.testing.assert_allclose(out["bias_model_dph"], reference["bias_model_dph"],
                               rtol=0, atol=1e-9)
    np.testing.assert_array_equal(out["in_range"], reference["in_range"])


def test_unknown_engine_is_a_clear_error(unit_model):
    with pytest.raises(InputError, match="engine must be 'fused' or 'numpy', got 'c'"):
        Compensator(unit_model, engine="c")


def test_import_loads_neither_numba_nor_scipy_signal():
    code = ("import sys, hrgtc.compensate; "
            "print(sorted({'numba', 'scipy.signal'} & set(sys.modules)))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "[]"


# -- file to file ------------------------------------------------------------------------
def test_file_to_file_equals_batch_and_leaves_no_temporary(unit_model, run, tmp_path):
    source = recording_io.write(run, tmp_path / "run.parquet")
    output = tmp_path / "out.parquet"
    summary = compensate_file(source, output, unit_model,
                              settings=CompensateSettings(chunk_rows=7_001))
    batch = compensate(unit_model, run)
    written = recording_io.read(output)
    assert written.names == (*run.names, *OUTPUT_COLUMNS, "at_rest")  # at rest: all 1
    for name in batch.names:
        np.testing.assert_array_equal(written[name], batch[name])
    assert np.all(written["at_rest"] == 1.0)
    compensator = Compensator(unit_model)
    compensator.transform(run)
    assert (summary.rows, summary.out_of_range_fraction, summary.rate_out_of_range_fraction) == (
        len(run), compensator.out_of_range_fraction, compensator.rate_out_of_range_fraction)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.parquet", "run.parquet"]


def test_file_to_file_refuses_to_drop_spikes(unit_model, run, tmp_path):
    """Compensation writes every row it reads: the library refuses ``spike_filter="drop"``
    as the command does (it used to drop the spikes' rows from a library call)."""
    source = recording_io.write(run, tmp_path / "run.parquet")
    with pytest.raises(InputError, match="never drops a row: use --spike-filter flag"):
        compensate_file(source, tmp_path / "out.parquet", unit_model,
                        read_options=recording_io.ReadOptions(spike_filter="drop"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.parquet"]


def test_file_to_file_bad_row_late_in_the_file_leaves_nothing(unit_model, tmp_path):
    # past the validator's first 100 000 rows: rejected by the read-ahead thread while
    # earlier chunks are already compensated and written (--motion keep: no detector's
    # pass, which would meet the row first)
    long_run = ramp_run(seed=26, hours=5.0)
    rate = long_run.rate_dph.copy()
    rate[150_000] = np.nan
    source = recording_io.write(long_run.with_columns(rate_dph=rate), tmp_path / "bad.parquet")
    written = []
    with pytest.raises(RecordingError, match="rate_dph"):
        compensate_file(source, tmp_path / "out.parquet", unit_model,
                        settings=CompensateSettings(chunk_rows=20_000),
                        progress=lambda done, total: written.append(done),
                        read_options=recording_io.ReadOptions(motion="keep"))
    assert written and max(written) >= 120_000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.parquet"]


def test_two_threads_give_the_bits_of_one_call(unit_model, monkeypatch):
    # a chunk long enough to be split in halves (filter advanced over the first half)
    from hrgtc.compensate import _kernel as kernel

    long_run = housing_run(seed=27, start_c=25.0, end_c=-25.0, hours=5.0)
    monkeypatch.setattr(kernel, "PARALLEL_ROWS", 1 << 15)
    fitted = dataclasses.replace(unit_model.drift, selected=("f", "df", "h", "dh", "f*dh"),
                                 scaled_coefficients=(0.4, 2.0, -0.3, 1.5, 0.2),
                                 settings=dataclasses.replace(
                                     unit_model.drift.settings,
                                     scales={"f": 10.0, "df": 1e-3, "h": 20.0, "dh": 1e-2}))
    model = Model.single(AxisModel(THERMOMETER, fitted))
    split = assert_engines_agree(model, long_run)
    a = Compensator(model).transform(long_run)
    monkeypatch.setattr(kernel, "PARALLEL_ROWS", len(long_run) + 1)
    whole = Compensator(model)
    b = whole.transform(long_run)
    for name in OUTPUT_COLUMNS:
        np.testing.assert_array_equal(a[name], b[name])
    assert (split.axis.out_of_range, split.axis.rate_out_of_range) == (
        whole.axis.out_of_range, whole.axis.rate_out_of_range)


def test_thermometer_beyond_the_kernel_series_falls_back_to_numpy(unit_model, run, monkeypatch):
    from hrgtc.compensate import _kernel as kernel

    monkeypatch.setattr(kernel, "POLY_SIZE", 3)  # as if the order-3 fit were order 5+
    assert not kernel.supports(THERMOMETER)
    out = compensate(unit_model, run)
    reference = compensate(unit_model, run, engine="numpy")
    for name in OUTPUT_COLUMNS:
        np.testing.assert_array_equal(out[name], reference[name])


def test_a_model_with_the_heating_switch_runs_on_numpy_in_both_engines(run):
    from hrgtc.drift.features import EQ21_TERMS

    runs = [ramp_run(seed=31, hours=3.0),
            with_heating_extra(ramp_run(seed=32, start_c=-20.0, end_c=20.0, hours=3.0))]
    fitted = drift.fit(runs, THERMOMETER, terms=(*EQ21_TERMS, "dpos", "f*dpos"))
    assert "dpos" in fitted.variables
    model = Model.single(AxisModel(THERMOMETER, fitted))
    fused, numpy_engine = Compensator(model), Compensator(model, engine="numpy")
    a, b = fused.transform(run), numpy_engine.transform(run)
    assert fused.axis._plan is None  # fell back: the kernel does not compute dpos
    for name in OUTPUT_COLUMNS:
        np.testing.assert_array_equal(a[name], b[name])
    settle = round(fitted.settings.warmup_s * run.sample_rate_hz)
    np.testing.assert_allclose(a["bias_model_dph"][settle:],
                               fitted.predict_recording(run)[settle:], rtol=1e-9, atol=1e-9)


def test_models_with_d2_and_aux_run_on_numpy_in_both_engines():
    # the fused kernel computes f, df, h, dh, g only: a model using d2 or a_NAME falls back
    # to the numpy engine, which must then give the same numbers as asking for numpy
    from synthetic import lagged_model, lagged_run

    model = lagged_model()
    run = lagged_run(seed=12, start_c=25.0, end_c=-25.0, hours=1.0, drive_amplitude_v=0.2)
    fused = assert_engines_agree(model, run)
    assert fused.axis._plan is None  # it did fall back
    later = run.with_columns(time_s=run.time_s + run.time_s[-1] + run.time_s[1])
    out = fused.transform(later)  # a second chunk, one step later: filter states carried
    assert np.all(np.isfinite(out["rate_comp_dph"]))
    # the drift model explains the gradient and the drive: the residual is the white noise
    truth = Compensator(model, engine="numpy").transform(run)
    skip = 6000
    err = truth["bias_model_dph"][skip:] - run["bias_dph"][skip:]
    assert np.sqrt(np.mean(err ** 2)) < 0.5
    without = recording_io.Recording({k: run[k] for k in run.names if k != "drive_v"},
                                      run.metadata, "held-out.parquet")
    with pytest.raises(InputError, match=r"held-out\.parquet: no column 'drive_v'"):
        Compensator(model).transform(without)


@pytest.mark.filterwarnings("ignore::hrgtc.core.errors.RateFilterWarning")  # tau 10 s, gap 600 s
@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_a_gap_exactly_on_a_chunk_boundary(unit_model, run, engine):
    # issue 21 item 8: chunks cut exactly at the first row after a gap. In "split" the
    # filter restarts there (as in one batch); otherwise it is carried across the gap with
    # the gap's dt, the previous time kept in its state. Either way streaming equals batch.
    gap_row = 20_000
    times = run.time_s.copy()
    times[gap_row:] += 600.0  # the logger slept 10 min
    gapped = run.with_columns(time_s=times)
    for gaps in ("split", "ignore"):
        batch = Compensator(unit_model, engine=engine, gaps=gaps).transform(gapped)
        streaming = Compensator(unit_model, engine=engine, gaps=gaps)
        parts = [streaming.transform(gapped.slice(0, gap_row)),
                 streaming.transform(gapped.slice(gap_row, len(gapped)))]
        for name in OUTPUT_COLUMNS:
            np.testing.assert_array_equal(np.concatenate([p[name] for p in parts]), batch[name])
        if gaps == "split":
            assert streaming.axis.segments == 2
            split = batch
        else:
            bridged = batch
    # the restart is visible: the split filter settles again after the gap (flagged)
    settle = round(unit_model.drift.settings.warmup_s * unit_model.drift.settings.sample_rate_hz)
    assert np.all(split["in_range"][gap_row:gap_row + settle] == 0.0)
    assert not np.array_equal(split["bias_model_dph"][gap_row:gap_row + 100],
                              bridged["bias_model_dph"][gap_row:gap_row + 100])


def test_a_step_of_exactly_two_periods_is_not_a_gap(unit_model, run):
    # one dropped sample (a step of two periods, rounded up by the time stamps) is bridged
    # even in "split": the compensator's gap test has the validator's tolerance
    times = run.time_s.copy()
    times[5000:] += 1.0 / run.sample_rate_hz * (1.0 + 1e-9)
    dropped = run.with_columns(time_s=times)
    compensator = Compensator(unit_model, gaps="split")
    compensator.transform(dropped)
    assert compensator.axis.segments == 1


@pytest.mark.parametrize("engine", ["fused", "numpy"])
def test_the_seen_f_and_df_extremes_are_those_of_the_variables(unit_model, run, engine):
    # issue 21 item 8: the extremes the range report is built from (f and df/dt seen), in
    # both engines, against the batch variables computed independently, over two chunks;
    # of the settled samples (issue 20: the settling ones are reported as such only)
    from hrgtc.drift.features import compute_variables

    values = compute_variables(run, unit_model.drift.settings, ("f", "df"))
    settled = run.time_s - run.time_s[0] >= unit_model.drift.settings.warmup_s
    assert 0 < np.count_nonzero(~settled) < 12_345  # the settling ends in the first chunk
    values = {v: x[settled] for v, x in values.items()}
    compensator = Compensator(unit_model, engine=engine)
    compensator.transform(run.slice(0, 12_345))
    compensator.transform(run.slice(12_345, len(run)))
    expected = [values["f"].min(), values["f"].max(), values["df"].min(), values["df"].max()]
    np.testing.assert_allclose(compensator.axis._extremes, expected, rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("suffix", ["parquet", "csv", "h5", "tdms", "mat", "mf4"])
def test_the_output_carries_the_restarts_of_every_chunk(unit_model, run, tmp_path, suffix):
    """A clock reset to about zero (a logger restart) in the third chunk: the compensated
    file lists it in its metadata (written at close), so that a reading of the output knows
    its runs -- its time axis is the repaired one, where the reset no longer shows."""
    time = run.time_s.copy()
    reset = 25_000
    time[reset:] = time[reset:] - time[reset] + 0.35  # the clock restarts at 0.35 s
    source = recording_io.write(run.with_columns(time_s=time), tmp_path / "reset.parquet")
    restarts = recording_io.read(source, gaps="bridge").metadata.extra["restarts_s"]
    assert len(restarts) == 1
    out = tmp_path / f"out.{suffix}"
    compensate_file(source, out, unit_model, settings=CompensateSettings(chunk_rows=10_000),
                    read_options=recording_io.ReadOptions(gaps="bridge"))
    written = recording_io.read(out, gaps="bridge")
    assert written.metadata.extra["restarts_s"] == pytest.approx(restarts, rel=0, abs=1e-9)
    # a reading of the output (chunk by chunk, as evaluate and calibrate read) finds the
    # restart at the reset's row: a new run starts there
    from hrgtc.core.timeline import RESTARTS_KEY, restart_rows

    rows, offset = [], 0
    for chunk in recording_io.ReadOptions(gaps="bridge").chunks(out, rows=7_000):
        rows.extend(offset + restart_rows(chunk.time_s, chunk.metadata.extra[RESTARTS_KEY]))
        offset += len(chunk)
    assert rows == [reset]


def test_samples_not_at_rest_are_flagged_as_run_rest_finds_them(unit_model, run, tmp_path):
    """Three handling bursts (5 s at up to 40,000 °/h) in a run: ``compensate`` drops none,
    writes ``at_rest`` 0 exactly where the detector of calibration and evaluation
    (:func:`hrgtc.drift.rest.run_rest`) marks the file, and counts them as flagged."""
    from hrgtc.drift.rest import run_rest

    rate = run.rate_dph.copy()
    t = run.time_s - run.time_s[0]
    truth = np.zeros(t.size, dtype=bool)
    for start_s in (900.0, 1800.0, 2700.0):
        inside = (t >= start_s) & (t < start_s + 5.0)
        rate[inside] += 40_000.0 * np.sin(np.pi * (t[inside] - start_s) / 5.0)
        truth |= inside
    source = recording_io.write(run.with_columns(rate_dph=rate), tmp_path / "handled.parquet")
    summary = compensate_file(source, tmp_path / "out.parquet", unit_model,
                              settings=CompensateSettings(chunk_rows=7_000))
    out = recording_io.read(tmp_path / "out.parquet")
    expected = run_rest(recording_io.ReadOptions().chunks(source), "exclude").keep
    assert len(out) == len(run)  # nothing dropped
    np.testing.assert_array_equal(out["at_rest"], expected.astype(float))
    assert not expected[truth].any()  # every handled sample is flagged
    assert np.count_nonzero(~expected) < 3 * truth.sum() + 3 * 2 * 300  # bursts and guards
    assert summary.accounting.flagged["motion"] == int(np.count_nonzero(~expected))
    keep = compensate_file(source, tmp_path / "keep.parquet", unit_model,
                           read_options=recording_io.ReadOptions(motion="keep"))
    assert "at_rest" not in recording_io.read(tmp_path / "keep.parquet")
    assert keep.accounting.flagged.get("motion", 0) == 0


@pytest.mark.parametrize("column", ["rate_dph", "time_s"])
def test_a_bad_sample_gets_the_validators_error_whatever_the_motion_pass(unit_model, run,
                                                                          tmp_path, column):
    """The at-rest pass reads the file unvalidated (the compensating pass validates it);
    a bad sample past the first chunk still stops ``compensate`` with the validator's
    error, the one ``--motion keep`` gives, not the detector's."""
    values = run[column].copy()
    values[20_000] = np.nan
    source = recording_io.write(run.with_columns(**{column: values}), tmp_path / "bad.parquet")
    errors = []
    for motion in ("keep", "exclude"):
        with pytest.raises(RecordingError) as caught:
            compensate_file(source, tmp_path / f"{motion}.parquet", unit_model,
                            settings=CompensateSettings(chunk_rows=7_000),
                            read_options=recording_io.ReadOptions(motion=motion))
        errors.append(str(caught.value))
    assert errors[0] == errors[1]
    assert "20000" in errors[0] or "20,000" in errors[0] or "20001" in errors[0]
