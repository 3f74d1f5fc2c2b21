"""Named real-logger simulations: the two real recordings of issue 20, reproducible.

* ``pan-cold``: like ``tests/data/pan-cold-test/pan_tvc_cold_2020-03-07.csv``: a
  three-axis MEMS gyro (``mems-3``) at rest in a chamber cooling it by about 13 °C in 2 h,
  logged at 50 Hz in 5 s bursts every 305 s (a burst then 300 s asleep), time in ms
  from 15352 ms with ~0.5 ms jitter, its magnetometer columns (not read), rates in rad/s to
  three significant digits, the
  temperature a signed 16-bit count stored unsigned (65236 = -300), three
  single-sample spikes, and a hand log every 5 min with clock times ``HH:MM``, °F and °C
  columns, blank cells, trailing empty columns and a byte-order mark (its probe lags
  the sensor by 5 min).
* ``fridge-3day``: the IMU of issue 20's second recording: ``mems-3`` at rest for three
  days at 1 Hz through a refrigerator cycle between 24 and 5 °C, in three orientations
  with handling bursts up to 560 °/s between them (accelerometer columns show them; the
  hands warm the sensor by 3.8 °C, as the real unit's handling samples read 27.8 °C),
  rates in mrad/s, the temperature in °C to 1/100.

Each is a chamber profile, a unit and a :class:`~hrgtc.simulate.logger.Logger`;
:func:`preset` returns them, and the CLI's options override the logger's fields.
"""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.core.errors import InputError
from hrgtc.simulate.handling import Handling
from hrgtc.simulate.logger import Logger
from hrgtc.simulate.mems import G_SENSITIVITY_DPH_PER_G, MEMS_UNIT
from hrgtc.simulate.profiles import Profile, Segment
from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel
from hrgtc.simulate.standard_profiles import cooldown

__all__ = ["PRESETS", "LoggerPreset", "preset"]

#: Names of the presets, for ``hrgtc simulate --logger NAME``.
PRESETS = ("pan-cold", "fridge-3day")


@dataclass(frozen=True)
class LoggerPreset:
    """A named simulation of a real logger: chamber profile, unit and logger."""

    name: str
    profile: Profile
    unit: str
    logger: Logger


def _pan_cold() -> LoggerPreset:
    profile = cooldown(21.5, 5.0, hours=2.04, ramp_c_per_min=0.14)
    names = {"time": "time (ms)", "temperature": "temp"}
    names.update({f"rate_{a}": f"gyro{a} rad/s" for a in "xyz"})
    logger = Logger(
        kind="burst", sample_rate_hz=50.0, burst_s=5.0, period_s=305.0, time_unit="ms",
        clock_start_s=15.352, jitter_s=0.5e-3, rate_unit="radps", rate_digits=3,
        frequency=False,
        # 1/160 °C per count, count -300 at 21.5 °C, stored as an unsigned 16-bit value.
        temperature=TemperatureChannel(lsb_c=0.00625, offset_c=23.375, bits=16, noise_c=0.01),
        # Started so that the logger's clock read 0 at 15:44:25 (its first sample, at
        # 15352 ms, comes 15.352 s later).
        reference_log=ReferenceLog(every_s=300.0, start="2020-03-07T15:44:40.352", lag_s=300.0,
                                   trailing_rows=13, empty_columns=14),
        spikes=3, spike_dph=-6200.0, columns=names,
        # The magnetometer the real file logs too (hrgtc does not read it). [T]
        extra_columns={"mag1x [T]": (-1.7e-5, 3e-7), "mag1y [T]": (2.8e-5, 3e-7),
                       "mag1z [T]": (2.8e-5, 3e-7)},
    )
    return LoggerPreset("pan-cold", profile, MEMS_UNIT, logger)


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
    logger = Logger(
        kind="continuous", sample_rate_hz=1.0, time_unit="ms", rate_unit="mradps",
        rate_digits=4, frequency=False,
        temperature=TemperatureChannel(decimals=2, noise_c=0.02),
        # Hands warm it by 3.8 °C (the real unit's handling samples read 27.8 °C at 24 °C).
        handling=Handling(orientations=3, handling_s=60.0, max_rate_dps=560.0,
                          g_sensitivity_dph_per_g=G_SENSITIVITY_DPH_PER_G,
                          hand_warming_c=3.8),
        accelerometer=True, accel_unit="mps2", columns=names,
    )
    return LoggerPreset("fridge-3day", profile, MEMS_UNIT, logger)


def preset(name: str) -> LoggerPreset:
    """The named preset (:data:`PRESETS`)."""
    if name == "pan-cold":
        return _pan_cold()
    if name == "fridge-3day":
        return _fridge_3day()
    raise InputError(f"unknown logger preset {name!r}; choose one of {', '.join(PRESETS)}")
