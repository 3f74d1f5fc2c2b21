"""Units as datasheets write them, onto the recording contract's s, Hz, °/h and °C.

One table, :data:`UNITS`, holds every unit a column of a user's file may be in:
its kind (``time``, ``freq``, ``rate``, ``temp``), its canonical name, the
spellings accepted (case-insensitive, spaces ignored) and the exact conversion to
the contract's unit, ``contract = (value + before) * multiply / divide``; the
help texts of ``--time-unit``, ``--freq-unit``, ``--rate-unit`` and
``--temp-unit`` are written from it.

Two kinds of unit need more than a factor:

* an **angle increment per sample** (``drad``, ``ddeg``: Δθ in rad or ° per
  sample, as integrating IMUs log): the rate of a sample is Δθ / Δt, with Δt the
  time step from the previous sample (the first sample of the file, a step over a
  gap of more than 2 median periods and a non-increasing step use the median
  period: the increment covers one output period, not the logger's pause);
* a **raw count** (``lsb`` for rates, with ``--rate-scale`` LSB per °/s as
  datasheets give it; ``count`` for temperatures, with ``--temp-scale`` and
  ``--temp-offset`` or a reference log, see :mod:`hrgtc.thermometry.reference`).

Temperatures in °F or K convert every temperature column (``temperature_c*``,
``chamber_c``, ``housing_c``, ``resonator_c``); a raw count is the gyro's own
sensor, ``temperature_c*`` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hrgtc.core.errors import InputError

__all__ = ["UNITS", "Unit", "convert", "find_unit", "unit_help"]


@dataclass(frozen=True)
class Unit:
    """A unit of a file's column and its exact conversion to the contract's unit.

    ``contract = (value + before) * multiply / divide``; for a per-sample
    increment the result is further divided by the sample's Δt [s]; a ``scaled``
    unit (a raw count) takes its scale from an option.
    """

    kind: str
    name: str
    symbol: str
    spellings: tuple[str, ...]
    multiply: float = 1.0
    divide: float = 1.0
    before: float = 0.0
    factor_text: str = "×1"
    per_sample: bool = False
    scaled: bool = False

    def apply(self, values: np.ndarray) -> np.ndarray:
        """``(values + before) * multiply / divide`` (the same array when that is 1)."""
        if self.before == 0.0 and self.multiply == 1.0 and self.divide == 1.0:
            return values
        out = values + self.before if self.before != 0.0 else values
        if self.multiply != 1.0:
            out = out * self.multiply
        return out / self.divide if self.divide != 1.0 else out


_RAD_TO_DPH = 648000.0 / math.pi  # 1 rad/s = (180/π) °/s = (180/π)·3600 °/h
#: Contract unit of each kind.
CONTRACT_UNIT = {"time": "s", "freq": "Hz", "rate": "°/h", "temp": "°C"}

#: Every unit a file's column may be in (canonical names are unique within a kind).
UNITS: tuple[Unit, ...] = (
    Unit("time", "s", "s", ("s", "sec", "second", "seconds")),
    Unit("time", "ms", "ms", ("ms", "msec", "millisecond", "milliseconds"), divide=1e3,
         factor_text="/1000"),
    Unit("time", "us", "µs", ("us", "µs", "μs", "usec", "microsecond", "microseconds"),
         divide=1e6, factor_text="/10^6"),
    Unit("time", "ns", "ns", ("ns", "nsec", "nanosecond", "nanoseconds"), divide=1e9,
         factor_text="/10^9"),
    Unit("time", "timestamp", "ISO 8601", ("timestamp", "datetime", "iso", "iso8601"),
         factor_text="seconds since the first sample"),
    Unit("freq", "Hz", "Hz", ("hz",)),
    Unit("freq", "kHz", "kHz", ("khz",), multiply=1e3, factor_text="×1000"),
    Unit("rate", "dph", "°/h", ("dph", "°/h", "deg/h", "deg/hr", "°/hr")),
    Unit("rate", "dps", "°/s", ("dps", "°/s", "deg/s", "deg/sec"), multiply=3600.0,
         factor_text="×3600"),
    Unit("rate", "mdps", "m°/s", ("mdps", "m°/s", "mdeg/s", "millideg/s"), multiply=3.6,
         factor_text="×3.6"),
    Unit("rate", "radps", "rad/s", ("radps", "rad/s", "rad/sec"), multiply=_RAD_TO_DPH,
         factor_text="×648000/π"),
    Unit("rate", "mradps", "mrad/s", ("mradps", "mrad/s", "mrad/sec"),
         multiply=_RAD_TO_DPH, divide=1e3, factor_text="×648/π"),
    Unit("rate", "drad", "Δθ rad/sample", ("drad", "rad/sample", "dtheta_rad", "Δθrad"),
         multiply=_RAD_TO_DPH, per_sample=True, factor_text="×648000/π ÷ Δt"),
    Unit("rate", "ddeg", "Δθ °/sample", ("ddeg", "deg/sample", "°/sample", "dtheta_deg",
                                         "Δθdeg"),
         multiply=3600.0, per_sample=True, factor_text="×3600 ÷ Δt"),
    Unit("rate", "lsb", "LSB", ("lsb", "count", "counts", "raw"), scaled=True,
         factor_text="×3600/K, K = --rate-scale LSB per °/s"),
    Unit("temp", "C", "°C", ("c", "°c", "degc", "celsius")),
    Unit("temp", "F", "°F", ("f", "°f", "degf", "fahrenheit"), before=-32.0, multiply=5.0,
         divide=9.0, factor_text="(F − 32)×5/9"),
    Unit("temp", "K", "K", ("k", "kelvin"), before=-273.15, factor_text="− 273.15"),
    Unit("temp", "count", "raw count", ("count", "counts", "lsb", "raw"), scaled=True,
         factor_text="× --temp-scale + --temp-offset, or a --temp-ref log"),
)

_BY_KIND: dict[str, dict[str, Unit]] = {}
for _unit in UNITS:
    _BY_KIND.setdefault(_unit.kind, {})[_unit.name] = _unit


def find_unit(kind: str, text: str) -> Unit:
    """The :class:`Unit` of a spelling (``"mrad/s"``, ``"°F"``, ``"ms"``, ...).

    Raises
    ------
    InputError
        Unknown kind or spelling; the message lists the accepted units.
    """
    if kind not in _BY_KIND:
        raise InputError(f"unknown unit kind {kind!r}; use one of {list(_BY_KIND)}")
    wanted = str(text).strip().lower().replace(" ", "")
    for unit in _BY_KIND[kind].values():
        # spellings and symbols compared as typed ones are: lower case, no spaces ("Δθdeg",
        # "Δθ °/sample" lower to "δθ...", which a capital Δ in the table never matched)
        spellings = {s.lower().replace(" ", "") for s in (*unit.spellings, unit.symbol)}
        if wanted == unit.name.lower() or wanted in spellings:
            return unit
    known = ", ".join(u.name if u.name == u.symbol else f"{u.name} ({u.symbol})"
                      for u in _BY_KIND[kind].values())
    raise InputError(f"unknown {kind} unit {text!r}; use one of {known}")


def unit_of(kind: str, name: str) -> Unit:
    """The :class:`Unit` of a canonical name (``"radps"``); ``KeyError`` if unknown."""
    return _BY_KIND[kind][name]


def convert(values: np.ndarray, kind: str, name: str) -> np.ndarray:
    """Values in unit ``name`` of ``kind`` in the contract's unit (not per-sample or scaled)."""
    unit = unit_of(kind, name)
    if unit.per_sample or unit.scaled:
        raise InputError(f"{unit.symbol} needs the time steps or a scale; read it through a "
                         "recording with its options")
    return unit.apply(np.asarray(values, dtype=np.float64))


