"""Tests of hrgtc.export.export_c: the firmware C99 export against the Python compensator.

The generated C is compiled with the system compiler under strict warnings, run
on a recording the model was not trained on, and compared with
:class:`hrgtc.compensate.Compensator` (rate to 1e-9 °/h, temperature to 1e-9 °C,
in-range flag identical); its thermometer inverse is also checked against the
published Table 2 of [1].

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy import signal
from typer.testing import CliRunner

from hrgtc import drift, thermometry
from hrgtc.cli import app
from hrgtc.compensate import Compensator
from hrgtc.core.errors import CalibrationError, InputError, OutputExistsError
from hrgtc.core.timeline import settle_threshold_s
from hrgtc.export.export_c import export_c
from hrgtc.model import AxisModel, Model, save_model
from hrgtc.thermometry import paper

from synthetic import THERMOMETER, block_std, ramp_run, with_heating_extra

COMPILER = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
needs_compiler = pytest.mark.skipif(COMPILER is None, reason="no C compiler on this system")
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic"]
# Extra hygiene a firmware build may ask of the generated file (not of the test driver).
STRICT = ["-Wshadow", "-Wconversion", "-Wdouble-promotion", "-Wstrict-prototypes",
          "-Wmissing-prototypes", "-Wcast-qual", "-Wfloat-equal"]

# Reads rows of (dt_s, freq_hz, rate_dph[, housing_c][, aux]) doubles, writes rows of 8 doubles:
# rate_comp, bias, resonator_c_est, in_range, f, df, return value of step(), rate_in_range.
# Prints the state's counters; replays the first samples after reset and fails (3) if they differ.
DRIVER = r"""
#include <stdio.h>
#include "PFX_model.h"

#define REPLAY 64

#ifndef UPFX_AUX_INPUTS
#define UPFX_AUX_INPUTS 0
#endif

static int same(double a, double b) { return a == b || (a != a && b != b); }

static double step(PFX_state *s, const double *row, PFX_output *out)
{
#if UPFX_AUX_INPUTS
    return PFX_step(s, row[0], row[1], row[2], row[3], row[4], out);
#elif UPFX_USES_HOUSING
    return PFX_step(s, row[0], row[1], row[2], row[3], out);
#else
    return PFX_step(s, row[0], row[1], row[2], out);
#endif
}

int main(int argc, char **argv)
{
    const size_t columns = (UPFX_USES_HOUSING ? 4 : 3) + UPFX_AUX_INPUTS;
    double row[5], record[8];
    PFX_state state;
    PFX_output out, first[REPLAY];
    size_t n = 0, k;
    FILE *in, *result;
    if (argc != 3 || !(in = fopen(argv[1], "rb")) || !(result = fopen(argv[2], "wb"))) {
        return 2;
    }
    PFX_init(&state);
    while (fread(row, sizeof(double), columns, in) == columns) {
        record[6] = step(&state, row, &out);
        record[0] = out.rate_comp_dph;
        record[1] = out.bias_model_dph;
        record[2] = out.resonator_c_est;
        record[3] = out.in_range;
        record[4] = out.f_hz;
        record[5] = out.df_hz_per_s;
        record[7] = out.rate_in_range;
        fwrite(record, sizeof(double), 8, result);
        if (n < REPLAY) {
            first[n] = out;
        }
        ++n;
    }
    fclose(result);
    printf("%lu %lu %lu\n", state.samples, state.out_of_range, state.rate_out_of_range);
    rewind(in);
    PFX_reset(&state);
    for (k = 0; k < n && k < REPLAY; ++k) {
        if (fread(row, sizeof(double), columns, in) != columns) {
            return 4;
        }
        step(&state, row, &out);
        if (!same(out.rate_comp_dph, first[k].rate_comp_dph)
            || !same(out.resonator_c_est, first[k].resonator_c_est)
            || out.in_range != first[k].in_range || out.rate_in_range != first[k].rate_in_range) {
            return 3;
        }
    }
    fclose(in);
    return 0;
}
"""


def housing_run(seed, **kwargs):
    """A ramp whose bias also depends on a housing thermistor (lag 900 s of the chamber)."""
    run = ramp_run(seed, **kwargs)
    chamber = run["chamber_c"]
    tau_s = 900.0
    a = -np.expm1(-1.0 / (tau_s * run.sample_rate_hz))
    housing = signal.lfilter([a], [1.0, a - 1.0], chamber, zi=[(1.0 - a) * chamber[0]])[0]
    extra = 0.3 * (housing - 20.0) + 4000.0 * (chamber - housing) / tau_s
    return run.with_columns(housing_c=housing, rate_dph=run.rate_dph + extra)


def build(model, folder: Path, prefix: str) -> Path:
    """Export, compile with strict warnings, link the driver; the driver's path."""
    export_c(model, folder, prefix=prefix)
    (folder / "driver.c").write_text(DRIVER.replace("UPFX", prefix.upper()).replace("PFX", prefix))
    obj = folder / "model.o"
    subprocess.run([COMPILER, *FLAGS, *STRICT, "-c", str(folder / f"{prefix}_model.c"),
                    "-o", str(obj)], check=True, capture_output=True, text=True)
    exe = folder / "driver"
    subprocess.run([COMPILER, *FLAGS, "-I", str(folder), str(folder / "driver.c"), str(obj),
                    "-o", str(exe), "-lm"], check=True, capture_output=True, text=True)
    return exe


