"""``hrgtc export-c``: --precision double|single and --format c|params, in-process.

Truth: the files the library writes for the same options (byte for byte), the header's
statement of the float32 build's accuracy, and the exit code and message of a bad option.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from typer.testing import CliRunner

from hrgtc import drift
from hrgtc.cli import app
from hrgtc.export.export_c import export_c
from hrgtc.model import AxisModel, Model, save_model

from synthetic import THERMOMETER, ramp_run

runner = CliRunner()


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    model = Model.single(
        AxisModel(thermometer=THERMOMETER, drift=drift.fit([ramp_run(seed=1)], THERMOMETER)),
            unit="synthetic-1")
    return save_model(model, tmp_path_factory.mktemp("model") / "unit.json")


@pytest.mark.parametrize(("options", "names"), [
    ([], ["gyro_model.h", "gyro_model.c"]),
    (["--precision", "double"], ["gyro_model.h", "gyro_model.c"]),
    (["--precision", "single"], ["gyro_model.h", "gyro_model.c"]),
    (["--format", "params"], ["gyro_params.txt"]),
], ids=["default", "double", "single", "params"])
def test_writes_what_the_library_writes(options, names, model_file, tmp_path):
    result = runner.invoke(app, ["export-c", str(model_file), "-o", str(tmp_path / "cli"),
                                 "--prefix", "gyro", "--json", *options])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert [Path(p).name for p in data["files"]] == names
    precision = options[1] if options[:1] == ["--precision"] else "double"
    output_format = options[1] if options[:1] == ["--format"] else "c"
    assert (data["precision"], data["format"]) == (precision, output_format)
    library = export_c(model_file, tmp_path / "lib", prefix="gyro", precision=precision,
                       output_format=output_format)
    for written, expected in zip(data["files"], library, strict=True):
        assert Path(written).read_text() == expected.read_text()


def test_single_header_states_its_accuracy(model_file, tmp_path):
    result = runner.invoke(app, ["export-c", str(model_file), "-o", str(tmp_path),
                                 "--precision", "single"])
    assert result.exit_code == 0, result.output
    assert "hrgtc_model.h" in result.output
    header = (tmp_path / "hrgtc_model.h").read_text()
    assert "#define HRGTC_SINGLE_PRECISION 1" in header
    bound_c = float(re.search(r"#define HRGTC_MAX_ERROR_C (\S+)f", header).group(1))
    bound_dph = float(re.search(r"#define HRGTC_MAX_ERROR_DPH (\S+)f", header).group(1))
    assert 0 < bound_c < 1e-3 and 0 < bound_dph < 1e-3
    assert "HRGTC_CENTRED_HZ(freq_hz)" in header


@pytest.mark.parametrize(("options", "message"), [
    (["--precision", "half"], "'half' is not one of"),
    (["--format", "json"], "'json' is not one of"),
    (["--format", "params", "--precision", "single"], "--precision applies to --format c"),
])
def test_bad_options_exit_2_and_say_why(options, message, model_file, tmp_path):
    result = runner.invoke(app, ["export-c", str(model_file), "-o", str(tmp_path), *options])
    assert result.exit_code == 2
    assert message in " ".join(result.output.split())
    assert not any(tmp_path.iterdir())


def test_an_instrument_file_exports_every_axis(tmp_path):
    fitted = drift.fit([ramp_run(seed=1)], THERMOMETER)
    axes = {name: AxisModel(thermometer=THERMOMETER, drift=fitted) for name in "ab"}
    path = save_model(Model(axes, "imu", {}), tmp_path / "imu.json")
    result = runner.invoke(app, ["export-c", str(path), "-o", str(tmp_path / "c"), "--json",
                                 "--precision", "single"])
    assert result.exit_code == 0, result.output
    names = [Path(p).name for p in json.loads(result.stdout)["files"]]
    assert names == ["hrgtc_model.h", "hrgtc_a_model.h", "hrgtc_a_model.c", "hrgtc_b_model.h",
                     "hrgtc_b_model.c"]
    params = runner.invoke(app, ["export-c", str(path), "-o", str(tmp_path / "p"),
                                 "--format", "params"])
    assert params.exit_code == 0, params.output
    text = (tmp_path / "p" / "hrgtc_params.txt").read_text()
    assert "\nn_axes = 2\n" in text and "\na_intercept_dph = " in text and "\nb_n_terms = " in text
