"""A raw temperature count not mapped to °C is not judged as °C (issue 27, the cold test).

``--temp-unit count`` with ``--spikes drop`` dropped every row of the real cold test (its
signed count unwrapped to about -300 is "below -200 °C"), and the validator called the
count an impossible temperature. The count has no °C bounds until a map gives it some.
"""

from __future__ import annotations

from pathlib import Path

from hrgtc.recording import read
from hrgtc.recording.info import describe

RUN = Path(__file__).resolve().parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
OPTIONS = dict(columns={"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s",
                        "rate_dph_y": "gyroy rad/s", "rate_dph_z": "gyroz rad/s",
                        "temperature_c": "temp"},
               units={"time": "ms", "rate": "radps", "temp": "count"}, thermometer="sensor",
               gaps="bridge")


def test_spikes_drop_keeps_the_rows_of_a_raw_count():
    recording = read(RUN, spikes="drop", **OPTIONS)
    assert len(recording) == 6250  # the file's rows (its 3 spikes are of plausible values)
    assert recording["temperature_c"][0] == -300.0  # the unwrapped count, as read


def test_info_does_not_judge_a_raw_count_as_degrees():
    info = describe(RUN, spikes="drop", **OPTIONS)
    assert info.ok, info.validation.message
    assert info.rows == 6250


def test_calibrate_asks_for_the_map_of_a_raw_count(tmp_path):
    # before: a model in counts was written, and its own loader called it corrupt
    from typer.testing import CliRunner

    from hrgtc.cli import app

    result = CliRunner().invoke(app, [
        "calibrate", "--drift", str(RUN), "--col", "time_s=time (ms)",
        "--col", "rate_dph_x=gyrox rad/s", "--col", "rate_dph_y=gyroy rad/s",
        "--col", "rate_dph_z=gyroz rad/s", "--col", "temperature_c=temp", "--time-unit", "ms",
        "--rate-unit", "radps", "--temp-unit", "count", "--thermometer", "sensor",
        "-o", str(tmp_path / "m.json")])
    assert result.exit_code == 2
    said = " ".join(result.output.split())
    assert "raw count" in said and "--temp-ref LOG" in said and "--temp-scale" in said
    assert not (tmp_path / "m.json").exists()
