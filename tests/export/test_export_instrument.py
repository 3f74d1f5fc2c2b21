"""The firmware exports of a multi-axis instrument: every axis, each with its own prefix.

Three axes with their own drift models (one with a scale factor) are exported in both
precisions and as a parameter file; the C is compiled with gcc and each axis run on its
own cool-down, compared with :class:`Compensator` of that axis's model (and the
contract's law ``(rate - B) / (1 + 1e-6 k)`` where the axis has a scale factor).
"""

from __future__ import annotations

import hashlib
import shutil
import subprocess

import numpy as np
import pytest

from hrgtc import drift
from hrgtc.compensate import Compensator
from hrgtc.core.errors import InputError
from hrgtc.export.export_c import export_c
from hrgtc.model import AxisModel, Model, save_model

from synthetic import THERMOMETER, ramp_run, scale_factor, with_scale_factor

COMPILER = shutil.which("gcc") or shutil.which("cc")
needs_compiler = pytest.mark.skipif(COMPILER is None, reason="no C compiler on this system")
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wshadow",
         "-Wconversion", "-Wdouble-promotion", "-Wmissing-prototypes"]
AXES = ("x", "y", "z")

# rows of (dt_s, freq_x, rate_x, freq_y, rate_y, freq_z, rate_z) -> rows of the three rate_comp
DRIVER = r"""
#include <stdio.h>
#include "imu_model.h"
int main(int argc, char **argv)
{
    double row[7], record[3];
    imu_x_state sx; imu_y_state sy; imu_z_state sz;
    FILE *in, *result;
    if (argc != 3 || !(in = fopen(argv[1], "rb")) || !(result = fopen(argv[2], "wb"))) {
        return 2;
    }
    imu_x_init(&sx); imu_y_init(&sy); imu_z_init(&sz);
    while (fread(row, sizeof(double), 7, in) == 7) {
        record[0] = imu_x_step(&sx, row[0], row[1], row[2], NULL);
        record[1] = imu_y_step(&sy, row[0], row[3], row[4], NULL);
        record[2] = imu_z_step(&sz, row[0], row[5], row[6], NULL);
        fwrite(record, sizeof(double), 3, result);
    }
    fclose(result);
    fclose(in);
    return IMU_N_AXES == 3 ? 0 : 5;
}
"""


@pytest.fixture(scope="module")
def imu():
    models = {}
    for k, name in enumerate(AXES):
        fitted = drift.fit([ramp_run(seed=11 + k)], THERMOMETER,
                           terms=("f", "f^2", "df") if k == 1 else ("f", "f^2", "df", "f*df"))
        models[name] = AxisModel(thermometer=THERMOMETER, drift=fitted)
    models["y"] = with_scale_factor(models["y"],
                                    scale_factor(models["y"].drift.settings.reference_freq_hz))
    return Model(models, "imu", {})


def runs():
    return {name: ramp_run(seed=21 + k, start_c=25.0, end_c=-25.0, hours=2.0,
                           input_rate_dph=3.6e5 if name == "y" else 10.0)
            for k, name in enumerate(AXES)}


def expected_rate(model, recording):
    """The axis's Compensator, which is the contract's (rate - B) / (1 + 1e-6 k)."""
    out = Compensator(model).transform(recording)
    sf = model.scale_factor
    k = 0.0 if sf is None else sf.ppm(recording.freq_hz)
    np.testing.assert_allclose(out["rate_comp_dph"],
                               (recording.rate_dph - out["bias_model_dph"]) / (1.0 + 1e-6 * k),
                               rtol=1e-15)
    return out["rate_comp_dph"]


@needs_compiler
def test_every_axis_compiles_and_compensates_like_its_model(imu, tmp_path):
    files = export_c(imu, tmp_path, prefix="imu")
    assert [p.name for p in files] == ["imu_model.h"] + [
        f"imu_{a}_model.{ext}" for a in AXES for ext in ("h", "c")]
    (tmp_path / "driver.c").write_text(DRIVER)
    exe = tmp_path / "driver"
    sources = [str(tmp_path / f"imu_{a}_model.c") for a in AXES]
    subprocess.run([COMPILER, *FLAGS, "-I", str(tmp_path), *sources, str(tmp_path / "driver.c"),
                    "-o", str(exe), "-lm"], check=True, capture_output=True, text=True)
    recordings = runs()
    dt = np.concatenate([[0.0], np.diff(recordings[AXES[0]].time_s)])
    columns = [dt, *(c for a in AXES for c in (recordings[a].freq_hz, recordings[a].rate_dph))]
    np.column_stack(columns).tofile(tmp_path / "in.bin")
    done = subprocess.run([str(exe), str(tmp_path / "in.bin"), str(tmp_path / "out.bin")],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    out = np.fromfile(tmp_path / "out.bin").reshape(-1, 3)
    for k, name in enumerate(AXES):
        expected = expected_rate(imu.of_axis(name), recordings[name])
        np.testing.assert_allclose(out[:, k], expected, rtol=1e-14, atol=1e-9)
    assert "#define IMU_Y_USES_SCALE_FACTOR 1" in (tmp_path / "imu_y_model.h").read_text()
    assert "SCALE_FACTOR" not in (tmp_path / "imu_x_model.h").read_text()


@needs_compiler
def test_single_precision_instrument_compiles(imu, tmp_path):
    files = export_c(imu, tmp_path, prefix="imu", precision="single")
    sources = [str(p) for p in files if p.suffix == ".c"]
    subprocess.run([COMPILER, *FLAGS, "-Wfloat-conversion", "-c", *sources],
                   check=True, capture_output=True, text=True, cwd=tmp_path)
    umbrella = files[0].read_text()
    assert "IMU_X_CENTRED_HZ(freq_hz)" in umbrella
    for name in AXES:
        assert f"#define IMU_{name.upper()}_MAX_ERROR_DPH" in (
            tmp_path / f"imu_{name}_model.h").read_text()


def test_parameter_file_has_every_axis(imu, tmp_path):
    (path,) = export_c(imu, tmp_path, prefix="imu", output_format="params")
    values = {}
    for line in path.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            key, _, value = line.partition("=")
            values[key.strip()] = value.strip()
    assert values["n_axes"] == "3" and values["axes"].split() == list(AXES)
    for name in AXES:
        model = imu.axes[name]
        assert float(values[f"{name}_intercept_dph"]) == model.drift.intercept_dph
        assert [values[f"{name}_term_{k + 1}"] for k in range(len(model.drift.selected))] == list(
            model.drift.selected)
    assert values["y_uses_scale_factor"] == "1" and values["x_uses_scale_factor"] == "0"
    assert float(values["y_sf_intercept_ppm"]) == 150.0


def test_long_axis_prefix_is_refused(imu, tmp_path):
    with pytest.raises(InputError, match="longer than 32 characters"):
        export_c(imu, tmp_path, prefix="p" * 31)
    assert not any(tmp_path.iterdir())


def test_from_the_instrument_file(imu, tmp_path):
    path = save_model(imu, tmp_path / "imu.json")
    files = export_c(path, tmp_path / "c", prefix="imu")
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    for name in AXES:
        header = (tmp_path / "c" / f"imu_{name}_model.h").read_text()
        assert f'#define IMU_{name.upper()}_MODEL_SHA256 "{digest}"' in header
        assert f"imu.json, axis {name}" in header
    assert files[0].name == "imu_model.h" and len(files) == 7
