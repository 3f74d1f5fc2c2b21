"""A logger's clock as written: a counter that wraps, or wall-clock timestamps.

:func:`unwrap_counter` is the arithmetic of an unsigned counter that wraps (a 32-bit µs
counter every 2^32 µs = 71.6 min); :func:`wall_clock` writes ISO 8601 local times that
follow a time zone's daylight-saving changes (a ±1 h step in naive clock times).
"""

from __future__ import annotations

from datetime import datetime
from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

import numpy as np

from hrgtc.core.errors import InputError

__all__ = ["unwrap_counter", "wall_clock"]


def wall_clock(start: str, seconds: np.ndarray, timezone: str | None = None) -> np.ndarray:
    """ISO 8601 local times, to the ms, ``seconds`` after the local time ``start``.

    With an IANA ``timezone`` the local clock follows its daylight-saving changes (a ±1 h
    step, as a logger whose clock is set to local time writes).

    Examples
    --------
    >>> wall_clock("2021-03-28T01:59:59", np.array([0.0, 2.0]), "Europe/Berlin").tolist()
    ['2021-03-28T01:59:59.000', '2021-03-28T03:00:01.000']
    """
    try:
        base = datetime.fromisoformat(start)
    except (TypeError, ValueError):
        raise InputError(
            f"start {start!r} is not an ISO 8601 time, e.g. 2020-03-07T15:44:40") from None
    s = np.asarray(seconds, dtype=np.float64)
    if timezone is None:
        local = (base - datetime(1970, 1, 1)).total_seconds() + s
    else:
        try:
            zone = ZoneInfo(timezone)
        except (ZoneInfoNotFoundError, ValueError):
            raise InputError(f"unknown time zone {timezone!r}; give an IANA name such as "
                             "Europe/Berlin") from None
        epoch = base.replace(tzinfo=zone).timestamp() + s
        quarter = np.floor(epoch / 900.0)  # zones change their offset on quarter hours
        unique, inverse = np.unique(quarter, return_inverse=True)
        offsets = np.array([datetime.fromtimestamp(q * 900.0, zone).utcoffset().total_seconds()
                            for q in unique])
        local = epoch + offsets[inverse]
    stamps = np.round(local * 1e3).astype(np.int64).astype("datetime64[ms]")
    return np.datetime_as_string(stamps, unit="ms")


def unwrap_counter(values: np.ndarray, bits: int) -> np.ndarray:
    """Unwrap an unsigned ``bits``-bit counter that only moves forward (between wraps).

    Examples
    --------
    >>> unwrap_counter(np.array([250.0, 254.0, 2.0, 6.0]), 8).tolist()
    [250.0, 254.0, 258.0, 262.0]
    """
    v = np.asarray(values, dtype=np.float64)
    wraps = np.concatenate(([0.0], np.cumsum(np.diff(v) < 0)))
    return v + wraps * 2.0 ** int(bits)
