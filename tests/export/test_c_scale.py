"""Tests of hrgtc.export.c.scale: the scale-factor correction in the C export.

Both builds are compiled with gcc and run on a cool-down that leaves the rate-table
frequency range (the tangent continuation); truth is the library's own pieces: the
drift model's bias from :class:`Compensator`, ``ScaleFactorModel.ppm`` and the
compensation law ``rate_comp = (rate - B) / (1 + 1e-6 k)`` of the contract.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.export.c.float32 import float_accuracy, float_constants, mirror_scale
from hrgtc.export.c.plan import plan_for
from hrgtc.export.export_c import export_c
from hrgtc.model import AxisModel, Model

from synthetic import THERMOMETER, ramp_run, scale_factor, with_scale_factor

COMPILER = shutil.which("gcc") or shutil.which("cc")
needs_compiler = pytest.mark.skipif(COMPILER is None, reason="no C compiler on this system")
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wshadow",
         "-Wconversion", "-Wdouble-promotion", "-Wmissing-prototypes", "-Wfloat-equal"]

# rows of (frequency input, rate_dph) in REAL -> rows of (rate_comp, bias, scale_model_ppm)
DRIVER = r"""
#include <stdio.h>
#include "PFX_model.h"
int main(int argc, char **argv)
{
    REAL row[3], record[3];
    PFX_state state;
    PFX_output out;
    FILE *in, *result;
    if (argc != 3 || !(in = fopen(argv[1], "rb")) || !(result = fopen(argv[2], "wb"))) {
        return 2;
    }
    PFX_init(&state);
    while (fread(row, sizeof(REAL), 3, in) == 3) {  /* dt_s, frequency, rate */
        record[0] = PFX_step(&state, row[0], row[1], row[2], &out);
        record[1] = out.bias_model_dph;
        record[2] = out.scale_model_ppm;
        fwrite(record, sizeof(REAL), 3, result);
    }
    fclose(result);
    fclose(in);
    return UPFX_USES_SCALE_FACTOR == 1 ? 0 : 5;
}
"""


@pytest.fixture(scope="module")
def model():
    fitted = drift.fit([ramp_run(seed=1)], THERMOMETER)
    # k's own reference 0.5 Hz off the drift model's: the float build shifts f by it
    sf = scale_factor(fitted.settings.reference_freq_hz + 0.5)
    return with_scale_factor(Model.single(
        AxisModel(thermometer=THERMOMETER, drift=fitted), unit="sf"), sf)


def run(model, tmp_path: Path, precision: str, columns, time_s):
    real = "double" if precision == "double" else "float"
    dtype = np.float64 if precision == "double" else np.float32
    export_c(model, tmp_path, prefix="sfx", precision=precision)
    (tmp_path / "driver.c").write_text(
        DRIVER.replace("UPFX", "SFX").replace("PFX", "sfx").replace("REAL", real))
    exe = tmp_path / "driver"
    subprocess.run([COMPILER, *FLAGS, "-I", str(tmp_path), str(tmp_path / "sfx_model.c"),
                    str(tmp_path / "driver.c"), "-o", str(exe), "-lm"], check=True,
                   capture_output=True, text=True)
    dt = np.concatenate([[0.0], np.diff(time_s)])
    np.column_stack([dt, *columns]).astype(dtype).tofile(tmp_path / "in.bin")
    done = subprocess.run([str(exe), str(tmp_path / "in.bin"), str(tmp_path / "out.bin")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return np.fromfile(tmp_path / "out.bin", dtype=dtype).reshape(-1, 3)


@needs_compiler
def test_double_build_divides_by_the_scale_factor(model, tmp_path):
    recording = ramp_run(seed=7, start_c=25.0, end_c=-25.0, hours=3.0, input_rate_dph=3.6e5)
    out = run(model, tmp_path, "double", [recording.freq_hz, recording.rate_dph],
              recording.time_s)
    k = model.scale_factor.ppm(recording.freq_hz)
    low, high = model.scale_factor.freq_range_hz
    beyond = (recording.freq_hz < low) | (recording.freq_hz > high)
    assert 0.05 < beyond.mean() < 0.95  # the tangent continuation is exercised
    np.testing.assert_allclose(out[:, 2], k, rtol=0, atol=1e-9)
    compensated = Compensator(model).transform(recording)
    bias = compensated["bias_model_dph"]
    np.testing.assert_allclose(out[:, 1], bias, rtol=0, atol=1e-9)
    expected = (recording.rate_dph - bias) / (1.0 + 1e-6 * k)
    np.testing.assert_allclose(out[:, 0], expected, rtol=1e-14, atol=1e-9)
    np.testing.assert_allclose(out[:, 0], compensated["rate_comp_dph"], rtol=1e-14, atol=1e-9)
    # the correction is real: at 100 deg/s input, 150 ppm is 54 deg/h
    assert np.max(np.abs(out[:, 0] - (recording.rate_dph - bias))) > 30.0
    header = (tmp_path / "sfx_model.h").read_text()
    assert "(rate_dph - B) / (1 + 1e-6*k)" in " ".join(header.replace(" * ", " ").split())


@needs_compiler
def test_single_build_scale_factor_matches_mirror_and_double(model, tmp_path):
    recording = ramp_run(seed=7, start_c=25.0, end_c=-25.0, hours=3.0)
    centre = model.drift.settings.reference_freq_hz
    f32 = (recording.freq_hz - centre).astype(np.float32)
    out = run(model, tmp_path, "single", [f32, recording.rate_dph.astype(np.float32)],
              recording.time_s)
    k32 = mirror_scale(model, f32)
    np.testing.assert_allclose(out[:, 2], k32, rtol=0, atol=4 * np.spacing(np.float32(200.0)))
    plan = plan_for(model, "single")
    accuracy = float_accuracy(model, plan, float_constants(model, plan))
    assert 0 < accuracy.scale_ppm < 1e-3
    f_low, f_high = THERMOMETER.frequency_range_hz
    calibrated = (recording.freq_hz >= f_low) & (recording.freq_hz <= f_high)
    k64 = model.scale_factor.ppm(recording.freq_hz)
    assert np.max(np.abs(out[calibrated, 2] - k64[calibrated])) <= 2 * accuracy.scale_ppm
    assert "scale_model_ppm: worst" in (tmp_path / "sfx_model.h").read_text()
