"""Words that fit the sensor (issue 20 item 11): on a model of the gyro's temperature sensor
(``--thermometer sensor``) the outputs say "sensor", not resonator, Hz or a cubic fit; on a
resonator model they keep the resonator's words, unchanged.

Truth: the committed golden model files (a resonator model, a sensor model, the PAN cold
test's sensor model with its ``temperature_map``) and the real cold test itself.
"""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.compensate.file_pass import compensated_metadata
from hrgtc.evaluation.calibration_figures import (
    SENSOR_THERMOMETER,
    THERMOMETER,
    calibration_summary,
)
from hrgtc.model import load_model
from hrgtc.recording import Metadata

GOLDEN = Path(__file__).parents[1] / "data" / "golden-models"
RESONATOR = GOLDEN / "v2" / "unit-resonator-254ab6c.json"
SENSOR = GOLDEN / "v2" / "unit-sensor-thermometer-ee60050.json"
PAN_MODEL = GOLDEN / "v3" / "instrument-pan-sensor-temp-map-ee60050.json"
DATA = Path(__file__).parents[1] / "data" / "pan-cold-test"
RUN = DATA / "pan_tvc_cold_2020-03-07.csv"
LOG = DATA / "pan_etu_cold_handlog_2020-03-07.csv"
READ = ["--thermometer", "sensor", "--time-unit", "ms", "--rate-unit", "rad/s", "--gaps", "bridge",
        "--col", "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
        "rate_dph_z=gyroz rad/s,temperature_c=temp"]
REF = ["--temp-ref", str(LOG), "--temp-ref-col", "time_s=Time", "--temp-ref-col",
       "temperature_c=C1 (C)", "--temp-ref-start", "15:45"]
runner = CliRunner()


def test_the_compensated_mark_says_what_drove_the_model():
    """``compensated_by.drift``: "sensor temperature" for a sensor model (was "frequency")."""
    metadata = Metadata(sample_rate_hz=5.0)
    sensor = compensated_metadata(metadata, load_model(SENSOR))
    assert sensor.extra["compensated_by"]["drift"] == "sensor temperature"
    resonator = compensated_metadata(metadata, load_model(RESONATOR))
    assert resonator.extra["compensated_by"]["drift"] == "frequency"
    instrument = compensated_metadata(metadata, load_model(PAN_MODEL))
    assert instrument.extra["compensated_by"]["drift"] == "sensor temperature"
    housing = compensated_metadata(metadata, load_model(RESONATOR), "housing")
    assert housing.extra["compensated_by"]["drift"] == "housing"


def _section(summary, heading):
    return {row[1]: row[2:] for row in summary.rows() if row[0] == heading}


def test_a_sensor_thermometer_shows_no_cubic_fit():
    """No "soak plateaus 2", c0 0, c1 1 °C/°C^1 for a sensor: what the thermometer is, the
    temperatures trained on and, with a reference log, its map."""
    model = load_model(SENSOR)
    summary = calibration_summary(model)
    assert THERMOMETER not in [row[0] for row in summary.rows()]
    rows = _section(summary, SENSOR_THERMOMETER)
    assert rows["thermometer"][0] == "temperature sensor, read directly"
    assert not {"soak plateaus", "order", "c0", "c1", "R²"} & set(rows)
    low, high = model.thermometer.temperature_range_c
    assert "trained temperatures" in rows
    assert f"{high - low:.4g}" in str(rows["trained temperatures"][0])

    pan = load_model(PAN_MODEL)
    mapped = _section(calibration_summary(pan.of_axis("x"), temperature_map=pan.temperature_map),
                      SENSOR_THERMOMETER)
    assert mapped["thermometer"][0] == "sensor count, mapped to °C"
    assert mapped["reference log"][0] == pan.temperature_map["reference"]
    assert mapped["map scale"][:2] == (f"{pan.temperature_map['scale_c_per_count']:.6g}",
                                       "°C/count")
    assert mapped["reference points"][0] == str(pan.temperature_map["points"])

    resonator = _section(calibration_summary(load_model(RESONATOR)), THERMOMETER)
    assert {"soak plateaus", "order", "c0", "c3"} <= set(resonator)
    assert resonator["c1"][1] == "Hz/°C^1"


