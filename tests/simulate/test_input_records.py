"""The simulator's inputs through their records: the same JSON text as before them.

Truth: ``tests/data/simulate-truth/inputs.json``, written by the commit before the
records (``make_inputs.py`` beside it) from ``tests/simulate_inputs.py``.
"""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import pytest

import simulate_inputs
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.simulate import profiles
from hrgtc.simulate.handling import Handling
from hrgtc.simulate.logged_files import LoggedFiles
from hrgtc.simulate.logger import Logger
from hrgtc.simulate.logger_records import LoggerRecord
from hrgtc.simulate.reflog import (
    ReferenceLog,
    TemperatureChannel,
)

TRUTH = Path(__file__).parents[1] / "data" / "simulate-truth" / "inputs.json"


def test_every_input_writes_the_same_text_as_before():
    expected = TRUTH.read_text(encoding="utf-8")
    assert json.dumps(simulate_inputs.documents(), indent=1) + "\n" == expected


def _schema(record):
    return jsonschema.Draft202012Validator(
        records.json_schema(record, "r", "https://hrgtc.invalid/r.json"))


@pytest.mark.parametrize("name", sorted(simulate_inputs.profiles()))
def test_a_profile_round_trips_and_fits_its_schema(name):
    profile = simulate_inputs.profiles()[name]
    written = json.loads(json.dumps(profile.to_dict()))
    again = profiles.Profile.from_dict(written)
    assert again == profile and again.to_dict() == written
    _schema(profiles.ProfileRecord).validate(written)


@pytest.mark.parametrize("name", sorted(simulate_inputs.loggers()))
def test_a_logger_round_trips_and_fits_its_schema(name):
    logger = simulate_inputs.loggers()[name]
    written = json.loads(json.dumps(logger.to_dict()))
    again = Logger.from_dict(written)
    assert again == logger and again.to_dict() == written
    _schema(LoggerRecord).validate(written)
    for part, kind, record in (("temperature", TemperatureChannel, TemperatureChannel),
                               ("reference_log", ReferenceLog, ReferenceLog),
                               ("handling", Handling, Handling)):
        if written[part] is not None:
            assert kind.from_dict(written[part]).to_dict() == written[part]
            _schema(record).validate(written[part])


def test_logged_files_round_trip_and_fit_their_schema():
    for files in simulate_inputs.logged_files().values():
        written = json.loads(json.dumps(files.to_dict()))
        assert LoggedFiles.from_dict(written) == files
        _schema(LoggedFiles).validate(written)


def test_input_refusals_name_the_place():
    soak = simulate_inputs.profiles()["soak"].to_dict()
    bad = {**soak, "segments": [{"setpoint_c": 0.0, "hold_h": -1.0}]}
    with pytest.raises(InputError, match=r"`\$.segments\[0\].hold_h`"):
        profiles.Profile.from_dict(bad)
    with pytest.raises(InputError, match=r"unknown field `colour` - at `\$.segments\[0\]`"):
        profiles.Profile.from_dict({**soak, "segments": [{"setpoint_c": 0.0, "hold_h": 1.0,
                                                          "colour": "red"}]})
    logger = simulate_inputs.loggers()["every-part"].to_dict()
    with pytest.raises(InputError, match=r"`\$.handling.orientations`"):
        Logger.from_dict({**logger, "handling": {**logger["handling"], "orientations": 0}})
    with pytest.raises(InputError, match=r"`\$.temperature.source`"):
        Logger.from_dict({**logger, "temperature": {**logger["temperature"], "source": "x"}})
    with pytest.raises(InputError, match=r"`\$.rows`"):
        LoggedFiles.from_dict({**simulate_inputs.logged_files()["without"].to_dict(),
                               "rows": -1})


def test_a_logged_runs_sidecar_is_its_record():
    from hrgtc.simulate.logger import log_run
    from hrgtc.simulate.logger_records import LoggedRunRecord
    from hrgtc.simulate.standard_profiles import constant

    logger = simulate_inputs.loggers()["every-part"]
    logger = Logger.from_dict({**logger.to_dict(), "sample_rate_hz": 5.0, "spikes": 2,
                               "restarts_s": [900.0], "accelerometer": True})
    info = json.loads(json.dumps(log_run(constant(20.0, 0.5), "imu-3", logger, seed=4).info))
    _schema(LoggedRunRecord).validate(info)
    assert records.dump(None, LoggedRunRecord, **info) == info  # round trip
    assert info["handling_windows"] and "from" in info["handling_windows"][0]
    assert info["temperature"]["reference_log"]["readings"]
    with pytest.raises(InputError, match=r"`\$.segments\[0\].first_row`"):
        records.load({**info, "segments": [{**info["segments"][0], "first_row": -1}]},
                     LoggedRunRecord, "sidecar")
