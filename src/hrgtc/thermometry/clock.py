"""Clock times and time zones of a reference log (``--temp-ref-start``, ``--temp-ref-tz``)."""

from __future__ import annotations

import datetime as dt
import re

from hrgtc.core.errors import InputError

__all__ = ["parse_clock", "parse_tz"]

_CLOCK = re.compile(r"^\s*(\d{1,2}):(\d{2})(?::(\d{2}(?:\.\d*)?))?\s*$")


def parse_clock(text: str, tz: dt.tzinfo | None = None) -> dt.datetime | dt.time:
    """A clock time ``HH:MM[:SS]`` (a :class:`datetime.time`) or an ISO date-time.

    ``tz`` is given to a date-time without a UTC offset.
    """
    value = str(text).strip()
    match = _CLOCK.match(value)
    if match:
        hours, minutes, seconds = match.groups()
        second = float(seconds or 0.0)
        whole = int(second)
        return dt.time(int(hours), int(minutes), whole, round((second - whole) * 1e6))
    try:
        stamp = dt.datetime.fromisoformat(value)
    except ValueError:
        raise InputError(f"{value!r} is neither a clock time HH:MM[:SS] nor an ISO date-time "
                         "(e.g. 2020-03-07T15:40:00)") from None
    return stamp.replace(tzinfo=tz) if stamp.tzinfo is None and tz is not None else stamp


def parse_tz(text: str | None) -> dt.tzinfo | None:
    """A UTC offset (``+01:00``, ``UTC``) or an IANA zone name (``Europe/Berlin``)."""
    if text is None or not str(text).strip():
        return None
    value = str(text).strip()
    if value.upper() in ("UTC", "Z"):
        return dt.UTC
    match = re.fullmatch(r"([+-])(\d{2}):?(\d{2})", value)
    if match:
        sign = 1 if match.group(1) == "+" else -1
        return dt.timezone(sign * dt.timedelta(hours=int(match.group(2)),
                                               minutes=int(match.group(3))))
    from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

    try:
        return ZoneInfo(value)
    except (ZoneInfoNotFoundError, ValueError):
        raise InputError(f"time zone {value!r} is neither a UTC offset like +01:00 nor a zone "
                         "name like Europe/Berlin") from None