def test_calibrate_on_the_cold_test_prints_its_map_as_the_thermometer(tmp_path, monkeypatch):
    from hrgtc.cli import _app

    monkeypatch.setattr(_app.console, "width", 200)
    result = runner.invoke(app, ["calibrate", "--drift", str(RUN), *READ, *REF,
                                 "--rate-tau-s", "310",
                                 "-o", str(tmp_path / "pan.json")], terminal_width=200)
    assert result.exit_code == 0, result.output
    out = result.output
    assert out.count(SENSOR_THERMOMETER) == 3 and "Eq. 18" not in out
    assert "soak plateaus" not in out and "°C/°C^1" not in out
    assert "map scale" in out and "0.00586994" in out and "°C/count" in out
    model = json.loads((tmp_path / "pan.json").read_text())
    assert model["temperature_map"]["points"] == 24
    # the compensated file's mark: what drove the model (an instrument of sensor axes)
    result = runner.invoke(app, ["compensate", str(RUN), "--model", str(tmp_path / "pan.json"),
                                 *READ, "-o", str(tmp_path / "out.csv")])
    assert result.exit_code == 0, result.output
    head = [line for line in (tmp_path / "out.csv").read_text().splitlines()[:40]
            if line.startswith("#")]
    assert '"drift": "sensor temperature"' in "\n".join(head)
    # the report: the same thermometer table (no Eq. 18 fit), the run's recorded time, the
    # run figure's legends
    from hrgtc.report import figures

    legends: list[str] = []
    drawn = figures.run_figure

    def run_figure(*args, **kwargs):
        figure = drawn(*args, **kwargs)
        legends.extend(t.get_text() for ax in figure.axes for t in ax.get_legend().get_texts())
        return figure

    monkeypatch.setattr(figures, "run_figure", run_figure)
    result = runner.invoke(app, ["report", "--model", str(tmp_path / "pan.json"), str(RUN),
                                 *READ, "-o", str(tmp_path / "pan.html")])
    assert result.exit_code == 0, result.output
    page = html.unescape((tmp_path / "pan.html").read_text(encoding="utf-8"))
    assert page.count("Thermometer: the gyro's temperature sensor, its count mapped to °C "
                      "by the reference log") == 3
    assert "<td>map scale</td>" in page and "soak plateaus" not in page
    assert "(0.0347 h recorded, in bursts of 5 s every 305 s)" in page
    assert len(legends) > 3 and "temperature sensor" in legends
    assert not [t for t in legends if "resonator" in t or "frequency" in t], legends
    assert any(t.startswith("compensated, temperature-sensor model") for t in legends)


def _export(model: Path, kind: str, folder: Path) -> dict[str, str]:
    result = runner.invoke(app, ["export-c", str(model), "-o", str(folder), "--format", kind],
                           terminal_width=400)
    assert result.exit_code == 0, result.output
    def prose(text: str) -> str:  # the comment lines joined, their "*" or "#" left out
        return " ".join(" ".join(line.strip().removeprefix("*").removeprefix("#").split())
                        for line in text.splitlines())

    return {p.name: prose(p.read_text()) for p in folder.iterdir()}


def test_the_exports_of_a_sensor_model_speak_of_the_sensor(tmp_path):
    """The C header and the parameter file: "gyro temperature-drift compensation
    (temperature sensor)", the sensor's reading in °C and its temperature, not "HRG" and a
    "resonator temperature"; a resonator model keeps its words."""
    for model in (SENSOR, PAN_MODEL):
        for kind in ("c", "params"):
            texts = _export(model, kind, tmp_path / model.stem / kind)
            for name, text in texts.items():
                if not name.endswith((".h", ".txt")):
                    continue
                assert "gyro temperature-drift compensation (temperature sensor)" in text, name
                assert "HRG" not in text.replace("HRGTC", ""), name
                assert "resonator temperature" not in text, name
                assert "resonator natural frequency" not in text, name
        header = _export(model, "c", tmp_path / model.stem / "again")
        readme = next(t for n, t in header.items()
                      if n.endswith("_model.h") and "Thermometer" in t)
        assert "freq_hz [degC] the temperature sensor's reading" in readme
        assert "Thermometer: the gyro's temperature sensor, freq = +1*T +0" in readme
    c = _export(RESONATOR, "c", tmp_path / "resonator" / "c")["hrgtc_model.h"]
    assert "hrgtc_model.h -- HRG temperature-drift compensation of unit" in c
    assert "the resonator temperature from the frequency (inverse of Eq. (18)" in c
    assert "freq_hz [Hz] resonator natural frequency" in c and "(temperature sensor)" not in c
    params = _export(RESONATOR, "params", tmp_path / "resonator" / "params")["hrgtc_params.txt"]
    assert "hrgtc parameter file -- HRG temperature-drift compensation of unit" in params
    assert "6. resonator temperature:" in params


def test_the_run_figure_names_the_thermometer():
    """The report's run figure: "temperature sensor" and "temperature-sensor model" for a
    sensor; a resonator's run keeps "resonator, from frequency" and "frequency model"."""
    import types

    import numpy as np

    from hrgtc.report.figures import run_figure

    n = 12
    blocks = {"time_s": 10.0 * np.arange(n), "raw_dph": np.linspace(0, 1, n),
              "model_dph": np.linspace(0, 1, n), "comp_dph": np.zeros(n),
              "temperature_c": np.linspace(20, 10, n), "in_range": np.ones(n)}
    run = types.SimpleNamespace(blocks=blocks, block_s=10.0, stability=lambda *_: 1.0)

    def legends(sensor):
        figure = run_figure(run, sensor)
        return [t.get_text() for ax in figure.axes for t in ax.get_legend().get_texts()]

    sensor, resonator = legends(True), legends(False)
    assert "temperature sensor" in sensor and "resonator, from frequency" not in sensor
    assert "compensated, temperature-sensor model (10 s stability 1 °/h)" in sensor
    assert "resonator, from frequency" in resonator
    assert "compensated, frequency model (10 s stability 1 °/h)" in resonator


