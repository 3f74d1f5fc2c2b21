"""Typed parameters (issue 22): every default is written once, in a settings dataclass, and
``--help``, the docs' option tables and a fresh model file show that same default."""

from __future__ import annotations

import dataclasses
import json
import re
from pathlib import Path

import pytest
import typer.main
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.cli.options_tables import DOCUMENTED, settings_class, update_docs
from hrgtc.cli.params import _value, option_settings
from hrgtc.settings import Setting, format_value, settings_of
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.drift import EQ21_TERMS, WARMUP_FACTOR, DriftSettings
from hrgtc.settings.inputs import CalibrationInputs
from hrgtc.settings.reading import ReadSettings

DOCS = Path(__file__).resolve().parents[2] / "docs"
#: The docs page of each table of :data:`hrgtc.cli.options_tables.DOCUMENTED`.
PAGES = {"calibrate": DOCS / "guide" / "calibrate.md", "reading": DOCS / "guide" / "index.md",
         "calibrate_inputs": DOCS / "guide" / "calibrate.md",
         "temperature_reference": DOCS / "real-loggers" / "sensors.md",
         "holdout": DOCS / "real-loggers" / "time.md",
         "compensate": DOCS / "guide" / "compensate.md",
         "evaluate": DOCS / "guide" / "evaluate.md", "report": DOCS / "guide" / "report.md",
         "export": DOCS / "guide" / "export-c.md", "demo": DOCS / "guide" / "demo.md",
         "fleet_simulate": DOCS / "guide" / "fleet.md",
         "fleet_calibrate": DOCS / "guide" / "fleet.md",
         "fleet_evaluate": DOCS / "guide" / "fleet.md",
         "fleet_cluster": DOCS / "guide" / "fleet.md",
         "simulate": DOCS / "guide" / "simulate.md",
         "simulate_logger": DOCS / "real-loggers" / "simulate.md",
         "update": DOCS / "guide" / "update.md"}
#: The commands whose options each settings class generates.
COMMANDS = {"calibrate": ["calibrate"], "calibrate_inputs": ["calibrate"],
            "temperature_reference": ["calibrate"], "holdout": ["calibrate"],
            "reading": ["info", "calibrate", "compensate", "evaluate", "report",
                        "fleet calibrate", "fleet evaluate", "fleet report", "update"],
            "compensate": ["compensate"], "evaluate": ["evaluate"], "report": ["report"],
            "export": ["export-c"], "demo": ["demo"], "fleet_simulate": ["fleet simulate"],
            "fleet_calibrate": ["fleet calibrate"],
            "fleet_evaluate": ["fleet evaluate"],
            "fleet_cluster": ["fleet simulate", "fleet calibrate", "fleet evaluate",
                              "fleet report"],
            "simulate": ["simulate"],
            "simulate_logger": ["simulate"], "update": ["update"]}
CASES = [(key, s) for key in DOCUMENTED for s in option_settings(settings_class(key))]


def _click_option(command: str, setting: Setting):
    import click

    cmd = typer.main.get_command(app)
    for word in command.split():
        cmd = cmd.commands[word]  # type: ignore[attr-defined]
    ctx = click.Context(cmd, info_name=command)
    first = setting.option.split("/")[0].split()[0]
    (param,) = [p for p in cmd.params if first in p.opts]
    return param, param.get_help_record(ctx)


def test_every_option_has_a_table():
    assert set(DOCUMENTED) == set(PAGES) == set(COMMANDS)
    # 16 of calibrate, 9 of its inputs (again 6 + 2 on their pages), 16 of reading, 12 of
    # the other commands
    assert len(CASES) >= 61