def run_driver(exe: Path, columns: list[np.ndarray], folder: Path, name: str,
               time_s: np.ndarray | None = None):
    """Run the driver on rows of ``columns``; the first input, dt_s, from ``time_s``
    (default: uniform steps at the sample rate, as the recording's times)."""
    source, target = folder / f"{name}.in", folder / f"{name}.out"
    if time_s is None:
        raise TypeError("run_driver needs the recording's time_s")
    dt = np.concatenate([[0.0], np.diff(time_s)])
    columns = [dt, *columns]
    np.column_stack(columns).astype("<f8" if np.little_endian else ">f8").tofile(source)
    done = subprocess.run([str(exe), str(source), str(target)], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, f"driver failed ({done.returncode}): {done.stderr}"
    counters = [int(v) for v in done.stdout.split()]
    return np.fromfile(target, dtype=np.float64).reshape(-1, 8), counters


@pytest.fixture(scope="module")
def frequency_model():
    return Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([ramp_run(seed=1)], THERMOMETER)),
            unit="synthetic-1")


@pytest.fixture(scope="module")
def housing_model():
    terms = ("f", "f^2", "df", "h", "dh", "f*dh")
    fitted = drift.fit([housing_run(seed=3)], THERMOMETER, terms=terms)
    return Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted), unit="synthetic-housing")


@pytest.fixture(scope="module")
def frequency_driver(frequency_model, tmp_path_factory):
    return build(frequency_model, tmp_path_factory.mktemp("c_frequency"), "gyro_x")