#: What a sensor model's outputs must not say: the paper's equation, table and figure
#: numbers, and the resonator's words (the C and column names ``resonator_c_est``,
#: ``resonator_c_<axis>`` are names of the interface, the same for both, and are left out).
PAPER_WORDS = re.compile(r"Eq\.|Eq \(|Eqs\.|Table [0-9]|Fig\. ?[0-9]|resonator|natural frequency"
                         r"|frequency model", re.IGNORECASE)
INTERFACE_NAMES = re.compile(r"resonator_c\w*")


def _paper_words(text: str) -> list[str]:
    """Each place of ``text`` that says a paper number or a resonator word, with context."""
    text = INTERFACE_NAMES.sub("", re.sub(r"data:image/[^\"']*", "", text))
    return [text[max(0, m.start() - 60):m.end() + 30] for m in PAPER_WORDS.finditer(text)]


def test_no_paper_numbers_or_resonator_words_in_any_output_of_a_sensor_model(tmp_path,
                                                                            monkeypatch):
    """Every command on the real cold test's sensor model (issue 27 item 6: ``calibrate``
    printed "drift model (Eq. 22)" and "Eq. (22) form" for a MEMS temperature sensor):
    calibrate (text and --json), info, compensate (its output and the file's mark),
    evaluate, report (HTML), export-c (C double and single, parameter file) and simulate
    of a sensor logger (README "Real loggers") say no equation, table or figure number of
    the paper and no resonator word."""
    from hrgtc.cli import _app

    monkeypatch.setattr(_app.console, "width", 200)
    monkeypatch.chdir(tmp_path)
    outputs: dict[str, str] = {}

    def run(name: str, *args: str) -> None:
        result = runner.invoke(app, list(args), terminal_width=200)
        assert result.exit_code == 0, (name, result.output)
        outputs[name] = result.output

    model = str(tmp_path / "pan.json")
    calibrate = ["calibrate", "--drift", str(RUN), *READ, *REF, "--holdout-fraction", "0.4"]
    run("calibrate", *calibrate, "-o", model)
    run("calibrate --json", *calibrate, "-o", str(tmp_path / "again.json"), "--json")
    scaled = [*READ, "--temp-scale", "0.00586994", "--temp-offset", "24.2787"]
    run("info", "info", str(RUN), *scaled)
    run("info --json", "info", str(RUN), *scaled, "--json")
    run("compensate", "compensate", str(RUN), "--model", model, *READ, "-o", "out.csv")
    run("compensate --json", "compensate", str(RUN), "--model", model, *READ, "-o",
        "out2.csv", "--json")
    outputs["compensated file's comments"] = "\n".join(
        line for line in Path("out.csv").read_text().splitlines() if line.startswith("#"))
    run("evaluate", "evaluate", str(RUN), "--model", model, *READ)
    run("evaluate --json", "evaluate", str(RUN), "--model", model, *READ, "--json")
    run("report", "report", "--model", model, str(RUN), *READ, "-o", "pan.html")
    run("export-c", "export-c", model, "-o", "c")
    run("export-c single", "export-c", model, "-o", "c32", "--precision", "single")
    run("export-c params", "export-c", model, "-o", "params", "--format", "params")
    logger = ["simulate", "--logger", "burst", "--unit", "mems-3", "--profile", "cooldown",
              "--start", "22", "--end", "5", "--hours", "0.5", "--rate-hz", "50", "--burst-s",
              "5", "--period-s", "300", "--time-unit", "ms", "--rate-unit", "radps",
              "--rate-digits", "3", "--spikes", "3"]
    run("simulate --logger", *logger, "-o", "cold.csv")
    run("simulate --logger --json", *logger, "-o", "cold2.csv", "--json")
    written = [Path("pan.html"), *Path("c").iterdir(), *Path("c32").iterdir(),
               *Path("params").iterdir(), *Path().glob("cold.*")]
    for path in written:
        outputs[str(path)] = path.read_text(encoding="utf-8")
    assert len(written) >= 3 + 2 * 6 + 1 + 3  # report, 2 C builds x 3 axes, params, logger
    assert "drift model (temperature sensor)" in outputs["calibrate"]
    assert "drift model: B = " in " ".join(outputs["calibrate"].split())
    found = {name: hits for name, text in outputs.items() if (hits := _paper_words(text))}
    assert not found, found
