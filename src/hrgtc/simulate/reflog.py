"""Raw temperature counts and the hand-written reference log of a test bench.

Many gyros log their temperature as a raw sensor count: ``T = count * lsb_c + offset_c``,
often a signed 16-bit count stored unsigned (the PAN cold test writes -300 as 65236).
The truth is then in a separate, sparse log an operator writes by hand every few
minutes from a reference probe: wall-clock times (``HH:MM`` from a stated start, or with
a date), °C or °F columns, blank cells, trailing empty columns, a UTF-8 byte-order
mark and CRLF line ends, as ``tests/data/pan-cold-test/pan_etu_cold_handlog_2020-03-07.csv``.

:class:`TemperatureChannel` turns a true temperature into what the logger writes;
:class:`ReferenceLog` writes the hand log (:func:`reference_log_text`), its reference
probe optionally lagging behind the sensor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import datetime, timedelta
from typing import Annotated, Any, Literal

import numpy as np
from msgspec import Meta
from scipy.signal import lfilter, lfilter_zi

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.settings.simulation import PLAIN_LOGGER as _PLAIN

__all__ = [
    "ReferenceLog",
    "ReferenceLogRecord",
    "TemperatureChannel",
    "TemperatureChannelRecord",
    "count_to_celsius",
    "first_order_lag",
    "reference_log_info",
    "reference_log_text",
]


@dataclass(frozen=True)
class TemperatureChannel(records.Written):
    """A logged temperature: in °C, or a raw count; at every row or slower.

    Parameters
    ----------
    lsb_c
        Size of one count (``T = count * lsb_c + offset_c``); None: °C written with
        ``decimals`` decimals. [°C]
    offset_c
        Temperature of count 0. [°C]
    bits
        A signed count stored unsigned in this many bits (16: -300 is written 65236);
        None: the signed count as it is.
    decimals
        Decimals of a temperature written in °C.
    rate_hz
        A slower channel: a new value at this rate, empty cells between; None: every row. [Hz]
    noise_c
        White noise of the sensor, rms per sample. [°C]
    source
        ``die``: the sensor temperature (the simulator's ``resonator_c``); ``housing``:
        the housing thermistor.
    """

    forbid_unknown_fields = True  # a misspelt key of a hand-written input is refused

    lsb_c: float | None = _PLAIN["temp_lsb"]
    offset_c: float = _PLAIN["temp_offset"]
    bits: Annotated[int, Meta(ge=2, le=64)] | None = _PLAIN["temp_bits"]
    decimals: int = 2
    rate_hz: records.Positive | None = _PLAIN["temp_rate_hz"]
    noise_c: float = 0.0
    source: Literal["die", "housing"] = "die"

    def __post_init__(self) -> None:
        if self.lsb_c is not None and not (math.isfinite(self.lsb_c) and self.lsb_c != 0.0):
            raise InputError(f"lsb_c must be finite and non-zero [°C], got {self.lsb_c!r}")
        if self.bits is not None and (self.lsb_c is None or not 2 <= int(self.bits) <= 64):
            raise InputError(
                f"bits={self.bits!r} needs a raw count (lsb_c) and 2 <= bits <= 64"
            )
        if self.rate_hz is not None and not (math.isfinite(self.rate_hz) and self.rate_hz > 0):
            raise InputError(f"rate_hz must be finite and > 0 [Hz], got {self.rate_hz!r}")
        if self.source not in ("die", "housing"):
            raise InputError(f"source must be 'die' or 'housing', got {self.source!r}")

    def written(self, temperature_c: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """What the logger writes for true temperatures (every row; see :meth:`held`)."""
        value = np.asarray(temperature_c, dtype=np.float64)
        if self.noise_c > 0.0:
            value = value + rng.normal(0.0, self.noise_c, size=value.shape)
        if self.lsb_c is None:
            return np.round(value, int(self.decimals))
        count = np.round((value - self.offset_c) / self.lsb_c)
        if self.bits is not None:
            half = 2.0 ** (int(self.bits) - 1)
            if count.size and (count.min() < -half or count.max() >= half):
                raise InputError(
                    f"the temperature count {count.min():.0f}..{count.max():.0f} does not fit "
                    f"in a signed {self.bits}-bit count; change lsb_c or offset_c"
                )
            count = np.mod(count, 2.0 * half)
        return count

    def map(self) -> dict[str, Any]:
        """The true count -> °C map (plain JSON types), or None-valued for °C."""
        return {
            "temperature_c": "count * lsb_c + offset_c" if self.lsb_c is not None else "as written",
            "lsb_c": self.lsb_c,
            "offset_c": self.offset_c if self.lsb_c is not None else 0.0,
            "signed_count_stored_unsigned_bits": self.bits,
        }


#: The record of :class:`TemperatureChannel` (nested in other records).
TemperatureChannelRecord = records.record_of(TemperatureChannel)


def count_to_celsius(written: np.ndarray, lsb_c: float, offset_c: float = 0.0,
                     bits: int | None = None) -> np.ndarray:
    """Invert a raw count as written (unsigned storage of a signed count unwrapped). [°C]

    Examples
    --------
    >>> count_to_celsius(np.array([65236.0]), 0.00625, 23.375, bits=16).round(4).tolist()
    [21.5]
    """
    count = np.asarray(written, dtype=np.float64)
    if bits is not None:
        half = 2.0 ** (int(bits) - 1)
        count = np.where(count >= half, count - 2.0 * half, count)
    return count * lsb_c + offset_c


def first_order_lag(time_s: np.ndarray, value: np.ndarray, tau_s: float) -> np.ndarray:
    """A first-order lag of time constant ``tau_s`` (exact for a linear input between samples).

    Starts in equilibrium with the first value; ``tau_s`` 0 returns the input.
    """
    v = np.asarray(value, dtype=np.float64)
    if tau_s <= 0.0 or v.size < 2:
        return v.copy()
    t = np.asarray(time_s, dtype=np.float64)
    dt = np.diff(t)
    h = float(np.median(dt))
    if not (h > 0.0 and np.allclose(dt, h, rtol=1e-6, atol=0.0)):
        raise InputError("first_order_lag needs evenly spaced, increasing times")
    a = math.exp(-h / tau_s)
    b = tau_s / h * (1.0 - a)
    # y' = (u - y) / tau with u linear over each step: y1 = a y0 + (1 - b) u1 + (b - a) u0.
    num, den = [1.0 - b, b - a], [1.0, -a]
    out, _ = lfilter(num, den, v, zi=lfilter_zi(num, den) * v[0])
    return out


@dataclass(frozen=True)
class ReferenceLog(records.Written):
    """A sparse hand-written log of reference temperatures, with a real log's quirks.

    Parameters
    ----------
    every_s
        Interval between readings, on the wall clock's round multiples. [s]
    start
        Wall-clock time (ISO 8601, naive local time) of the run's t = 0.
    dates
        Times written with their date (``2020-03-07 15:45``); else ``HH:MM`` only.
    fahrenheit
        The reference probe's column in °F (``C1 (F)``); else °C (``C1 (C)``).
    lag_s
        Time constant of the reference probe behind the sensor. [s]
    decimals
        Decimals of the reference probe's readings.
    blank_fraction
        Share of readings left blank (never the first).
    trailing_rows
        Rows after the end with a time and no readings.
    empty_columns
        Empty columns after the last one (each row ends in that many commas).
    bom, crlf
        A UTF-8 byte-order mark; CRLF line ends.
    """

    forbid_unknown_fields = True  # a misspelt key of a hand-written input is refused

    every_s: Annotated[float, Meta(ge=60.0)] = 300.0
    start: str = "2020-03-07T15:43:00"
    dates: bool = False
    fahrenheit: bool = False
    lag_s: records.NonNegative = _PLAIN["reference_lag_s"]
    decimals: int = 1
    blank_fraction: float = 0.05
    trailing_rows: int = 5
    empty_columns: int = 14
    bom: bool = True
    crlf: bool = True

    def __post_init__(self) -> None:
        if not (math.isfinite(self.every_s) and self.every_s >= 60.0):
            raise InputError(f"every_s must be >= 60 [s] (a hand log), got {self.every_s!r}")
        try:
            datetime.fromisoformat(self.start)
        except (TypeError, ValueError):
            raise InputError(
                f"start {self.start!r} is not an ISO 8601 time, e.g. 2020-03-07T15:43:00"
            ) from None
        if not (math.isfinite(self.lag_s) and self.lag_s >= 0.0):
            raise InputError(f"lag_s must be finite and >= 0 [s], got {self.lag_s!r}")

    @property
    def probe_column(self) -> str:
        """Header of the reference probe's column."""
        return "C1 (F)" if self.fahrenheit else "C1 (C)"


#: The record of :class:`ReferenceLog` (nested in other records).
ReferenceLogRecord = records.record_of(ReferenceLog)


def _fahrenheit(celsius: np.ndarray) -> np.ndarray:
    return celsius * 1.8 + 32.0


def reference_log_text(
    log: ReferenceLog,
    time_s: np.ndarray,
    sensor_c: np.ndarray,
    housing_c: np.ndarray,
    chamber_c: np.ndarray,
    rng: np.random.Generator,
) -> tuple[str, list[dict[str, Any]]]:
    """The hand log's text and its true readings.

    Columns as the PAN hand log: ``Time``, ``F2 (F)`` and ``F3 (F)`` (housing, whole °F),
    ``F4 (F)`` (chamber air, whole °F), then the reference probe on the sensor, lagging
    ``lag_s`` behind it.

    Parameters
    ----------
    log
        The log's layout and quirks.
    time_s, sensor_c, housing_c, chamber_c
        The continuous run: time since t = 0 [s], true sensor, housing and chamber
        temperatures [°C].
    rng
        Chooses the blank cells.

    Returns
    -------
    text, readings
        The file's text (BOM and line ends included) and one dict per row (wall clock,
        true time_s, probe °C as written or None).
    """
    t = np.asarray(time_s, dtype=np.float64)
    probe = first_order_lag(t, sensor_c, log.lag_s)
    start = datetime.fromisoformat(log.start)
    step = timedelta(seconds=log.every_s)
    midnight = start.replace(hour=0, minute=0, second=0, microsecond=0)
    k0 = math.ceil((start - midnight).total_seconds() / log.every_s - 1e-9)
    first = midnight + k0 * step
    end = start + timedelta(seconds=float(t[-1]))
    times = []
    clock = first
    while clock <= end:
        times.append(clock)
        clock += step
    trailing = [times[-1] + (i + 1) * step for i in range(log.trailing_rows)] if times else []
    seconds = np.array([(c - start).total_seconds() for c in times])
    values = {
        "probe": np.interp(seconds, t, probe),
        "housing": np.interp(seconds, t, housing_c),
        "chamber": np.interp(seconds, t, chamber_c),
    }
    blank = rng.random(len(times)) < log.blank_fraction
    if blank.size:
        blank[0] = False
    fmt_time = "%Y-%m-%d %H:%M" if log.dates else "%H:%M"
    tail = "," * int(log.empty_columns)
    lines = ["Time,F2 (F),F3 (F),F4 (F)," + log.probe_column + tail]
    readings = []
    for i, clock in enumerate(times):
        probe_value = values["probe"][i]
        written = _fahrenheit(probe_value) if log.fahrenheit else probe_value
        text = "" if blank[i] else f"{round(float(written), log.decimals):g}"
        housing_f = round(float(_fahrenheit(values["housing"][i])))
        chamber_f = round(float(_fahrenheit(values["chamber"][i])))
        lines.append(f"{clock.strftime(fmt_time)},{housing_f},{housing_f},{chamber_f},{text}{tail}")
        readings.append({
            "clock": clock.isoformat(timespec="minutes"),
            "time_s": float(seconds[i]),
            "probe_c": None if blank[i] else float(probe_value),
            "sensor_c": float(np.interp(seconds[i], t, sensor_c)),
        })
    for clock in trailing:
        lines.append(f"{clock.strftime(fmt_time)},,,," + tail)
    newline = "\r\n" if log.crlf else "\n"
    text = newline.join(lines) + newline
    return ("\ufeff" if log.bom else "") + text, readings


def reference_log_info(log: ReferenceLog, clock_zero: datetime,
                       readings: list[dict[str, Any]]) -> dict[str, Any]:
    """The sidecar's entry of a reference log: its columns, the wall-clock time
    ``clock_zero`` at which the recording's clock read 0, the ``hrgtc`` options that
    read it, and its true readings (from :func:`reference_log_text`)."""
    zero_text = clock_zero.isoformat(timespec="milliseconds")
    return {
        "probe_column": log.probe_column, "start": log.start, "lag_s": log.lag_s,
        "recording_clock_zero": zero_text,
        "hrgtc_options": [
            "--temp-ref-col", "time_s=Time", "--temp-ref-col",
            f"temperature_c={log.probe_column}", "--temp-ref-start",
            zero_text if log.dates else zero_text[11:].removesuffix(".000"),
        ],
        "readings": readings,
    }
