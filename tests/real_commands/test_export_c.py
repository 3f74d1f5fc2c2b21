"""``hrgtc export-c`` of the real cold test's model, compiled with gcc and run on the file's
held-out rows as a firmware would see them (each sample's dt, the logged count mapped to °C
by numpy with the map the header states, the rates), against ``hrgtc compensate`` of the
same rows: equal to 1e-9 relative on every axis."""

from __future__ import annotations

import re
import shutil
import subprocess

import numpy as np
import pyarrow.parquet as pq
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app

from .conftest import MAPPING, RUN, pan_columns

COMPILER = shutil.which("gcc") or shutil.which("cc")
FLAGS = ["-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic"]
#: Share of the rows trained on (tests/test_against_a_line.py): the rest is held out.
TRAINED = 0.6

# rows of (dt_s, T_C, rate_x, rate_y, rate_z) -> rows of the three rate_comp
DRIVER = r"""
#include <stdio.h>
#include "hrgtc_model.h"
int main(int argc, char **argv)
{
    double row[5], record[3];
    hrgtc_x_state sx; hrgtc_y_state sy; hrgtc_z_state sz;
    FILE *in, *result;
    if (argc != 3 || !(in = fopen(argv[1], "rb")) || !(result = fopen(argv[2], "wb"))) {
        return 2;
    }
    hrgtc_x_init(&sx); hrgtc_y_init(&sy); hrgtc_z_init(&sz);
    while (fread(row, sizeof(double), 5, in) == 5) {
        record[0] = hrgtc_x_step(&sx, row[0], row[1], row[2], NULL);
        record[1] = hrgtc_y_step(&sy, row[0], row[1], row[3], NULL);
        record[2] = hrgtc_z_step(&sz, row[0], row[1], row[4], NULL);
        fwrite(record, sizeof(double), 3, result);
    }
    fclose(result);
    fclose(in);
    return 0;
}
"""


def _stated_map(header: str) -> tuple[float, float]:
    """The count's map to °C as the C header states it: (scale, offset)."""
    assert "freq_hz = T = S*count + O" in header, "the header states no map of the count"
    scale = re.search(r"S = (\S+) degC per count", header)
    offset = re.search(r"O = (\S+) degC", header)
    assert scale and offset, header
    return float(scale.group(1)), float(offset.group(1))


@pytest.mark.skipif(COMPILER is None, reason="no C compiler on this system")
def test_the_c_export_compensates_the_real_held_out_rows_as_python_does(pan_model, tmp_path):
    runner = CliRunner()
    result = runner.invoke(app, ["export-c", str(pan_model), "-o", str(tmp_path / "c")])
    assert result.exit_code == 0, result.output
    c = pan_columns()
    cut = round(TRAINED * c["time_s"].size)  # a burst's first row
    start_s = 0.5 * (c["time_s"][cut - 1] + c["time_s"][cut]) - c["time_s"][0]
    output = tmp_path / "held.parquet"
    result = runner.invoke(app, ["compensate", str(RUN), "--model", str(pan_model), *MAPPING,
                                 "--start", f"{start_s:.6f}", "-o", str(output)])
    assert result.exit_code == 0, result.output
    python = pq.read_table(output)
    assert python.num_rows == c["time_s"].size - cut

    header = (tmp_path / "c" / "hrgtc_y_model.h").read_text()
    scale, offset = _stated_map(header)
    held = slice(cut, None)
    dt = np.concatenate([[0.0], np.diff(c["time_s"][held])])
    rows = [dt, scale * c["count"][held] + offset, *(c[a][held] for a in "xyz")]
    np.column_stack(rows).tofile(tmp_path / "in.bin")
    (tmp_path / "driver.c").write_text(DRIVER)
    sources = [str(tmp_path / "c" / f"hrgtc_{a}_model.c") for a in "xyz"]
    subprocess.run([COMPILER, *FLAGS, "-I", str(tmp_path / "c"), *sources,
                    str(tmp_path / "driver.c"), "-o", str(tmp_path / "driver"), "-lm"],
                   check=True, capture_output=True, text=True)
    done = subprocess.run([str(tmp_path / "driver"), str(tmp_path / "in.bin"),
                           str(tmp_path / "out.bin")], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    out = np.fromfile(tmp_path / "out.bin").reshape(-1, 3)
    for k, axis in enumerate("xyz"):
        expected = python.column(f"rate_comp_dph_{axis}").to_numpy()
        assert np.all(np.isfinite(expected))
        np.testing.assert_allclose(out[:, k], expected, rtol=1e-9, atol=0.0, err_msg=axis)
        # and the model does something: the compensation is not the raw rate
        assert np.max(np.abs(expected - c[axis][held])) > 1.0