@pytest.mark.parametrize(("key", "setting"), CASES, ids=[s.option for _, s in CASES])
def test_help_shows_the_dataclass_default(key, setting):
    for command in COMMANDS[key]:
        param, (_, text) = _click_option(command, setting)
        # the value a command passes on when the option is not given
        assert _value(setting, param.default) == setting.default, (command, setting.option)
        # "[default: 32; x>=1]": click adds a number's range after the default
        shown = re.search(r"\[default: (.*?)(; [-\d.]*<?=?x[<>]?=?[-\d.]*)?\]$",
                          " ".join(text.split()))
        if setting.default in (None, ()) and setting.default_text is None:
            assert shown is None  # not given: none (a repeated option: no item)
        elif isinstance(setting.default, bool) and "/" not in setting.option:
            assert shown is None and setting.default is False  # a flag: off unless given
        elif isinstance(setting.default, bool):
            assert shown is not None and shown.group(1) == (
                setting.option.split("/")[0 if setting.default else 1].strip().lstrip("-"))
        elif setting.default_text is not None:
            assert shown is not None and shown.group(1) == f"({setting.default_text})"
        else:
            assert shown is not None and shown.group(1) == format_value(setting.default)
        assert setting.help.rstrip(".").split(" [")[0][:40] in " ".join(text.split())
        if setting.min is not None or setting.max is not None:  # click's range, e.g. x>=1
            bounds = [f"{b:g}" for b in (setting.min, setting.max) if b is not None]
            assert shown.group(2) and all(b in shown.group(2) for b in bounds), setting.option


@pytest.mark.parametrize("key", sorted(DOCUMENTED))
def test_docs_tables_are_generated_from_the_dataclasses(key):
    page = PAGES[key].read_text(encoding="utf-8")
    assert update_docs(page) == page, (
        f"{PAGES[key]} is stale: PYTHONPATH=src python -m hrgtc.cli.options_tables {PAGES[key]}")
    block = page.split(f"<!-- options: {key} -->")[1].split("<!-- /options -->")[0]
    rows = {}
    for line in block.strip().splitlines()[2:]:
        option, default, _ = (c.strip() for c in re.split(r"(?<!\\)\|", line)[1:4])
        rows[option.strip("`")] = default.replace("\\|", "|")
    expected = {s.option: s.shown_default() for s in option_settings(settings_class(key))}
    assert rows == expected
    known = {"calibrate": ("--rate-tau-s", "10.0"), "reading": ("--spike-k", "8.0"),
             "evaluate": ("--deviation", "oadev"), "fleet_simulate": (
                 "--setpoints", "-20,-10,0,10,20,30,40"),  # Table 1 of [1]
             "simulate_logger": ("--period-s", "300.0; pan-cold 305.0")}
    if key in known:
        assert rows[known[key][0]] == known[key][1]


def test_a_value_out_of_range_is_refused_naming_the_range(tmp_path):
    """``fleet simulate --units 0`` and ``--seed -1`` are refused before anything runs (the
    ``min`` of the field), naming the option and the bound; the docs list the range."""
    by_name = {s.name: s for s in option_settings(settings_class("fleet_simulate"))}
    assert (by_name["units"].min, by_name["seed"].min) == (1, 0)
    for args, bound in ((["--units", "0"], "1"), (["--seed", "-1"], "0")):
        result = CliRunner().invoke(app, ["fleet", "simulate", *args,
                                          "-o", str(tmp_path / "fleet")])
        assert result.exit_code == 2, result.output
        message = " ".join(result.output.split())
        assert f"Invalid value for '{args[0]}'" in message and bound in message
        assert not (tmp_path / "fleet").exists()
    page = PAGES["fleet_simulate"].read_text(encoding="utf-8")
    assert "| `--units` | 32 | Number of units. Range: ≥ 1. |" in page


def _logger_value(logger, name):
    """The value of ``--logger`` option ``name`` in a simulator ``Logger`` (the inverse of
    ``logger_presets.with_options``, read off the objects the simulator uses)."""
    from hrgtc.simulate.handling import Handling
    from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel

    temperature = logger.temperature or TemperatureChannel()
    handling = logger.handling or Handling(orientations=1)
    reference = logger.reference_log or ReferenceLog()
    inside = {"temp_lsb": temperature.lsb_c, "temp_offset": temperature.offset_c,
              "temp_bits": temperature.bits, "temp_rate_hz": temperature.rate_hz,
              "reference_log": logger.reference_log is not None,
              "reference_lag_s": reference.lag_s, "orientations": handling.orientations,
              "handling_max_dps": handling.max_rate_dps,
              "hand_warming_c": handling.hand_warming_c, "jitter_ms": logger.jitter_s * 1e3,
              "wall_start": logger.start, "tz": logger.timezone, "restarts": logger.restarts_s}
    return inside[name] if name in inside else getattr(logger, name)


