"""The command line starts without the library: heavy imports wait for the command that needs them.

Timing is measured in ``bench/bench_cli.py``; here the property behind it is checked:
building the whole command tree (what ``hrgtc --help`` does) imports none of numpy,
scipy, pyarrow, matplotlib, numba or the pipeline's stages, and the defaults the
commands write out for ``--help`` equal the library's own.
"""

from __future__ import annotations

import subprocess
import sys

from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.core.meta import __version__

HEAVY = ("numpy", "scipy", "pyarrow", "matplotlib", "numba", "h5py", "hrgtc.recording",
         "hrgtc.thermometry", "hrgtc.drift", "hrgtc.model", "hrgtc.simulate")


def test_building_the_commands_imports_no_heavy_module():
    code = ("import sys, hrgtc.cli; from typer.main import get_command; "
            "get_command(hrgtc.cli.app); "
            f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_version_alone():
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0 and result.output.strip() == f"hrgtc {__version__}"


def test_help_keeps_units_and_defaults_in_brackets():
    result = CliRunner().invoke(app, ["calibrate", "--help"], terminal_width=200)
    assert result.exit_code == 0
    assert "Averaging window of the fit [s]." in result.output
    assert "[default: (max(--penter, 0.1))]" in result.output
    assert "Reference temperature of f [°C]." in result.output


def test_written_out_defaults_equal_the_library():
    from hrgtc.cli.calibrate_cmd import EQ21_DEFAULT
    from hrgtc.drift import EQ21_TERMS
    from hrgtc.settings.simulation import (
        DEFAULT_INPUT_RATE_DPH,
        DEFAULT_UNIT,
        PROFILE_KINDS,
        UNIT_NAMES,
    )
    from hrgtc.simulate import campaign, standard_profiles, units

    assert EQ21_DEFAULT == ",".join(EQ21_TERMS)
    assert PROFILE_KINDS == standard_profiles.KINDS
    assert list(UNIT_NAMES) == units.names()
    assert DEFAULT_UNIT == units.DEFAULT_UNIT
    assert DEFAULT_INPUT_RATE_DPH == campaign.DEFAULT_INPUT_RATE_DPH


def test_an_error_naming_a_column_with_brackets_prints_the_brackets(tmp_path):
    """A column named like a logger's (``gyro_x [deg/h]``) is text in an error, not rich
    markup: the message names it whole."""
    run = tmp_path / "run.csv"
    run.write_text("time_s,freq_hz,rate_dph\n0,4424.9,9.7\n1,4424.9,9.7\n2,4424.9,9.7\n")
    result = CliRunner().invoke(app, ["info", str(run), "--col", "rate_dph=gyro_x [deg/h]"])
    assert result.exit_code == 2
    assert "error: " in result.output
    assert "column 'gyro_x [deg/h]' (given for rate_dph) not found" in result.output.replace(
        "\n", " ").split("error: ")[-1]
