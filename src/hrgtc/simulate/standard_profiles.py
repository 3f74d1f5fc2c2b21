"""The standard runs of a chamber campaign, and the runs of one command line.

* soaks (Section 3 of [1], Fig. 3): each soak starts with the unit in
  equilibrium at room temperature, 20 °C, and the chamber slews to the
  set-point at its maximum rate: :func:`soak_campaign` gives one profile per
  set-point (one file per soak); :func:`soak_series` one profile visiting the
  set-points in sequence, each soak starting from the previous set-point;
* cool-down and warm-up like the run of Fig. 6 of [1] (:func:`cooldown`,
  :func:`warmup`): ramp, then hold until the end of the run;
* a ramp between two temperatures (:func:`ramp`) and a constant temperature
  (:func:`constant`);
* a rate-table run (:func:`rate_table`): temperature plateaus, each a soak with
  the table at rest and then known rates held in turn (on each axis in turn for
  a multi-axis unit), as in the scale-factor tests of IEEE Std 1431;
* :func:`build` turns the ``hrgtc simulate`` options (or a profile file, see
  :mod:`hrgtc.simulate.profiles`) into the list of runs.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.settings.simulation import (
    DEFAULT_PLATEAUS_C,
    DEFAULT_TABLE_RATES_DPS,
    PROFILE_DEFAULTS,
    PROFILE_KINDS,
    REQUIRED,
    SimulationSettings,
)
from hrgtc.simulate.profiles import (
    CHAMBER_MAX_C_PER_MIN,
    DEFAULT_RAMP_C_PER_MIN,
    ROOM_TEMPERATURE_C,
    Profile,
    Segment,
    finite_number,
    format_temperature,
    load,
)

__all__ = [
    "DEFAULT_PLATEAUS_C",
    "DEFAULT_TABLE_RATES_DPS",
    "KINDS",
    "PROFILE_OPTIONS",
    "build",
    "constant",
    "cooldown",
    "ramp",
    "rate_table",
    "soak",
    "soak_campaign",
    "soak_series",
    "warmup",
]


def _check_hours(hours: float) -> float:
    value = finite_number("hours", hours, "h")
    if value <= 0.0:
        raise InputError(f"hours must be > 0 [h], got {value!r}")
    return value


def soak(
    setpoint_c: float,
    hours: float,
    start_c: float = ROOM_TEMPERATURE_C,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> Profile:
    """A soak at one set-point from equilibrium at ``start_c``, as in Fig. 3 of [1].

    Parameters
    ----------
    setpoint_c
        Chamber set-point. [°C]
    hours
        Duration of the soak, the chamber's slew included. [h]
    start_c
        Temperature of the unit and the chamber at the start. [°C]
    chamber_max_c_per_min
        Rate at which the chamber slews to the set-point. [°C/min]

    Examples
    --------
    >>> soak(-10.0, 5.0).description
    'soak -10 C, 5 h from 20 C'
    """
    hours = _check_hours(hours)
    setpoint = finite_number("setpoint_c", setpoint_c, "°C")
    start_c = finite_number("start_c", start_c, "°C")
    return Profile(
        (Segment(setpoint, hold_h=hours),),
        start_c=start_c,
        chamber_max_c_per_min=chamber_max_c_per_min,
        name=f"soak_{format_temperature(setpoint)}C",
        description=f"soak {format_temperature(setpoint)} C, {hours:g} h from "
        f"{format_temperature(start_c)} C",
        setpoint_c=setpoint,
    )


def soak_campaign(
    setpoints_c: Sequence[float],
    hours: float,
    start_c: float = ROOM_TEMPERATURE_C,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> list[Profile]:
    """One soak profile per set-point, each from equilibrium at ``start_c`` (Section 3 of [1]).

    Parameters
    ----------
    setpoints_c
        Chamber set-points, one run each. [°C]
    hours
        Duration of each soak. [h]
    start_c
        Temperature of the unit and the chamber at the start of every soak. [°C]
    chamber_max_c_per_min
        Rate at which the chamber slews to the set-point. [°C/min]

    Examples
    --------
    >>> [p.name for p in soak_campaign([-20, -10], 5)]
    ['soak_-20C', 'soak_-10C']
    """
    points = _check_setpoints(setpoints_c)
    return [soak(s, hours, start_c, chamber_max_c_per_min) for s in points]


def soak_series(
    setpoints_c: Sequence[float],
    hours: float,
    start_c: float = ROOM_TEMPERATURE_C,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> Profile:
    """One profile visiting the set-points in sequence, ``hours`` each.

    The first soak starts from equilibrium at ``start_c``, each later one from
    the previous set-point.

    Parameters
    ----------
    setpoints_c
        Chamber set-points, in order. [°C]
    hours
        Duration of each soak, the chamber's slew included. [h]
    start_c
        Temperature of the unit and the chamber at the start. [°C]
    chamber_max_c_per_min
        Rate at which the chamber slews between set-points. [°C/min]
    """
    points = _check_setpoints(setpoints_c)
    hours = _check_hours(hours)
    start_c = finite_number("start_c", start_c, "°C")
    label = ", ".join(format_temperature(s) for s in points)
    return Profile(
        tuple(Segment(s, hold_h=hours) for s in points),
        start_c=start_c,
        chamber_max_c_per_min=chamber_max_c_per_min,
        name=f"soaks_{format_temperature(points[0])}C_to_{format_temperature(points[-1])}C",
        description=f"soaks {label} C, {hours:g} h each from {format_temperature(start_c)} C",
    )


def _check_setpoints(setpoints_c: Sequence[float]) -> list[float]:
    points = [finite_number(f"setpoints_c[{i}]", s, "°C") for i, s in enumerate(setpoints_c)]
    if not points:
        raise InputError("setpoints_c is empty; give at least one set-point, e.g. -20,-10,0")
    return points


def ramp(
    start_c: float,
    end_c: float,
    rate_c_per_min: float,
    hold_h: float = 0.0,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> Profile:
    """A ramp from equilibrium at ``start_c`` to ``end_c``, then an optional hold.

    Parameters
    ----------
    start_c, end_c
        Start and end temperatures. [°C]
    rate_c_per_min
        Ramp rate, at most ``chamber_max_c_per_min``. [°C/min]
    hold_h
        Hold at ``end_c`` after the ramp (0 for none). [h]
    chamber_max_c_per_min
        Maximum rate of the chamber. [°C/min]
    """
    end = finite_number("end_c", end_c, "°C")
    start = finite_number("start_c", start_c, "°C")
    if end == start:
        raise InputError(f"ramp start_c and end_c are both {start:g} °C; use constant() instead")
    segments = [Segment(end, ramp_c_per_min=rate_c_per_min)]
    hold = finite_number("hold_h", hold_h, "h")
    if hold < 0.0:
        raise InputError(f"hold_h must be >= 0 [h], got {hold!r}")
    if hold > 0.0:
        segments.append(Segment(end, hold_h=hold))
    rate = segments[0].ramp_c_per_min
    return Profile(
        tuple(segments),
        start_c=start,
        chamber_max_c_per_min=chamber_max_c_per_min,
        name=f"ramp_{format_temperature(start)}C_to_{format_temperature(end)}C",
        description=f"ramp {format_temperature(start)} C to {format_temperature(end)} C at "
        f"{rate:g} C/min" + (f", hold {hold:g} h" if hold > 0 else ""),
    )


def _ramp_then_hold(
    kind: str,
    start_c: float,
    end_c: float,
    hours: float,
    ramp_c_per_min: float,
    chamber_max_c_per_min: float,
) -> Profile:
    hours = _check_hours(hours)
    start = finite_number("start_c", start_c, "°C")
    end = finite_number("end_c", end_c, "°C")
    rate = finite_number("ramp_c_per_min", ramp_c_per_min, "°C/min")
    if rate <= 0.0:
        raise InputError(f"ramp_c_per_min must be > 0 [°C/min], got {rate!r}")
    ramp_h = abs(end - start) / rate / 60.0
    if ramp_h >= hours:
        raise InputError(
            f"the {kind} ramp {format_temperature(start)} -> {format_temperature(end)} C at "
            f"{rate:g} C/min takes {ramp_h:.3g} h, not less than hours={hours:g}; give more "
            "hours or a faster ramp"
        )
    segments = [Segment(end, hold_h=hours - ramp_h)]
    if end != start:
        segments.insert(0, Segment(end, ramp_c_per_min=rate))
    return Profile(
        tuple(segments),
        start_c=start,
        chamber_max_c_per_min=chamber_max_c_per_min,
        name=f"{kind}_{format_temperature(start)}C_to_{format_temperature(end)}C",
        description=f"{kind} {format_temperature(start)} C to {format_temperature(end)} C at "
        f"{rate:g} C/min, {hours:g} h",
    )


def cooldown(
    start_c: float = ROOM_TEMPERATURE_C,
    end_c: float = -20.0,
    hours: float = 5.0,
    ramp_c_per_min: float = DEFAULT_RAMP_C_PER_MIN,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> Profile:
    """A cool-down like the run of Fig. 6 of [1]: ramp from ``start_c`` to ``end_c``, then hold.

    The unit starts in equilibrium at ``start_c``; the whole run lasts ``hours``.

    Examples
    --------
    >>> p = cooldown(20, -20, 5)
    >>> p.chamber_c([0.0, 1200.0, 2400.0, 18000.0]).tolist()
    [20.0, 0.0, -20.0, -20.0]
    """
    if finite_number("end_c", end_c, "°C") >= finite_number("start_c", start_c, "°C"):
        raise InputError(
            f"a cool-down needs end_c < start_c, got {start_c!r} -> {end_c!r}; use warmup()"
        )
    return _ramp_then_hold("cooldown", start_c, end_c, hours, ramp_c_per_min, chamber_max_c_per_min)


def warmup(
    start_c: float = -20.0,
    end_c: float = ROOM_TEMPERATURE_C,
    hours: float = 5.0,
    ramp_c_per_min: float = DEFAULT_RAMP_C_PER_MIN,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> Profile:
    """A warm-up, the mirror of :func:`cooldown`: the unit starts soaked at ``start_c``."""
    if finite_number("end_c", end_c, "°C") <= finite_number("start_c", start_c, "°C"):
        raise InputError(
            f"a warm-up needs end_c > start_c, got {start_c!r} -> {end_c!r}; use cooldown()"
        )
    return _ramp_then_hold("warmup", start_c, end_c, hours, ramp_c_per_min, chamber_max_c_per_min)


def constant(temperature_c: float, hours: float) -> Profile:
    """Constant temperature: unit and chamber in equilibrium at ``temperature_c`` throughout."""
    hours = _check_hours(hours)
    temp = finite_number("temperature_c", temperature_c, "°C")
    return Profile(
        (Segment(temp, hold_h=hours),),
        start_c=temp,
        name=f"constant_{format_temperature(temp)}C",
        description=f"constant {format_temperature(temp)} C, {hours:g} h",
        setpoint_c=temp,
    )




def rate_table(
    plateaus_c: Sequence[float] = DEFAULT_PLATEAUS_C,
    rates_dps: Sequence[float] = DEFAULT_TABLE_RATES_DPS,
    hold_s: float = 60.0,
    soak_h: float = 3.0,
    axes: Sequence[str] | None = None,
    start_c: float = ROOM_TEMPERATURE_C,
    chamber_max_c_per_min: float = CHAMBER_MAX_C_PER_MIN,
) -> Profile:
    """A rate-table run: at each plateau a soak, then each rate held ``hold_s`` in turn.

    At every plateau the chamber slews to the temperature and holds it for
    ``soak_h`` hours with the table at rest, then the table turns at each of
    ``rates_dps`` for ``hold_s`` seconds (the chamber still holding), axis after
    axis for a multi-axis unit (the other axes see no table rate). The unit
    starts in equilibrium at ``start_c``. The run lasts
    ``len(plateaus) * (soak_h * 3600 + len(axes) * len(rates) * hold_s)`` seconds.

    Parameters
    ----------
    plateaus_c
        Chamber temperatures, in order. [°C]
    rates_dps
        Table rates held at every plateau, in order. [°/s]
    hold_s
        Time each rate is held. [s]
    soak_h
        Soak at each plateau before the rates, the chamber's slew included. [h]
    axes
        Axes of a multi-axis unit, turned one at a time; None for a single-axis unit.
    start_c
        Temperature of the unit and the chamber at the start. [°C]
    chamber_max_c_per_min
        Rate at which the chamber slews between plateaus. [°C/min]

    Examples
    --------
    >>> p = rate_table([20.0], [0.0, 100.0], hold_s=90.0, soak_h=1.0)
    >>> p.segment_ends_s().tolist(), p.table_rate_dps([3599.0, 3650.0, 3700.0]).tolist()
    ([3600.0, 3690.0, 3780.0], [0.0, 0.0, 100.0])
    """
    points = _check_setpoints(plateaus_c)
    rates = [finite_number(f"rates_dps[{i}]", r, "°/s") for i, r in enumerate(rates_dps)]
    if not rates:
        raise InputError("rates_dps is empty; give at least one table rate, e.g. 0,10,-10")
    hold = finite_number("hold_s", hold_s, "s")
    if hold <= 0.0:
        raise InputError(f"hold_s must be > 0 [s], got {hold!r}")
    soak_hours = _check_hours(soak_h)
    start = finite_number("start_c", start_c, "°C")
    turned: tuple[str | None, ...] = (None,) if axes is None else tuple(axes)
    if not turned:
        raise InputError("axes is empty; give the unit's axes, or None for a single-axis unit")
    segments = []
    for plateau in points:
        segments.append(Segment(plateau, hold_h=soak_hours))
        segments += [
            Segment(plateau, hold_h=hold / 3600.0, table_rate_dps=rate, axis=axis)
            for axis in turned
            for rate in rates
        ]
    label = ", ".join(format_temperature(p) for p in points)
    on_axes = "" if axes is None else f" on axes {', '.join(axes)} in turn"
    return Profile(
        tuple(segments),
        start_c=start,
        chamber_max_c_per_min=chamber_max_c_per_min,
        name=f"ratetable_{format_temperature(points[0])}C"
        + (f"_to_{format_temperature(points[-1])}C" if len(points) > 1 else ""),
        description=f"rate table at {label} C ({soak_hours:g} h soak each), rates "
        f"{', '.join(f'{r:g}' for r in rates)} °/s {hold:g} s each{on_axes}, from "
        f"{format_temperature(start)} C",
    )


#: Profile kinds known to :func:`build` (besides a path to a profile file).
KINDS = PROFILE_KINDS


#: The profile's parameters that :func:`build` takes by keyword: the profile fields of
#: :class:`~hrgtc.settings.simulation.SimulationSettings` (all but ``profile``, the kind).
PROFILE_OPTIONS = ("setpoints_c", "hours", "start_c", "end_c", "temperature_c",
                   "ramp_c_per_min", "single_file", "rates_dps", "rate_hold_s")


def build(kind: str, settings: SimulationSettings | None = None, *,
          axes: Sequence[str] | None = None, **options: Any) -> list[Profile]:
    """The runs of one command line: a kind of profile (or a profile file) and its options.

    Parameters
    ----------
    kind
        ``"soak"``, ``"cooldown"``, ``"warmup"``, ``"constant"``, ``"ramp"``,
        ``"ratetable"``, or the path of a JSON/YAML profile file.
    settings
        The profile's parameters: the fields of :data:`PROFILE_OPTIONS` (its other
        fields, the run's, are not read); None: every field None (its kind's default).
    axes
        Rate table: the axes of a multi-axis unit, turned one at a time (ignored
        by the other kinds); None for a single-axis unit.
    **options
        Any field of :data:`PROFILE_OPTIONS` by keyword, over ``settings``'s:

        ``setpoints_c``
            Soak set-points, or the plateaus of a rate table. [°C]
        ``hours``
            Hours per soak (also at each rate-table plateau), or duration of a
            cool-down/warm-up/constant run; hold after a ramp. [h]
        ``start_c``, ``end_c``
            Start and end temperatures of a cool-down, warm-up or ramp (the start of a
            rate table too). [°C]
        ``temperature_c``
            Temperature of a constant run. [°C]
        ``ramp_c_per_min``
            Ramp rate of a cool-down, warm-up or ramp. [°C/min]
        ``single_file``
            Soaks: one run visiting all set-points instead of one run per set-point.
        ``rates_dps``
            Rate table: the rates. [°/s]
        ``rate_hold_s``
            Rate table: time each rate is held. [s]

    A parameter None takes its kind's default, written once in
    :data:`hrgtc.settings.simulation.PROFILE_DEFAULTS` (the help of ``hrgtc simulate``
    shows the same table); a parameter that does not apply to the kind is an error.

    Returns
    -------
    list of Profile
        One profile per output file.

    Raises
    ------
    TypeError
        For a keyword that is not one of :data:`PROFILE_OPTIONS`.
    """
    unknown = sorted(set(options) - set(PROFILE_OPTIONS))
    if unknown:
        raise TypeError(f"build() got unexpected keyword argument(s) {unknown}; "
                        f"the profile's options are {list(PROFILE_OPTIONS)}")
    chosen = dataclasses.replace(settings or SimulationSettings(), **options)
    given = {name: getattr(chosen, name) for name in PROFILE_OPTIONS
             if name not in ("hours", "single_file")}
    _refuse_options(kind, given, chosen.single_file)
    if kind in PROFILE_DEFAULTS:
        value = {**PROFILE_DEFAULTS[kind],
                 **{k: v for k, v in {**given, "hours": chosen.hours}.items() if v is not None}}
        missing = [name for name, v in value.items() if v == REQUIRED]
        if missing:
            options_text = ", ".join("--" + name.removesuffix("_c") for name in missing)
            raise InputError(f"a {kind} needs {' and '.join(missing)} ({options_text})")
        return _runs(kind, value, chosen.single_file, axes)
    if chosen.hours is not None:
        raise InputError(f"option hours does not apply to the profile file {kind}")
    return [load(kind)]


def _refuse_options(kind: str, given: dict[str, Any], single_file: bool) -> None:
    """Refuse an unknown kind, a missing profile file, or options ``kind`` does not take."""
    allowed = {kind: set(defaults) - {"hours"} for kind, defaults in PROFILE_DEFAULTS.items()}
    if kind not in KINDS:
        path = Path(kind)
        if path.suffix.lower() not in (".json", ".yaml", ".yml"):
            raise InputError(
                f"unknown profile {kind!r}; choose one of {', '.join(KINDS)} or give a "
                ".json/.yaml profile file"
            )
        if not path.is_file():
            raise InputError(f"profile file {kind} not found")
        allowed[kind] = set()
    extra = sorted(k for k, v in given.items() if v is not None and k not in allowed[kind])
    if extra or (single_file and kind != "soak"):
        names = extra + (["single_file"] if single_file and kind != "soak" else [])
        raise InputError(f"option(s) {names} do not apply to profile {kind!r}")


def _runs(kind: str, value: dict[str, Any], single_file: bool,
          axes: Sequence[str] | None) -> list[Profile]:
    """The profiles of a standard ``kind`` from its parameters, defaults filled in."""
    if kind == "soak":
        points, hold = list(value["setpoints_c"]), value["hours"]
        return [soak_series(points, hold)] if single_file else soak_campaign(points, hold)
    if kind in ("cooldown", "warmup"):
        function = cooldown if kind == "cooldown" else warmup
        return [function(value["start_c"], value["end_c"], value["hours"],
                         value["ramp_c_per_min"])]
    if kind == "constant":
        return [constant(value["temperature_c"], value["hours"])]
    if kind == "ramp":
        return [ramp(value["start_c"], value["end_c"], value["ramp_c_per_min"],
                     value["hours"])]
    return [rate_table(list(value["setpoints_c"]), list(value["rates_dps"]),
                       value["rate_hold_s"], value["hours"], axes=axes,
                       start_c=value["start_c"])]
