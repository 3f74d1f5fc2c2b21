"""Checks that the causal df/dt filter can follow a recording (issue 20 item 2).

One way a valid recording defeats the filter of :mod:`hrgtc.drift.rate_filter`:
**quantisation**. A temperature (or a raw count) that moves in steps of one LSB q is a
staircase; each step is a step input of size q to D(s) = s/(tau s + 1)^2, whose rate
response peaks at q/(e tau) (at t = tau). When the recording's own df/dt, estimated as
its span over its duration, is below that, the df/dt the model sees is mostly the
quantisation's. :func:`resolution` estimates q as the smallest step between distinct
values that recurs (not one rounding accident).

A duty-cycled logger's bursts are not such a case. Across a gap the filter's step takes
the input as a straight line from the last sample to the next (a first-order hold), so
after a gap much longer than tau it reads the chord's slope, the gap's mean rate: a
short tau follows the trend of bursts better than a tau as long as their period, whose
own lag (2 tau) is then minutes (docs/real-loggers/dfdt.md, "Bursts").

:func:`rate_filter_problems` returns the messages; :func:`warn_rate_filter` issues each
as a :class:`~hrgtc.core.errors.RateFilterWarning`, once per message.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

from hrgtc.core.errors import RateFilterWarning

#: Fewer distinct values than this and no resolution is estimated.
MIN_DISTINCT = 3
#: The staircase's peak rate response to one LSB step: q / (e tau).
STEP_PEAK = 1.0 / math.e
#: Rows of a run looked at (its start): enough bursts and LSB steps, and cheap.
CHECK_ROWS = 100_000
#: Rows whose distinct values tell a continuous channel at once (most of them distinct).
QUICK_ROWS = 4096


def resolution(values: np.ndarray) -> float | None:
    """The channel's quantisation step (LSB), or None when it looks continuous. [unit]

    The smallest positive difference between sorted distinct values that occurs at least
    twice (a continuous, noisy channel has as many distinct values as samples and steps
    that never repeat to the bit).
    """
    values = np.asarray(values, dtype=np.float64)
    values = values[np.isfinite(values)]
    head = values[:QUICK_ROWS]
    if head.size >= 100 and np.unique(head).size > 0.5 * head.size:
        return None  # continuous and noisy: no need to sort the whole run
    distinct = np.unique(values)
    if distinct.size < MIN_DISTINCT or distinct.size > 0.5 * values.size:
        return None
    steps = np.diff(distinct)
    smallest = float(np.min(steps))
    # steps equal to the smallest within rounding of the values' magnitude
    slack = 1e-9 * max(float(np.max(np.abs(distinct))), smallest)
    if np.count_nonzero(np.abs(steps - smallest) <= slack) < 2:
        return None
    return smallest


def rate_filter_problems(time_s: np.ndarray, levels: Mapping[str, np.ndarray], tau_s: float,
                         units: Mapping[str, str] | None = None, where: str = "",
                         thermometer_source: str = "resonator") -> list[str]:
    """Why the df/dt filter of time constant ``tau_s`` cannot follow this recording.

    Parameters
    ----------
    time_s
        Sample times of (a representative part of) one run. [s]
    levels
        The filtered channels by name (e.g. ``{"freq_hz": ..., "housing_c": ...}``).
    tau_s
        Time constant of each stage of the rate filter. [s]
    units
        Unit of each channel for the messages.
    where
        Prefix of the messages (the file's name).
    thermometer_source
        ``"sensor"``: ``freq_hz`` holds the temperature sensor's column, named
        ``temperature_c`` in °C in the messages.
    """
    units = column_units() if units is None else units
    if thermometer_source == "sensor":
        units = {**units, "temperature_c": "°C"}
        levels = {("temperature_c" if name == "freq_hz" else name): values
                  for name, values in levels.items()}
    prefix = f"{where}: " if where else ""
    time_s = np.asarray(time_s, dtype=np.float64)[:CHECK_ROWS]
    levels = {name: np.asarray(values)[:CHECK_ROWS] for name, values in levels.items()}
    out = []
    duration = float(time_s[-1] - time_s[0]) if time_s.size > 1 else 0.0
    for name, values in levels.items():
        q = resolution(values)
        if q is None or duration <= 0:
            continue
        finite = np.asarray(values, dtype=np.float64)
        finite = finite[np.isfinite(finite)]
        signal = float(np.ptp(finite)) / duration
        noise = STEP_PEAK * q / tau_s
        if noise > signal:
            unit = units.get(name, "")
            needed = STEP_PEAK * q / signal if signal > 0 else math.inf
            advice = (f"pass --rate-tau-s {_round_up(needed)} or more, or log the channel "
                      "with a finer resolution" if math.isfinite(needed) else
                      "the channel does not move at all: df/dt terms cannot be fitted")
            out.append(
                f"{prefix}{name} moves in steps of {q:.3g} {unit} (its resolution); through "
                f"the df/dt filter (tau {tau_s:g} s) each step reads as a rate of up to "
                f"{noise:.3g} {unit}/s (q/(e tau)), more than the recording's own rate of "
                f"{signal:.3g} {unit}/s over its {duration:g} s, so df/dt is mostly "
                f"quantisation noise; {advice}")
    return out


#: Recording column each rate variable filters, and its unit.
_LEVEL_OF = {"df": ("freq_hz", "Hz"), "dpos": ("freq_hz", "Hz"), "d2": ("freq_hz", "Hz"),
             "dh": ("housing_c", "°C")}


def filtered_levels(chunk: Any, variables: Iterable[str]) -> dict[str, np.ndarray]:
    """The recording columns the rate variables among ``variables`` filter (by column)."""
    out = {}
    for v in variables:
        if v in _LEVEL_OF and _LEVEL_OF[v][0] in chunk:
            out[_LEVEL_OF[v][0]] = chunk[_LEVEL_OF[v][0]]
    return out


def column_units() -> dict[str, str]:
    """Unit of each filtered column, for the messages."""
    return dict(_LEVEL_OF.values())


def warn_rate_filter(messages: Iterable[str]) -> None:
    """Issue each message once as a :class:`~hrgtc.core.errors.RateFilterWarning`."""
    for message in dict.fromkeys(messages):
        warnings.warn(message, RateFilterWarning, stacklevel=3)


def _round_up(value: float) -> str:
    """A round number of seconds at least ``value`` (two significant figures)."""
    if value <= 0 or not math.isfinite(value):
        return f"{value:g}"
    magnitude = 10 ** math.floor(math.log10(value) - 1)
    return f"{math.ceil(value / magnitude) * magnitude:g}"
