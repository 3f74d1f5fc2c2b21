"""The loggers of ``hrgtc simulate --logger``: the plain ones and the named presets.

The presets are the two real recordings of issue 20, reproducible:

* ``pan-cold``: like ``tests/data/pan-cold-test/pan_tvc_cold_2020-03-07.csv``: a
  three-axis MEMS gyro (``mems-3``) at rest in a chamber cooling it by about 13 °C in 2 h,
  logged in bursts, time in ms with jitter, its magnetometer columns (not read), rates in
  rad/s to a few significant digits, the temperature a signed count stored unsigned,
  single-sample spikes, and a hand log every 5 min with clock times ``HH:MM``, °F and °C
  columns, blank cells, trailing empty columns and a byte-order mark, its probe lagging
  the sensor.
* ``fridge-3day``: the IMU of issue 20's second recording: ``mems-3`` at rest for three
  days through a refrigerator cycle between 24 and 5 °C, in three orientations with
  handling bursts between them (accelerometer columns show them; the hands warm the
  sensor), rates in mrad/s, the temperature in °C to 1/100.

The values a ``--logger`` option sets are written once, in
:data:`hrgtc.settings.simulation.PLAIN_LOGGER` (the plain logger) and
:data:`~hrgtc.settings.simulation.PRESET_CHANGES` (what each preset changes), which the
options' help shows; this module adds what is not an option (the chamber program, the
column names, the sensor noise, the hand log's quirks). :func:`preset` returns a preset's
profile, unit and logger, :func:`plain_logger` the plain one, and :func:`with_options`
applies option values (a preset's, or the CLI's overrides) to a logger.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.settings.simulation import PLAIN_LOGGER, PRESET_CHANGES
from hrgtc.simulate.handling import Handling
from hrgtc.simulate.logger import Logger
from hrgtc.simulate.mems import G_SENSITIVITY_DPH_PER_G, MEMS_UNIT
from hrgtc.simulate.profiles import Profile, Segment
from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel
from hrgtc.simulate.standard_profiles import cooldown

__all__ = ["PRESETS", "LoggerPreset", "plain_logger", "preset", "with_options"]

#: Names of the presets, for ``hrgtc simulate --logger NAME``.
PRESETS = tuple(PRESET_CHANGES)
#: Option name -> the Logger field it sets, where they differ.
_LOGGER_FIELDS = {"wall_start": "start", "tz": "timezone", "restarts": "restarts_s"}
#: Option name -> the TemperatureChannel field it sets.
_TEMPERATURE_FIELDS = {"temp_lsb": "lsb_c", "temp_offset": "offset_c", "temp_bits": "bits",
                       "temp_rate_hz": "rate_hz"}
#: Option name -> the Handling field it sets.
_HANDLING_FIELDS = {"orientations": "orientations", "handling_max_dps": "max_rate_dps",
                    "hand_warming_c": "hand_warming_c"}


@dataclass(frozen=True)
class LoggerPreset:
    """A named simulation of a real logger: chamber profile, unit and logger."""

    name: str
    profile: Profile
    unit: str
    logger: Logger


def _changes(name: str) -> dict[str, Any]:
    """The option values preset ``name`` sets (without its unit)."""
    return {k: v for k, v in PRESET_CHANGES[name].items() if k != "unit"}


def _pan_cold() -> LoggerPreset:
    profile = cooldown(21.5, 5.0, hours=2.04, ramp_c_per_min=0.14)
    names = {"time": "time (ms)", "temperature": "temp"}
    names.update({f"rate_{a}": f"gyro{a} rad/s" for a in "xyz"})
    base = Logger(
        frequency=False, temperature=TemperatureChannel(noise_c=0.01),
        # Started so that the logger's clock read 0 at 15:44:25 (its first sample, at
        # 15352 ms, comes 15.352 s later).
        reference_log=ReferenceLog(every_s=300.0, start="2020-03-07T15:44:40.352",
                                   trailing_rows=13, empty_columns=14),
        columns=names,
        # The magnetometer the real file logs too (hrgtc does not read it). [T]
        extra_columns={"mag1x [T]": (-1.7e-5, 3e-7), "mag1y [T]": (2.8e-5, 3e-7),
                       "mag1z [T]": (2.8e-5, 3e-7)},
    )
    logger = with_options(base, MEMS_UNIT, _changes("pan-cold"))
    return LoggerPreset("pan-cold", profile, PRESET_CHANGES["pan-cold"]["unit"], logger)


def _fridge_3day() -> LoggerPreset:
    profile = Profile(
        (
            Segment(24.0, hold_h=4.0),
            Segment(5.0, ramp_c_per_min=0.1),
            Segment(5.0, hold_h=24.0),
            Segment(24.0, ramp_c_per_min=0.05),
            Segment(24.0, hold_h=72.0 - 4.0 - 24.0 - (19.0 / 0.1 + 19.0 / 0.05) / 60.0),
        ),
        start_c=24.0,
        name="fridge_3day",
        description="refrigerator cycle 24 -> 5 -> 24 C over 72 h",
    )
    names = {"time": "timestamp_ms", "temperature": "temp_C"}
    names.update({f"rate_{a}": f"g{a}_mrad_s" for a in "xyz"})
    names.update({f"accel_{a}": f"a{a}_m_s2" for a in "xyz"})
    base = Logger(
        frequency=False, temperature=TemperatureChannel(decimals=2, noise_c=0.02),
        handling=Handling(handling_s=60.0, g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G),
        accel_unit="mps2", columns=names,
    )
    logger = with_options(base, MEMS_UNIT, _changes("fridge-3day"))
    return LoggerPreset("fridge-3day", profile, PRESET_CHANGES["fridge-3day"]["unit"], logger)


def preset(name: str) -> LoggerPreset:
    """The named preset (:data:`PRESETS`)."""
    if name == "pan-cold":
        return _pan_cold()
    if name == "fridge-3day":
        return _fridge_3day()
    raise InputError(f"unknown logger preset {name!r}; choose one of {', '.join(PRESETS)}")


def plain_logger(kind: str, unit: str) -> Logger:
    """The logger of ``--logger continuous`` or ``burst`` (:data:`PLAIN_LOGGER`) for ``unit``:
    an HRG writes its resonator frequency and no temperature, a MEMS unit its die
    temperature in °C."""
    mems = unit == MEMS_UNIT
    return Logger(kind=kind, sample_rate_hz=PLAIN_LOGGER["sample_rate_hz"], frequency=not mems,
                  temperature=TemperatureChannel(decimals=2) if mems else None)


def with_options(base: Logger, unit: str, values: Mapping[str, Any]) -> Logger:
    """``base`` with the ``--logger`` option values given (by option name, as
    :class:`~hrgtc.settings.simulation.LoggerSettings` names them; None: not given).

    A temperature option on a logger without a temperature channel adds one (a MEMS
    unit's die sensor, an HRG's housing thermistor); ``reference_log`` True or a
    ``reference_lag_s`` adds a hand log, False removes it; a handling option on a logger
    without handling adds it (one orientation unless ``orientations`` says more; a MEMS
    unit's g-sensitivity); ``accelerometer`` False drops the accelerometer columns with
    their names.
    """
    given = {k: v for k, v in values.items() if v is not None}
    mems = unit == MEMS_UNIT
    temperature = {_TEMPERATURE_FIELDS[k]: given.pop(k) for k in list(given)
                   if k in _TEMPERATURE_FIELDS}
    if temperature:
        # An HRG's temperature sensor sits on the housing; a MEMS die has its own.
        channel = base.temperature or TemperatureChannel(source="die" if mems else "housing")
        base = replace(base, temperature=replace(channel, **temperature))
    reference, lag = given.pop("reference_log", None), given.pop("reference_lag_s", None)
    if reference is False:
        base = replace(base, reference_log=None)
    elif reference or lag is not None:
        log = base.reference_log or ReferenceLog()
        base = replace(base, reference_log=log if lag is None else replace(log, lag_s=lag))
    handling = {_HANDLING_FIELDS[k]: given.pop(k) for k in list(given) if k in _HANDLING_FIELDS}
    if handling:
        start = base.handling or Handling(
            orientations=PLAIN_LOGGER["orientations"],
            g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G if mems else {})
        base = replace(base, handling=replace(start, **handling))
    if given.get("accelerometer") is False:  # the preset's names of its columns go too
        given["columns"] = {role: name for role, name in base.columns.items()
                            if not role.startswith("accel_")}
    if "jitter_ms" in given:
        given["jitter_s"] = given.pop("jitter_ms") * 1e-3
    return replace(base, **{_LOGGER_FIELDS.get(k, k): v for k, v in given.items()})