@pytest.mark.parametrize("kind", ["continuous", "burst", "pan-cold", "fridge-3day"])
def test_logger_defaults_shown_are_the_simulators(kind):
    """Each ``--logger`` option's default text names, for each logger, the value the
    simulator's logger really has when the option is not given (the plain logger's
    ``Logger`` defaults, a preset's values), and the preset's unit and sample rate."""
    from hrgtc.settings.simulation import (
        LOGGER_KINDS,
        PLAIN_LOGGER,
        PRESET_CHANGES,
        LoggerSettings,
    )
    from hrgtc.simulate.logger_presets import plain_logger, preset

    assert LOGGER_KINDS == ("continuous", "burst", "pan-cold", "fridge-3day")
    values = {**PLAIN_LOGGER, **PRESET_CHANGES.get(kind, {})}
    if kind in PRESET_CHANGES:
        chosen = preset(kind)
        logger, unit = chosen.logger, chosen.unit
    else:
        unit = PLAIN_LOGGER["unit"]
        logger = plain_logger(kind, unit)
    assert unit == values["unit"] and logger.sample_rate_hz == values["sample_rate_hz"]
    assert logger.kind == values.get("kind", kind)
    for setting in option_settings(LoggerSettings):
        if setting.name == "logger":
            continue
        value, expected = _logger_value(logger, setting.name), values[setting.name]
        assert value == (pytest.approx(expected) if isinstance(value, float) else expected), (
            kind, setting.option, value)
        # "300.0; pan-cold 305.0": the plain logger's, then "preset[/preset] value"
        plain, *others = setting.default_text.split("; ")
        shown = {"plain": plain}
        for part in others:
            presets, text = part.split(" ")
            shown.update(dict.fromkeys(presets.split("/"), text))
        assert shown.get(kind, plain) == (format_value(expected) if expected != () else "none"), (
            kind, setting.option, setting.default_text)


def test_stale_docs_table_is_found():
    page = PAGES["calibrate"].read_text(encoding="utf-8")
    stale = page.replace("| `--rate-tau-s` | 10.0 |", "| `--rate-tau-s` | 12.0 |")
    assert stale != page and update_docs(stale) == page


def test_derived_help_follows_its_constant():
    """The help of --rate-tau2-s and --warmup-s comes from the constants the fit uses."""
    from hrgtc.drift.variables.d2 import TAU2_FACTOR, derive

    by_name = {s.name: s for s in settings_of(DriftSettings)}
    assert by_name["rate_tau2_s"].default_text == f"{TAU2_FACTOR:g} × --rate-tau-s"
    assert by_name["warmup_s"].default_text.startswith(f"{WARMUP_FACTOR:g} ×")
    given = {**DriftSettings().variable_options(), "rate_tau_s": DriftSettings.rate_tau_s}
    assert derive(("d2",), given) == {"rate_tau2_s": TAU2_FACTOR * DriftSettings.rate_tau_s}
    assert DriftSettings(rate_tau_s=20.0).warmup(0.0) == WARMUP_FACTOR * 20.0
    assert EQ21_TERMS[0] == "f" and len(EQ21_TERMS) == 9  # Eq. (21) of [1]: nine terms


def test_library_defaults_come_from_the_dataclasses():
    """``drift.fit``, ``read``, ``iter_chunks`` and ``describe`` take the fields' defaults."""
    import inspect

    from hrgtc.drift import FeatureSettings, fit
    from hrgtc.drift.fit_stages import drift_settings
    from hrgtc.recording import ReadOptions, describe, iter_chunks, read

    parameters = inspect.signature(fit).parameters  # one settings object, no field repeated
    assert parameters["settings"].default is None
    assert not {f.name for f in dataclasses.fields(DriftSettings)} & set(parameters)
    assert drift_settings(None, {})[0] == DriftSettings()  # None: the fields' defaults
    assert drift_settings(None, {"premove": 0.2})[0] == DriftSettings(premove=0.2)
    assert FeatureSettings(1.0, 1.0).rate_tau_s == DriftSettings().rate_tau_s
    fields = {f.name for f in dataclasses.fields(ReadSettings)}
    for function in (read, iter_chunks, describe):  # one options object, no field repeated
        assert not fields & set(inspect.signature(function).parameters), function.__name__
    assert issubclass(ReadOptions, ReadSettings)