def unit_help(kind: str) -> str:
    """``name (symbol, factor), ...`` for the help of a unit option."""
    target = CONTRACT_UNIT[kind]
    parts = [f"{u.name} ({u.symbol}, {u.factor_text})" for u in _BY_KIND[kind].values()]
    return f"to {target}: " + "; ".join(parts)


def per_sample_steps(time_s: np.ndarray, previous_s: float | None,
                     period_s: float) -> np.ndarray:
    """Δt of each sample for an angle increment per sample. [s]

    The step from the previous sample (``previous_s``: the last time of the
    previous chunk, None at the start of the file); the first sample of the file,
    a non-increasing step and a step over a gap (more than 2 ``period_s``) take
    ``period_s``, the median period.
    """
    before = np.empty_like(time_s)
    if len(time_s):
        before[0] = np.nan if previous_s is None else previous_s
        before[1:] = time_s[:-1]
    with np.errstate(invalid="ignore"):
        steps = time_s - before
        odd = ~((steps > 0) & (steps <= 2.0 * period_s))
    steps[odd] = period_s
    return steps


def median_period(time_s: np.ndarray) -> float | None:
    """Median of the positive finite time steps [s], None without one."""
    steps = np.diff(time_s)
    steps = steps[np.isfinite(steps) & (steps > 0)]
    return float(np.median(steps)) if steps.size else None