@needs_compiler
@pytest.mark.parametrize("kind", ["frequency", "housing"])
def test_c_matches_the_python_compensator(kind, request, tmp_path):
    model = request.getfixturevalue(f"{kind}_model")
    if kind == "housing":
        assert {"h", "dh"} & set(model.drift.variables), "the fit should use the thermistor"
        # a deeper cool-down, another seed: partly outside the training ranges
        recording = housing_run(seed=8, start_c=25.0, end_c=-25.0, hours=3.0)
        exe = build(model, tmp_path, "hrgtc")
        inputs = [recording.freq_hz, recording.rate_dph, recording["housing_c"]]
    else:
        # a deeper cool-down than the training run, another seed: leaves the calibrated
        # frequency range (below -20 °C) and the training range of f at its start
        recording = ramp_run(seed=7, start_c=25.0, end_c=-25.0, hours=3.0)
        exe = request.getfixturevalue("frequency_driver")
        inputs = [recording.freq_hz, recording.rate_dph]
    compensator = Compensator(model)
    expected = compensator.transform(recording)
    out, counters = run_driver(exe, inputs, tmp_path, "run", recording.time_s)

    assert out.shape[0] == len(recording)
    assert counters == [compensator.samples, compensator.axis.out_of_range,
                        compensator.axis.rate_out_of_range]
    in_range = expected["in_range"]
    assert 0.05 < in_range.mean() < 0.95  # both branches of the flag are exercised
    assert 0 < compensator.axis.rate_out_of_range < len(recording)
    np.testing.assert_array_equal(out[:, 3] * out[:, 7], in_range)  # the file's flag: both
    assert set(np.unique(out[:, 7])) <= {0.0, 1.0}
    # counted once settled (issue 20: a settling sample is counted as such only)
    settled = recording.time_s - recording.time_s[0] >= settle_threshold_s(
        model.drift.settings.warmup_s)
    assert compensator.axis.settling == int(np.count_nonzero(~settled)) > 0
    assert int(np.count_nonzero((out[:, 7] == 0.0) & settled)) == compensator.axis.rate_out_of_range
    np.testing.assert_allclose(out[:, 0], expected["rate_comp_dph"], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(out[:, 6], out[:, 0])  # return value == out->rate_comp_dph
    np.testing.assert_allclose(out[:, 1], expected["bias_model_dph"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(out[:, 2], expected["resonator_c_est"], rtol=0, atol=1e-9)
    assert np.all(np.isfinite(out[:, 2]))
    # and the compensation is real: 60 s bias stability after the filter's warm-up
    skip, rows = 3000, 600
    raw = block_std(recording.measured_bias_dph[skip:], rows)
    assert block_std(out[skip:, 0] - recording.metadata.input_rate_dph, rows) < 0.5 * raw


@needs_compiler
@pytest.mark.parametrize("selected", [(), ("f^4*dh",)], ids=["intercept-only", "f^4*dh"])
def test_edge_models_compile_cleanly_and_agree(selected, housing_model, tmp_path):
    # no term at all (B = B0), and a fourth power (the C library's pow) times a housing rate
    fitted = dataclasses.replace(housing_model.drift, selected=selected,
                                 scaled_coefficients=(0.7,) * len(selected),
                                 coefficients=dict.fromkeys(selected, 1.0))
    model = Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted))
    recording = housing_run(seed=9, start_c=25.0, end_c=-25.0, hours=1.0)
    columns = [recording.freq_hz, recording.rate_dph]
    if model.drift.variables != ("f",):
        columns.append(recording["housing_c"])
    compensator = Compensator(model)
    expected = compensator.transform(recording)
    out, counters = run_driver(build(model, tmp_path, "edge"), columns, tmp_path, "run",
                               recording.time_s)
    assert counters == [compensator.samples, compensator.axis.out_of_range,
                        compensator.axis.rate_out_of_range]
    np.testing.assert_array_equal(out[:, 3] * out[:, 7], expected["in_range"])
    np.testing.assert_allclose(out[:, 0], expected["rate_comp_dph"], rtol=0, atol=1e-9)


@needs_compiler
def test_c_thermometer_gives_table2_and_nan_beyond(frequency_driver, tmp_path):
    beyond = np.array([4300.0, 4600.0, np.nan])  # outside the monotonic extension, not a number
    freq = np.concatenate([paper.TABLE2_FREQUENCY_HZ, beyond])
    rate = np.full(freq.size, 10.0)
    out, _ = run_driver(frequency_driver, [freq, rate], tmp_path, "table2",
                        np.arange(freq.size) / 200.0)
    temperature = out[:, 2]
    # Table 2 of [1], printed to 3 (one value 4) decimals from the authors' own inversion
    np.testing.assert_allclose(temperature[:7], paper.TABLE2_CALCULATED_C, rtol=0, atol=1e-3)
    assert np.all(np.isnan(temperature[7:]))
    assert np.all(out[7:, 3] == 0.0)
    np.testing.assert_allclose(temperature[:7], THERMOMETER.temperature(freq[:7], warn=False),
                               rtol=0,
                               atol=1e-9)


def test_constants_are_printed_to_round_trip(frequency_model, tmp_path):
    header, source = export_c(frequency_model, tmp_path)
    code = source.read_text()
    settings = frequency_model.drift.settings

    def constant(name):
        return float(re.search(rf"{name} = ([^;]+);", code).group(1))

    assert constant("REFERENCE_FREQ_HZ") == settings.reference_freq_hz
    assert constant("INTERCEPT_DPH") == frequency_model.drift.intercept_dph
    block = re.search(r"COEFFICIENTS\[\d+\] = \{([^}]*)\}", code).group(1)
    values = [float(v) for v in block.replace("\n", " ").split(",") if v.strip()]
    assert values == list(frequency_model.drift.scaled_coefficients)
    text = header.read_text()
    assert "doi:10.3390/s120506434" in text and "synthetic-1" in text
    assert "#include <stdio.h>" not in code and "malloc" not in code
    assert all(ord(c) < 128 for c in text + code)
    assert "TEMPERATURE SENSOR" not in text  # a resonator thermometer: the Hz are Hz


def test_refuses_to_overwrite_without_force(frequency_model, tmp_path):
    header, source = export_c(frequency_model, tmp_path, prefix="unit7")
    assert [p.name for p in (header, source)] == ["unit7_model.h", "unit7_model.c"]
    header.write_text("kept")
    with pytest.raises(OutputExistsError, match=r"unit7_model\.h .*--force"):
        export_c(frequency_model, tmp_path, prefix="unit7")
    assert header.read_text() == "kept"
    # one of the two present: nothing is written half-way
    other = tmp_path / "other"
    other.mkdir()
    (other / "unit7_model.c").write_text("kept")
    with pytest.raises(OutputExistsError, match=r"unit7_model\.c"):
        export_c(frequency_model, other, prefix="unit7")
    assert not (other / "unit7_model.h").exists()
    export_c(frequency_model, tmp_path, prefix="unit7", force=True)
    assert header.read_text().startswith("/*")
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "other", "unit7_model.c", "unit7_model.h"]  # no temporary files left


