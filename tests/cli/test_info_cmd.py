"""``hrgtc info``: in-process runs with Typer's CliRunner, checked through --json.

Truth: the numbers the test put into the files (row count, duration n/fs,
column ranges from numpy) and the corruptions it made.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.core.errors import SpikeWarning
from hrgtc.recording import Metadata, Recording, write

runner = CliRunner()
RATE_HZ = 200.0


def recording(n: int = 1000, seed: int = 0) -> Recording:
    rng = np.random.default_rng(seed)
    return Recording(
        {
            "time_s": np.arange(n) / RATE_HZ,
            "freq_hz": 4425.0 + 0.3 * np.linspace(-1, 1, n) + 0.01 * rng.standard_normal(n),
            "rate_dph": 12.0 + 2.0 * rng.standard_normal(n),
            "chamber_c": np.linspace(20.0, -5.0, n),
            "housing_c": np.linspace(20.0, -3.0, n),
        },
        Metadata(sample_rate_hz=RATE_HZ, unit="SN-3", input_rate_dph=9.67, profile="ramp"),
    )


def info_json(*args: str) -> tuple[int, dict, str]:
    result = runner.invoke(app, ["info", *args, "--json"])
    return result.exit_code, json.loads(result.stdout), result.stderr


@pytest.mark.parametrize("suffix", [".parquet", ".csv", ".h5"])
def test_info_reports_a_good_file(tmp_path, suffix):
    rec = recording()
    path = write(rec, tmp_path / f"run{suffix}")
    code, data, _ = info_json(str(path))
    assert code == 0
    assert data["rows"] == 1000
    assert data["duration_s"] == pytest.approx(1000 / RATE_HZ)
    assert data["sample_rate_hz"] == RATE_HZ and data["sample_rate_inferred"] is False
    assert data["measured_sample_rate_hz"] == pytest.approx(RATE_HZ, rel=1e-9)
    units = {c["name"]: c["unit"] for c in data["columns"]}
    assert units == {
        "time_s": "s",
        "freq_hz": "Hz",
        "rate_dph": "deg/h",
        "chamber_c": "degC",
        "housing_c": "degC",
    }
    assert data["spans"]["chamber_c"] == [-5.0, 20.0]
    assert data["spans"]["housing_c"] == [-3.0, 20.0]
    assert data["spans"]["freq_hz"] == [rec.freq_hz.min(), rec.freq_hz.max()]
    assert data["validation"]["ok"] is True and data["validation"]["n_gaps"] == 0
    assert data["metadata"]["unit"] == "SN-3"
    text = runner.invoke(app, ["info", str(path)])
    assert text.exit_code == 0
    assert "chamber_c" in text.stdout and "[degC]" in text.stdout and "ok" in text.stdout


def test_bad_file_exits_2_with_message_and_json_problems(tmp_path):
    rec = recording()
    rate = rec.rate_dph.copy()
    rate[321] = np.nan
    path = write(rec.with_columns(rate_dph=rate), tmp_path / "bad.parquet")
    result = runner.invoke(app, ["info", str(path)])
    assert result.exit_code == 2
    assert "column 'rate_dph', row 321: value nan is not finite" in " ".join(result.stderr.split())
    code, data, _ = info_json(str(path))
    assert code == 2
    assert data["rows"] == 1000
    assert data["validation"]["ok"] is False
    problem = data["validation"]["problems"][0]
    assert (problem["kind"], problem["column"], problem["row"]) == ("not_finite", "rate_dph", 321)


def test_unreadable_file_is_reported_in_json(tmp_path):
    path = write(recording(n=50), tmp_path / "run.csv")
    lines = path.read_text(encoding="utf-8").splitlines()
    lines[-5] = lines[-5][:8]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    code, data, _ = info_json(str(path))
    assert code == 2
    assert data["validation"]["ok"] is False
    assert data["validation"]["problems"][0]["kind"] == "unreadable"
    assert "expected 5 fields" in data["validation"]["problems"][0]["message"]


def test_column_and_unit_options_map_a_foreign_file(tmp_path):
    n = 600
    rng = np.random.default_rng(5)
    rows = np.column_stack(
        [np.arange(n) * 5.0, 4.425 + 1e-5 * rng.standard_normal(n), 0.003 + 5e-4 * rng.random(n)]
    )
    path = tmp_path / "logger.csv"
    np.savetxt(path, rows, delimiter=",", header="t,f,w", comments="", fmt="%.17g")
    result = runner.invoke(app, ["info", str(path)])
    assert result.exit_code == 2 and "--col time_s=" in result.stderr.replace("\n", "")
    options = ["--col", "time_s=t", "--col", "freq_hz=f,rate_dph=w"]
    options += ["--time-unit", "ms", "--freq-unit", "kHz", "--rate-unit", "°/s"]
    code, data, _ = info_json(str(path), *options)
    assert code == 0, data["validation"]
    assert data["duration_s"] == pytest.approx(n * 0.005)
    assert data["sample_rate_inferred"] is True
    assert data["sample_rate_hz"] == pytest.approx(200.0)
    assert data["spans"]["freq_hz"] == pytest.approx(
        [rows[:, 1].min() * 1000, rows[:, 1].max() * 1000]
    )
    code, data, _ = info_json(str(path), *options, "--rate-hz", "100", "--unit-name", "X1")
    assert code == 2
    assert data["metadata"]["unit"] == "X1"
    assert [p["kind"] for p in data["validation"]["problems"]] == ["sample_rate"]


def test_gap_option_and_bad_options(tmp_path):
    rec = recording()
    time = rec.time_s.copy()
    time[700:] += 30.0  # longer than a dropout (5 s)
    path = write(rec.with_columns(time_s=time), tmp_path / "gap.h5")
    code, data, _ = info_json(str(path))
    assert code == 2 and data["validation"]["problems"][0]["kind"] == "gap"
    code, data, _ = info_json(str(path), "--gaps", "split")
    assert code == 0 and data["validation"]["n_gaps"] == 1
    assert data["validation"]["gaps"][0]["row"] == 700
    bad_unit = runner.invoke(app, ["info", str(path), "--freq-unit", "MHz"])
    assert bad_unit.exit_code == 2 and "unknown freq unit" in bad_unit.stderr
    bad_col = runner.invoke(app, ["info", str(path), "--col", "freq"])
    assert bad_col.exit_code == 2 and "NAME=THEIRS" in bad_col.stderr
    missing = runner.invoke(app, ["info", str(tmp_path / "nope.parquet")])
    assert missing.exit_code == 2 and "no such file" in missing.stderr


def test_json_stays_valid_with_infinite_times(tmp_path):
    rec = recording()
    time = rec.time_s.copy()
    time[10] = np.inf
    path = write(rec.with_columns(time_s=time), tmp_path / "inf.parquet")
    code, data, _ = info_json(str(path))
    assert code == 2
    kinds = {p["kind"] for p in data["validation"]["problems"]}
    assert {"not_finite", "time_order"} <= kinds


def px4_style_csv(tmp_path, n: int = 600) -> tuple:
    """A three-axis MEMS log: time in µs, rates in rad/s, a raw temperature count, a spike."""
    rng = np.random.default_rng(4)
    t_us = np.arange(n) * 5000  # 200 Hz
    gyro = {a: (2e-5 * (i + 1) + 1e-6 * rng.standard_normal(n)).tolist()
            for i, a in enumerate("xyz")}
    count = np.round(np.linspace(800.0, 960.0, n))  # °C = count / 16
    gyro["y"][321] = 1e4  # rad/s: a spike
    path = tmp_path / "px4.csv"
    with open(path, "w") as out:
        out.write("timestamp,gyro_x,gyro_y,gyro_z,temp_raw\n")
        for i in range(n):
            out.write(f"{t_us[i]},{gyro['x'][i]!r},{gyro['y'][i]!r},{gyro['z'][i]!r},"
                      f"{count[i]:.0f}\n")
    return path, count


PX4_ARGS = ["--col", "time_s=timestamp,rate_dph_x=gyro_x,rate_dph_y=gyro_y,rate_dph_z=gyro_z",
            "--col", "temperature_c=temp_raw", "--time-unit", "us", "--rate-unit", "radps",
            "--thermometer", "sensor", "--temp-scale", "0.0625", "--temp-offset", "0"]


def test_info_of_a_messy_multi_axis_imu_file(tmp_path):
    path, _ = px4_style_csv(tmp_path)
    code, data, _ = info_json(str(path), *PX4_ARGS)
    assert code == 2 and not data["validation"]["ok"]
    problem = data["validation"]["problems"][0]
    assert (problem["column"], problem["row"]) == ("rate_dph_y", 321)
    with pytest.warns(SpikeWarning, match=r"dropped 1 row\(s\).*'rate_dph_y', row 321"):
        code, data, err = info_json(str(path), *PX4_ARGS, "--spikes", "drop")
    assert code == 0, err
    assert data["axes"] == ["x", "y", "z"]
    assert data["rows"] == 599
    assert data["sample_rate_hz"] == pytest.approx(200.0)
    assert data["spans"]["temperature_c"] == [50.0, 60.0]  # 800/16 .. 960/16
    # the sensor's temperature is listed once, not again as freq_hz_x/y/z [degC]
    assert not any(name.startswith("freq_hz") for name in data["spans"])
    units = {c["name"]: c["unit"] for c in data["columns"]}
    assert units["rate_dph_z"] == "deg/h" and not any(n.startswith("freq_hz") for n in units)
    with pytest.warns(SpikeWarning):
        result = runner.invoke(app, ["info", str(path), *PX4_ARGS, "--spikes", "drop"])
    assert "axes: x, y, z" in result.stdout


def test_a_slow_housing_channel_is_held_or_refused_as_asked(tmp_path):
    # issue 20 item 5 on the command line: housing_c logged at 20 Hz in a 200 Hz file
    from hrgtc.core.errors import SlowChannelWarning

    rec = recording(2000)
    housing = rec["housing_c"].copy()
    housing[np.arange(2000) % 10 != 0] = np.nan
    path = tmp_path / "slow.csv"
    write(rec.with_columns(housing_c=housing), path)
    with pytest.warns(SlowChannelWarning, match=r"'housing_c' is logged every 0.05 s.*held"):
        code, data, err = info_json(str(path))
    assert code == 0, err
    assert data["rows"] == 2000
    code, data, err = info_json(str(path), "--slow-channels", "error")
    assert code != 0 and not data["validation"]["ok"]
    assert data["validation"]["problems"][0]["column"] == "housing_c"
    # a value older than --hold-max-s is a gap in the channel: the row is dropped
    housing[1000:1100] = np.nan  # 0.5 s without a reading, then values again
    write(rec.with_columns(housing_c=housing), path, force=True)
    with pytest.warns(SlowChannelWarning, match="dropped as a gap"):
        code, data, err = info_json(str(path), "--hold-max-s", "0.1", "--gaps", "split")
    assert code == 0, err
    # the last value before the stop is row 990's; rows 991..1010 are within 0.1 s of it
    assert data["rows"] == 2000 - (1100 - 1011)


def test_info_shows_only_the_metadata_a_file_sets(tmp_path):
    """A plain CSV (no metadata header) has no profile: no "profile ''", no "input rate 0";
    a file that sets them shows them."""
    rec = recording()
    named = write(rec, tmp_path / "named.parquet")
    text = " ".join(runner.invoke(app, ["info", str(named)]).stdout.split())
    assert "unit SN-3, profile 'ramp', input rate 9.67 °/h" in text
    plain = tmp_path / "plain.csv"
    plain.write_text("time_s,freq_hz,rate_dph\n" + "".join(
        f"{k / RATE_HZ},{4425.0 + 1e-3 * k},{12.0 + (k % 3)}\n" for k in range(400)))
    result = runner.invoke(app, ["info", str(plain)])
    assert result.exit_code == 0, result.stderr
    text = " ".join(result.stdout.split())
    assert "profile" not in text and "input rate" not in text
    assert "unit unknown" in text
