"""Settings of ``hrgtc simulate``: the chamber program and the simulated run.

A profile's parameters take defaults that depend on its kind (a soak holds 5 h, a
rate-table plateau 3 h, a ramp 0 h); they are written once, in :data:`PROFILE_DEFAULTS`,
which :func:`hrgtc.simulate.standard_profiles.build` uses and from which the options'
help texts are generated (:func:`per_kind`), so ``--help``, the docs and the simulator
agree. A field None is "the kind's default" (or the ``--logger`` preset's).

The ``--logger`` options (:class:`LoggerSettings`) work the same way: the plain logger's
values (``--logger continuous|burst``) are one table, :data:`PLAIN_LOGGER`, from which the
simulator's :class:`~hrgtc.simulate.logger.Logger` (and its temperature channel, reference
log and handling) take their defaults; what each preset changes is one table,
:data:`PRESET_CHANGES`, from which :mod:`hrgtc.simulate.logger_presets` builds the preset;
the options' default texts are generated from both (:func:`per_preset`).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from hrgtc.settings import format_value, setting
from hrgtc.settings.fleet import SETPOINTS_C

#: The simulated gyros (:mod:`hrgtc.simulate.units`) and the default one.
UNIT_NAMES = ("paper-unit", "unit-b", "unit-play", "imu-3", "mems-3")
DEFAULT_UNIT = "paper-unit"
#: Known constant input rate of a single-axis run (e.g. the Earth-rate component). [°/h]
DEFAULT_INPUT_RATE_DPH = 10.0
#: Sample rate of a simulated run without a logger preset (Section 3 of [1]). [Hz]
DEFAULT_SAMPLE_RATE_HZ = 200.0
#: Room temperature: where the chamber starts. [°C]
ROOM_TEMPERATURE_C = 20.0
#: Chamber ramp rate of a cool-down, warm-up or ramp. [°C/min]
DEFAULT_RAMP_C_PER_MIN = 1.0
#: Rate-table plateaus. [°C]
DEFAULT_PLATEAUS_C = (-10.0, 10.0, 30.0, 50.0)
#: Rate-table rates. [°/s]
DEFAULT_TABLE_RATES_DPS = (0.0, 10.0, -10.0, 50.0, -50.0, 100.0, -100.0, 300.0, -300.0)
#: Marks a parameter a kind needs and has no default for.
REQUIRED = "required"

#: Each profile kind's parameters and their defaults (a parameter not listed does not
#: apply to that kind; ``hours`` applies to every kind).
PROFILE_DEFAULTS: dict[str, dict[str, Any]] = {
    "soak": {"setpoints_c": SETPOINTS_C, "hours": 5.0},  # Table 1 of [1], "4-5 h" per soak
    "cooldown": {"start_c": ROOM_TEMPERATURE_C, "end_c": -20.0, "hours": 5.0,
                 "ramp_c_per_min": DEFAULT_RAMP_C_PER_MIN},
    "warmup": {"start_c": -20.0, "end_c": ROOM_TEMPERATURE_C, "hours": 5.0,
               "ramp_c_per_min": DEFAULT_RAMP_C_PER_MIN},
    "constant": {"temperature_c": ROOM_TEMPERATURE_C, "hours": 5.0},
    "ramp": {"start_c": REQUIRED, "end_c": REQUIRED, "hours": 0.0,
             "ramp_c_per_min": DEFAULT_RAMP_C_PER_MIN},
    "ratetable": {"setpoints_c": DEFAULT_PLATEAUS_C, "start_c": ROOM_TEMPERATURE_C,
                  "hours": 3.0, "rates_dps": DEFAULT_TABLE_RATES_DPS, "rate_hold_s": 60.0},
}
#: Profile kinds (besides a JSON/YAML profile file).
PROFILE_KINDS = tuple(PROFILE_DEFAULTS)


def per_kind(name: str) -> str:
    """The defaults of parameter ``name`` by profile kind, as the help shows them
    (``"soak 5, cooldown 5, ..., ratetable 3"``; kinds sharing a value grouped)."""
    by_value: dict[str, list[str]] = {}
    for kind, defaults in PROFILE_DEFAULTS.items():
        if name in defaults:
            by_value.setdefault(format_value(defaults[name]), []).append(kind)
    return "; ".join(f"{'/'.join(kinds)} {value}" for value, kinds in by_value.items())


#: Units of the rates a simulated logger writes (``--rate-unit``).
LOGGER_RATE_UNITS = ("dph", "dps", "radps", "mradps")
#: Units of the time a simulated logger writes (``--time-unit``).
LOGGER_TIME_UNITS = ("s", "ms", "us", "timestamp")

#: The plain logger (``--logger continuous`` or ``burst``): the value of each ``--logger``
#: option when it is not given (and the unit and sample rate of the run). The simulator's
#: ``Logger``, ``TemperatureChannel``, ``ReferenceLog`` and ``Handling`` take their
#: defaults from here.
PLAIN_LOGGER: dict[str, Any] = {
    "unit": DEFAULT_UNIT, "sample_rate_hz": DEFAULT_SAMPLE_RATE_HZ,
    "burst_s": 5.0, "period_s": 300.0,  # 5 s of every 300 s in the PAN cold test
    "time_unit": "s", "wall_start": "2020-03-07T15:44:40", "tz": None, "counter_bits": None,
    "clock_start_s": 0.0, "jitter_ms": 0.0, "restarts": (), "run_offset_dph": 0.0,
    "warmup_dph": 0.0, "warmup_tau_s": 120.0, "rate_unit": "dph", "rate_digits": None,
    "temp_lsb": None, "temp_offset": 0.0, "temp_bits": None, "temp_rate_hz": None,
    "reference_log": False, "reference_lag_s": 0.0, "duplicates": 0, "spikes": 0,
    "spike_dph": 0.0, "orientations": 1, "handling_max_dps": 300.0, "hand_warming_c": 0.0,
    "accelerometer": False,
}
#: What each preset of ``--logger`` changes of :data:`PLAIN_LOGGER`: the two real
#: recordings of issue 20 (``hrgtc.simulate.logger_presets`` adds what is not an option:
#: the chamber program, column names, sensor noise, the hand log's quirks).
PRESET_CHANGES: dict[str, dict[str, Any]] = {
    # tests/data/pan-cold-test: 50 Hz bursts, 5 s of every 305 s, ms from 15352 ms with
    # ~0.5 ms jitter, rad/s to 3 digits, 1/160 °C per count with count -300 at 21.5 °C
    # stored as an unsigned 16-bit value, 3 spikes, a hand log 5 min behind the sensor.
    "pan-cold": {"kind": "burst", "unit": "mems-3", "sample_rate_hz": 50.0, "period_s": 305.0,
                 "time_unit": "ms", "clock_start_s": 15.352, "jitter_ms": 0.5,
                 "rate_unit": "radps", "rate_digits": 3, "temp_lsb": 0.00625,
                 "temp_offset": 23.375, "temp_bits": 16, "reference_log": True,
                 "reference_lag_s": 300.0, "spikes": 3, "spike_dph": -6200.0},
    # The IMU of the second recording: 1 Hz, mrad/s to 4 digits, three orientations with
    # handling up to 560 °/s, the hands warming it by 3.8 °C (its handling samples read
    # 27.8 °C at 24 °C), accelerometer columns.
    "fridge-3day": {"kind": "continuous", "unit": "mems-3", "sample_rate_hz": 1.0,
                    "time_unit": "ms", "rate_unit": "mradps", "rate_digits": 4,
                    "orientations": 3, "handling_max_dps": 560.0, "hand_warming_c": 3.8,
                    "accelerometer": True},
}
#: ``--logger``: the plain kinds, then the presets.
LOGGER_KINDS = ("continuous", "burst", *PRESET_CHANGES)


def _shown(value: Any) -> str:
    return "none" if value == () else format_value(value)


def per_preset(name: str) -> str:
    """The value of ``--logger`` option ``name`` when not given, as the help shows it: the
    plain logger's, then each preset's that differs (``"300.0; pan-cold 305.0"``)."""
    plain = PLAIN_LOGGER[name]
    by_value: dict[str, list[str]] = {}
    for preset, changes in PRESET_CHANGES.items():
        if name in changes and changes[name] != plain:
            by_value.setdefault(_shown(changes[name]), []).append(preset)
    return "; ".join([_shown(plain)] + [f"{'/'.join(presets)} {value}"
                                        for value, presets in by_value.items()])


_PROFILE = "Profile"
_RUN = "Run"
_LOGGER = "Logger (files as a real logger writes them, with ground truth)"


@dataclass(frozen=True)
class SimulationSettings:
    """The chamber program and the run of ``hrgtc simulate`` (without ``--logger``'s)."""

    profile: str | None = setting(
        None, "Chamber program: soak (one run per set-point), cooldown, warmup, constant, "
        "ramp, ratetable (plateaus from --setpoints, each soaked --hours then the --rates "
        "held --rate-hold-s each, axis after axis), or a JSON/YAML profile file (list of "
        "{setpoint_c, hold_h | ramp_c_per_min[, table_rate_dps, axis]} segments).",
        metavar="|".join(PROFILE_KINDS) + "|FILE.yaml",
        default_text="soak, or the --logger preset's program", panel=_PROFILE)
    setpoints_c: tuple[float, ...] | None = setting(
        None, "Soak set-points or rate-table plateaus (write --setpoints=-20,... when the "
        "list starts with a minus sign).", unit="°C", cli="--setpoints", metavar="T1,T2,...",
        default_text=per_kind("setpoints_c"), panel=_PROFILE)
    hours: float | None = setting(
        None, "Hours per soak, of the cool-down/warm-up/constant run, of the hold after a "
        "ramp, or of the soak at each rate-table plateau.", unit="h",
        default_text=per_kind("hours"), panel=_PROFILE)
    start_c: float | None = setting(
        None, "Start temperature of a cooldown, warmup, ramp or rate table.", unit="°C",
        cli="--start", default_text=per_kind("start_c"), panel=_PROFILE)
    end_c: float | None = setting(
        None, "End temperature of a cooldown, warmup or ramp.", unit="°C", cli="--end",
        default_text=per_kind("end_c"), panel=_PROFILE)
    temperature_c: float | None = setting(
        None, "Temperature of a constant run.", unit="°C", cli="--temperature",
        default_text=per_kind("temperature_c"), panel=_PROFILE)
    ramp_c_per_min: float | None = setting(
        None, "Chamber ramp rate of a cooldown, warmup or ramp.", unit="°C/min",
        cli="--ramp-rate", default_text=per_kind("ramp_c_per_min"), panel=_PROFILE)
    rates_dps: tuple[float, ...] | None = setting(
        None, "Rate-table rates.", unit="°/s", cli="--rates", metavar="W1,W2,...",
        default_text=per_kind("rates_dps"), panel=_PROFILE)
    rate_hold_s: float | None = setting(
        None, "Rate table: time each rate is held.", unit="s",
        default_text=per_kind("rate_hold_s"), panel=_PROFILE)
    single_file: bool = setting(
        False, "Soaks: one file visiting all set-points in sequence.", panel=_PROFILE)
    unit: str | None = setting(
        None, "Simulated gyro.", choices=UNIT_NAMES, default_text=per_preset("unit"),
        panel=_RUN)
    sample_rate_hz: float | None = setting(
        None, "Sample rate.", unit="Hz", cli="--sample-rate-hz --rate-hz",
        default_text=per_preset("sample_rate_hz"), panel=_RUN)
    seed: int = setting(0, "Random seed; the same seed gives the same files.", min=0,
                        panel=_RUN)
    input_rate_dph: float | None = setting(
        None, "Known constant rate on the sensitive axis (e.g. Earth rate); a value given "
        "applies to every axis of a multi-axis unit.", unit="°/h",
        default_text=f"{DEFAULT_INPUT_RATE_DPH:g}, or each axis's Earth-rate component for "
        "a multi-axis unit", panel=_RUN)

    def profile_options(self) -> dict[str, Any]:
        """The profile's parameters given (not None), as keywords of
        :func:`hrgtc.simulate.standard_profiles.build`."""
        names = ("setpoints_c", "hours", "start_c", "end_c", "temperature_c",
                 "ramp_c_per_min", "rates_dps", "rate_hold_s")
        words = {name: getattr(self, name) for name in names}
        return {**{k: v for k, v in words.items() if v is not None},
                "single_file": self.single_file}


@dataclass(frozen=True)
class LoggerSettings:
    """``hrgtc simulate --logger``: the files as a real logger writes them.

    A field None is the value of the logger chosen (:func:`per_preset`: the plain logger's,
    :data:`PLAIN_LOGGER`, or the preset's, :data:`PRESET_CHANGES`); a value given
    overrides it (:func:`hrgtc.simulate.logger_presets.with_options`).
    """

    logger: str | None = setting(
        None, "Write the run as a real logger does, with ground truth beside it "
        "(FILE.truth.json, FILE.truth.csv): continuous, burst (--burst-s of every --period-s "
        "from each power-on), or a preset: pan-cold (the PAN cold test of "
        "tests/data/pan-cold-test: MEMS bursts, a raw temperature count, a hand log), "
        "fridge-3day (a MEMS IMU in a fridge for 3 days, handled between orientations). "
        "The options below override the logger's values (their defaults).",
        choices=LOGGER_KINDS, metavar="|".join(LOGGER_KINDS), panel=_LOGGER)
    burst_s: float | None = setting(
        None, "Burst length of a burst logger.", unit="s",
        default_text=per_preset("burst_s"), panel=_LOGGER)
    period_s: float | None = setting(
        None, "Burst period: a burst starts every period from each power-on.", unit="s",
        default_text=per_preset("period_s"), panel=_LOGGER)
    time_unit: str | None = setting(
        None, "Unit of the written time since power-on (ms and µs as integers), or "
        "timestamp: ISO 8601 wall-clock times from --wall-start (they run on through "
        "restarts).", choices=LOGGER_TIME_UNITS, metavar="|".join(LOGGER_TIME_UNITS),
        default_text=per_preset("time_unit"), panel=_LOGGER)
    wall_start: str | None = setting(
        None, "Wall-clock time (local) of the run's start, for --time-unit timestamp.",
        metavar="ISO", default_text=per_preset("wall_start"), panel=_LOGGER)
    tz: str | None = setting(
        None, "Time zone of the wall clock (e.g. Europe/Berlin): a daylight-saving change "
        "in the run is a ±1 h step, as a logger set to local time writes (CSV only); none: "
        "no zone, no step.", metavar="ZONE", default_text=per_preset("tz"), panel=_LOGGER)
    counter_bits: int | None = setting(
        None, "Time as an unsigned counter of this many bits that wraps (32 bits of µs wrap "
        "every 71.6 min); none: no wrap.", default_text=per_preset("counter_bits"),
        panel=_LOGGER)
    clock_start_s: float | None = setting(
        None, "Clock reading at the first sample after each power-on (--restarts start "
        "from it again: keep it small with restarts, or hrgtc reads a gap, not a reset); "
        "near 4295 s (2^32 µs) to see a µs wrap early.", unit="s",
        default_text=per_preset("clock_start_s"), panel=_LOGGER)
    jitter_ms: float | None = setting(
        None, "Rms Gaussian jitter of each time stamp.", unit="ms",
        default_text=per_preset("jitter_ms"), panel=_LOGGER)
    restarts: tuple[float, ...] | None = setting(
        None, "Power cycles at these times: the logger is off a moment, then the clock, the "
        "bursts and the warm-up start again, and --run-offset-dph draws a new offset.",
        unit="s", metavar="T1,T2,...", default_text=per_preset("restarts"), panel=_LOGGER)
    run_offset_dph: float | None = setting(
        None, "Rms of a turn-on offset drawn for each run (the first included).", unit="°/h",
        default_text=per_preset("run_offset_dph"), panel=_LOGGER)
    warmup_dph: float | None = setting(
        None, "A warm-up transient after each power-on: this offset decaying with "
        "--warmup-tau-s (in the truth's offset_dph).", unit="°/h",
        default_text=per_preset("warmup_dph"), panel=_LOGGER)
    warmup_tau_s: float | None = setting(
        None, "Time constant of the warm-up.", unit="s",
        default_text=per_preset("warmup_tau_s"), panel=_LOGGER)
    rate_unit: str | None = setting(
        None, "Unit of the written rates.", choices=LOGGER_RATE_UNITS,
        metavar="|".join(LOGGER_RATE_UNITS), default_text=per_preset("rate_unit"),
        panel=_LOGGER)
    rate_digits: int | None = setting(
        None, "Significant digits of the written rates; none: full precision.",
        default_text=per_preset("rate_digits"), panel=_LOGGER)
    temp_lsb: float | None = setting(
        None, "Log the temperature as a raw count of this size (T = count × LSB + "
        "--temp-offset); none: in °C for a MEMS unit (its die), no temperature for an HRG.",
        unit="°C", default_text=per_preset("temp_lsb"), panel=_LOGGER)
    temp_offset: float | None = setting(
        None, "Temperature of count 0.", unit="°C", default_text=per_preset("temp_offset"),
        panel=_LOGGER)
    temp_bits: int | None = setting(
        None, "The signed count stored unsigned in this many bits (16: -300 is written "
        "65236); none: signed.", default_text=per_preset("temp_bits"), panel=_LOGGER)
    temp_rate_hz: float | None = setting(
        None, "A slower temperature channel: a new value at this rate, empty cells between; "
        "none: every row.", unit="Hz", default_text=per_preset("temp_rate_hz"),
        panel=_LOGGER)
    reference_log: bool | None = setting(
        None, "Write a hand-written reference log FILE_reflog.csv (HH:MM clock times, °F and "
        "°C columns, blank cells, BOM).", cli="--reference-log/--no-reference-log",
        default_text=per_preset("reference_log"), panel=_LOGGER)
    reference_lag_s: float | None = setting(
        None, "Lag of the reference probe behind the sensor.", unit="s",
        default_text=per_preset("reference_lag_s"), panel=_LOGGER)
    duplicates: int | None = setting(
        None, "Rows written twice (a logger re-sending a line; the truth's duplicate column "
        "marks the copies).", default_text=per_preset("duplicates"), panel=_LOGGER)
    spikes: int | None = setting(
        None, "Single-sample spikes to inject (their rows and sizes in the truth).",
        default_text=per_preset("spikes"), panel=_LOGGER)
    spike_dph: float | None = setting(
        None, "Size of each spike, sign included; 0: 50 σ of the rate noise, negative.",
        unit="°/h", default_text=per_preset("spike_dph"), panel=_LOGGER)
    orientations: int | None = setting(
        None, "Orientations visited, still, with handling (rotation bursts up to "
        "--handling-max-dps) between them.", default_text=per_preset("orientations"),
        panel=_LOGGER)
    handling_max_dps: float | None = setting(
        None, "Peak rotation rate of the handling.", unit="°/s",
        default_text=per_preset("handling_max_dps"), panel=_LOGGER)
    hand_warming_c: float | None = setting(
        None, "The hands warm the sensor by this much during each handling (its bias "
        "follows), cooling back afterwards.", unit="°C",
        default_text=per_preset("hand_warming_c"), panel=_LOGGER)
    accelerometer: bool | None = setting(
        None, "Write accelerometer columns.", cli="--accelerometer/--no-accelerometer",
        default_text=per_preset("accelerometer"), panel=_LOGGER)

    def given(self) -> dict[str, Any]:
        """The logger's values given (not None), by option name, without ``logger``."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if f.name != "logger" and getattr(self, f.name) is not None}
