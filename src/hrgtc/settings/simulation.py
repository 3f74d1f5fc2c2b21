"""Settings of ``hrgtc simulate``: the chamber program and the simulated run.

A profile's parameters take defaults that depend on its kind (a soak holds 5 h, a
rate-table plateau 3 h, a ramp 0 h); they are written once, in :data:`PROFILE_DEFAULTS`,
which :func:`hrgtc.simulate.standard_profiles.build` uses and from which the options'
help texts are generated (:func:`per_kind`), so ``--help``, the docs and the simulator
agree. A field None is "the kind's default" (or the ``--logger`` preset's).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from hrgtc.settings import format_value, setting
from hrgtc.settings.fleet import SETPOINTS_C

#: The simulated gyros (:mod:`hrgtc.simulate.units`) and the default one.
UNIT_NAMES = ("paper-unit", "unit-b", "imu-3", "mems-3")
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


_PROFILE = "Profile"
_RUN = "Run"


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
        None, "Simulated gyro.", choices=UNIT_NAMES,
        default_text=f"{DEFAULT_UNIT}, or the --logger preset's", panel=_RUN)
    sample_rate_hz: float | None = setting(
        None, "Sample rate.", unit="Hz", cli="--sample-rate-hz --rate-hz",
        default_text=f"{DEFAULT_SAMPLE_RATE_HZ:g}, or the --logger preset's", panel=_RUN)
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