def test_bad_prefix_and_non_monotonic_thermometer(frequency_model, tmp_path):
    with pytest.raises(InputError, match="prefix '9lives' is not usable"):
        export_c(frequency_model, tmp_path, prefix="9lives")
    # a quadratic with its turning point at 20 °C: one frequency, two temperatures
    bent = thermometry.fit([0, 10, 20, 30, 40], [4400.0, 4401.5, 4402.0, 4401.5, 4400.0], order=2)
    model = Model.single(AxisModel(thermometer=bent, drift=frequency_model.drift))
    with pytest.raises(CalibrationError, match="not monotonic"):
        export_c(model, tmp_path)
    assert not list(tmp_path.iterdir())


def test_cli_writes_the_files_and_records_the_model_hash(frequency_model, tmp_path):
    path = save_model(frequency_model, tmp_path / "unit.json")
    outdir = tmp_path / "firmware"
    runner = CliRunner()
    result = runner.invoke(app, ["export-c", str(path), "-o", str(outdir), "--prefix", "hrg1",
                                 "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert [Path(p).name for p in data["files"]] == ["hrg1_model.h", "hrg1_model.c"]
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    assert f'#define HRG1_MODEL_SHA256 "{digest}"' in (outdir / "hrg1_model.h").read_text()

    again = runner.invoke(app, ["export-c", str(path), "-o", str(outdir), "--prefix", "hrg1"])
    assert again.exit_code == 2
    assert "exist" in again.output and "--force" in again.output
    forced = runner.invoke(app, ["export-c", str(path), "-o", str(outdir), "--prefix", "hrg1",
                                 "--force"])
    assert forced.exit_code == 0
    assert "hrg1_model.c" in forced.output

    missing = runner.invoke(app, ["export-c", str(tmp_path / "nope.json"), "-o", str(outdir)])
    assert missing.exit_code == 2 and "no such model file" in missing.output


def test_refuses_a_model_with_the_heating_switch(tmp_path):
    from hrgtc.drift.features import EQ21_TERMS

    runs = [ramp_run(seed=41, hours=3.0),
            with_heating_extra(ramp_run(seed=42, start_c=-20.0, end_c=20.0,
                                        hours=3.0))]
    fitted = drift.fit(runs, THERMOMETER, terms=(*EQ21_TERMS, "dpos"))
    assert "dpos" in fitted.selected
    with pytest.raises(InputError, match=r"uses dpos .*heating/cooling switch"):
        export_c(Model.single(AxisModel(THERMOMETER, fitted)), tmp_path / "c")
    assert not (tmp_path / "c").exists() or not any((tmp_path / "c").iterdir())


@needs_compiler
def test_c_computes_d2_g_and_the_extra_channel_as_python_does(tmp_path):
    # issue 12: the second df/dt filter (its own state), the gradient housing_c - T(f) from the
    # C thermometer inverse, and --aux channels as step() inputs, centred as in training;
    # a held-out run leaving every training range, so the tangent branches run too
    from synthetic import lagged_model, lagged_run

    model = lagged_model()
    recording = lagged_run(seed=13, start_c=25.0, end_c=-25.0, hours=2.0,
                           drive_amplitude_v=0.2)
    exe = build(model, tmp_path, "lag")
    header = (tmp_path / "lag_model.h").read_text()
    assert "#define LAG_AUX_INPUTS 1" in header and "double aux_drive" in header
    assert "f2_filter" in header  # the second filter's state
    inputs = [recording.freq_hz, recording.rate_dph, recording["housing_c"],
              recording["drive_v"]]
    compensator = Compensator(model)
    expected = compensator.transform(recording)
    out, counters = run_driver(exe, inputs, tmp_path, "run", recording.time_s)
    assert counters == [compensator.samples, compensator.axis.out_of_range,
                        compensator.axis.rate_out_of_range]
    assert 0 < compensator.axis.out_of_range < len(recording)
    np.testing.assert_array_equal(out[:, 3] * out[:, 7], expected["in_range"])
    np.testing.assert_allclose(out[:, 1], expected["bias_model_dph"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(out[:, 0], expected["rate_comp_dph"], rtol=0, atol=1e-9)
    # the C bias is the model's: B(x) with d2 and g from their own definitions
    skip = 6000
    err = out[skip:, 1] - recording["bias_dph"][skip:]
    assert np.sqrt(np.mean(err ** 2)) < 0.5


@needs_compiler
def test_c_on_bursts_bridges_each_gap_with_its_dt(tmp_path):
    # issue 20 item 2 in C: bursts of 5 s every 300 s cut from a continuous simulated
    # recording; step() gets each sample's dt_s (the 295 s gaps too). C and the Python
    # compensator agree sample by sample, and the C df/dt on the bursts is the continuous
    # recording's within 1 % of its range after settling (tau = 300 s, the burst period;
    # tests/drift/test_rate_filter.py states the bounds).
    from hrgtc.recording import Recording

    fitted = drift.fit([ramp_run(seed=1, hours=8.0)], THERMOMETER, rate_tau_s=300.0)
    model = Model.single(AxisModel(thermometer=THERMOMETER, drift=fitted), unit="bursts")
    continuous = ramp_run(seed=7, hours=6.0)
    continuous = continuous.with_columns(freq_hz=THERMOMETER.frequency(continuous["resonator_c"]))
    rows = np.flatnonzero(np.mod(continuous.time_s, 300.0) < 5.0 - 1e-9)
    bursts = Recording({n: continuous[n][rows] for n in continuous.names}, continuous.metadata,
                       "bursts")
    exe = build(model, tmp_path, "burst")
    out, _ = run_driver(exe, [bursts.freq_hz, bursts.rate_dph], tmp_path, "run",
                        bursts.time_s)
    compensator = Compensator(model)
    expected = compensator.transform(bursts)
    np.testing.assert_allclose(out[:, 1], expected["bias_model_dph"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(out[:, 0], expected["rate_comp_dph"], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(out[:, 3] * out[:, 7], expected["in_range"])
    from hrgtc.drift.features import compute_variables

    df_continuous = compute_variables(continuous, fitted.settings, ("df",))["df"][rows]
    settled = bursts.time_s > 600.0 + 10 * 300.0
    span = np.ptp(df_continuous[settled])
    assert span > 1e-4
    assert np.max(np.abs(out[settled, 5] - df_continuous[settled])) < 0.01 * span
    # the per-sample reading of the old filter would have been 60x too steep: not so here
    assert np.median(np.abs(out[settled, 5])) < 2 * np.median(np.abs(df_continuous[settled]))