#: The fields of TemperatureReferenceSettings, by the key of TemperatureReference.to_dict.
REFERENCE_FIELDS = {"reference_log": "path", "reference_columns": "columns",
                    "reference_unit": "unit", "reference_start": "start", "reference_tz": "tz",
                    "reference_lag_s": "lag_s"}


def test_reference_defaults_are_the_libraries():
    """What a model file records of a reference log given alone (``--temp-ref LOG``) holds
    the other fields' defaults; the lag's default text names the library's search range;
    ``calibrate`` defaults to no channel, no log and no holdout."""
    import inspect

    from hrgtc.pipeline.calibration import calibrate, temperature_reference
    from hrgtc.pipeline.terms import parse_aux
    from hrgtc.settings.inputs import TemperatureReferenceSettings
    from hrgtc.thermometry.reference import (
        MAX_LAG_S,
        TemperatureReference,
        fit_count_map,
        parse_reference_columns,
    )

    defaults = TemperatureReferenceSettings(reference_log=Path("log.csv"))
    recorded = TemperatureReference(
        defaults.reference_log, parse_reference_columns(list(defaults.reference_columns)),
        unit=defaults.reference_unit, start=defaults.reference_start,
        tz=defaults.reference_tz, lag_s=defaults.reference_lag_s).to_dict()
    library = TemperatureReference("log.csv").to_dict()
    assert recorded == library
    assert set(REFERENCE_FIELDS.values()) == set(library)
    for name, key in REFERENCE_FIELDS.items():
        value = getattr(defaults, name)
        expected = {} if value == () else str(value) if isinstance(value, Path) else value
        assert library[key] == expected, name
    assert inspect.signature(fit_count_map).parameters["max_lag_s"].default == MAX_LAG_S
    by_name = {s.name: s for s in settings_of(TemperatureReferenceSettings)}
    assert by_name["reference_lag_s"].default_text == f"fitted within ±{MAX_LAG_S:g} s"
    assert inspect.signature(calibrate).parameters["inputs"].default is None  # the defaults:
    given = CalibrationInputs()
    assert parse_aux(given.aux) == {}
    assert temperature_reference(given.reference) is None
    assert (given.holdout.holdout_s, given.holdout.holdout_fraction) == (None, None)


@pytest.mark.slow
def test_fresh_model_file_records_the_defaults(paper_campaign, tmp_path):
    """``hrgtc calibrate`` with no option of the fit: the model file's provenance holds
    every field's default, the drift model's feature settings its filter."""
    files = paper_campaign
    out = tmp_path / "unit.json"
    result = CliRunner().invoke(app, ["calibrate", *[a for s in files.soaks for a in
                                                     ("--soak", str(s))],
                                      "--drift", str(files.cooldown), "-o", str(out), "--json"])
    assert result.exit_code == 0, result.output
    model = json.loads(out.read_text())
    recorded = model["provenance"]["settings"]
    for setting in settings_of(CalibrationSettings):
        value = recorded[setting.name]
        if setting.name == "terms":  # None: resolved to the default candidates
            assert tuple(value) in (EQ21_TERMS, ("f", "f^2", "f^3", "g", "f*g", "f^2*g"))
            continue
        expected = (list(setting.default) if isinstance(setting.default, tuple)
                    else setting.default)
        assert value == expected, setting.name
    assert recorded["motion"] == ReadSettings.motion
    given = {s.name: s.default for s in settings_of(CalibrationInputs)}
    assert set(given) == {"aux", "holdout_s", "holdout_fraction", *REFERENCE_FIELDS}
    assert recorded["aux"] == dict(given["aux"]) == {}  # () given: no channel
    assert (recorded["holdout_s"], recorded["holdout_fraction"]) == (
        given["holdout_s"], given["holdout_fraction"])
    # no log: no temperature_reference (its fields' defaults: test_reference_defaults_...)
    assert given["reference_log"] is None and "temperature_reference" not in recorded
    (axis,) = model["axes"].values() if "axes" in model else (model,)
    features = axis["drift"]["settings"]
    assert features["rate_tau_s"] == DriftSettings.rate_tau_s
    rate_free = not any(v in term for term in axis["drift"]["selected"]
                        for v in ("df", "dh", "d2"))
    # no rate term chosen: no filter to wait for, the warm-up is trained on (0 s)
    assert features["warmup_s"] == (0.0 if rate_free else
                                    WARMUP_FACTOR * DriftSettings.rate_tau_s)
