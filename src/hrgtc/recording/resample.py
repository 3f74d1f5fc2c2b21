"""Channels logged at a slower rate than the file's rows (issue 20 item 5).

A logger that writes a 10 Hz row for the gyro but reads its temperature once a second
leaves the temperature cell empty (NaN) in nine rows out of ten. Such a **slow channel**
is recognised on the first rows read: at least half of its cells are empty and it has
values at a regular pace (its period, the median time between its values). It is then
filled, as ``--slow-channels`` says:

``hold`` (default)
    each empty cell takes the channel's last value (causal: what a firmware sees);
``interpolate``
    linear in time between the values on either side (the last one is held);
``error``
    the empty cells stay and the validation refuses them, as before.

A value is used for at most ``--hold-max-s`` seconds (default
:data:`DEFAULT_MAX_AGE_PERIODS` periods of the channel): a row farther than that from
a value of the channel, or before its first value, is a gap in the channel and is
dropped (counted), so the time axis shows the gap and ``--gaps`` decides what it means.
A channel whose cells are only occasionally empty is not slow: its empty cells are
refused by the validation as before (a dropout, not a logging rate).

:class:`SlowChannels` works chunk by chunk (state carried: the last value and its time;
``interpolate`` holds back the rows after a chunk's last value until the next one) and
reports what it did (:meth:`SlowChannels.summary`, a
:class:`~hrgtc.core.errors.SlowChannelWarning`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError, SlowChannelWarning
from hrgtc.core.records import Count, Positive, Record
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.settings.reading import DEFAULT_MAX_AGE_PERIODS

#: What to do with a slow channel's empty cells.
SLOW_MODES = ("hold", "interpolate", "error")
#: A channel with at least this share of empty cells (in the first rows) is slow.
SLOW_FRACTION = 0.5
#: Columns never treated as slow (the time axis and the gyro's own outputs).
_NEVER = ("time_s", "rate_dph", "input_rate_dph")


def check_slow_mode(mode: str) -> str:
    """``mode`` if it is one of :data:`SLOW_MODES`, else InputError."""
    if mode not in SLOW_MODES:
        raise InputError(f"--slow-channels must be one of {', '.join(SLOW_MODES)}, got {mode!r}")
    return mode


def _eligible(name: str) -> bool:
    return not any(name == base or name.startswith(base + "_") for base in _NEVER)


@dataclass
class ChannelFill(records.Written):
    """What was done to one slow channel (the figures are written, not the state)."""

    not_written = ("last_time", "last_value", "alias_of")

    column: str
    period_s: Positive
    max_age_s: Positive
    filled: Count = 0
    dropped: Count = 0
    first_dropped_row: Count | None = None
    last_time: float = -math.inf
    last_value: float = math.nan
    alias_of: str | None = None  # the same cells under another name (a sensor's freq_hz)


#: The record of :class:`ChannelFill` (nested in :class:`SlowChannelsRecord`).
ChannelFillRecord = records.record_of(ChannelFill)


@dataclass
class SlowChannels:
    """Fill the empty cells of slow channels, chunk by chunk.

    Parameters
    ----------
    mode
        ``"hold"``, ``"interpolate"`` or ``"error"`` (see the module docstring).
    max_age_s
        Longest time a value is used for; None: :data:`DEFAULT_MAX_AGE_PERIODS` periods
        of each channel. [s]
    source
        The file's name, for the report.
    """

    mode: str = "hold"
    max_age_s: float | None = None
    source: str = ""
    channels: dict[str, ChannelFill] = field(default_factory=dict)
    _decided: bool = False
    _pending: dict[str, np.ndarray] | None = None
    _pending_offset: int = 0

    def __post_init__(self) -> None:
        check_slow_mode(self.mode)
        if self.max_age_s is not None and not (self.max_age_s > 0 and
                                               math.isfinite(self.max_age_s)):
            raise InputError(f"--hold-max-s must be a positive number of seconds, got "
                             f"{self.max_age_s!r}")

    # -- detection ------------------------------------------------------------------
    def _decide(self, arrays: dict[str, np.ndarray]) -> None:
        self._decided = True
        time = arrays.get("time_s")
        if time is None or self.mode == "error":
            return
        for name, values in arrays.items():
            if not _eligible(name) or values.size == 0:
                continue
            present = np.isfinite(values)
            count = int(present.sum())
            if count < 2 or count > (1.0 - SLOW_FRACTION) * values.size:
                continue
            period = float(np.median(np.diff(time[present])))
            if not period > 0:
                continue
            age = self.max_age_s if self.max_age_s is not None else \
                DEFAULT_MAX_AGE_PERIODS * period
            alias = next((c for c in self.channels if _same_cells(arrays[c], values)), None)
            self.channels[name] = ChannelFill(name, period, float(age), alias_of=alias)

    # -- filling ----------------------------------------------------------------------
    def fill(self, arrays: dict[str, np.ndarray], offset: int = 0) -> dict[str, np.ndarray]:
        """The next part of the file (contract columns) with its slow channels filled.

        ``offset`` is the file row of the part's first row. Rows too far from any value
        are dropped; ``interpolate`` returns the rows up to the part's last value and
        keeps the rest for the next call (or :meth:`flush`).
        """
        if not self._decided:
            self._decide(arrays)
        if not self.channels:
            return arrays
        if self._pending is not None:
            arrays = {k: np.concatenate([self._pending[k], arrays[k]]) for k in arrays}
            offset = self._pending_offset
            self._pending = None
        n = len(arrays["time_s"])
        cut = n
        if self.mode == "interpolate":  # rows after a channel's last value may wait for
            time = arrays["time_s"]      # the next one (those within its maximum age)
            for name, state in self.channels.items():
                present = np.flatnonzero(np.isfinite(arrays[name]))
                start = int(present[-1]) + 1 if present.size else 0
                last_time = float(time[present[-1]]) if present.size else state.last_time
                if start < n and time[start] - last_time <= state.max_age_s:
                    cut = min(cut, start)
            if cut < n:
                self._pending = {k: v[cut:] for k, v in arrays.items()}
                self._pending_offset = offset + cut
                arrays = {k: v[:cut] for k, v in arrays.items()}
        return self._fill(arrays, offset, interpolate=self.mode == "interpolate")

    def flush(self) -> dict[str, np.ndarray] | None:
        """The rows held back by ``interpolate`` at the end of the file (held, not
        interpolated: there is no later value), or None."""
        if self._pending is None:
            return None
        arrays, offset = self._pending, self._pending_offset
        self._pending = None
        return self._fill(arrays, offset, interpolate=False)

    def _fill(self, arrays: dict[str, np.ndarray], offset: int,
              interpolate: bool) -> dict[str, np.ndarray]:
        time = arrays["time_s"]
        n = time.size
        keep = np.ones(n, dtype=bool)
        out = dict(arrays)
        for name, state in self.channels.items():
            values = arrays[name]
            present = np.isfinite(values)
            rows = np.arange(n)
            last = np.maximum.accumulate(np.where(present, rows, -1))
            before_time = np.where(last >= 0, time[np.maximum(last, 0)], state.last_time)
            before_value = np.where(last >= 0, values[np.maximum(last, 0)], state.last_value)
            age = time - before_time
            filled = before_value.copy()
            if interpolate:
                following = np.minimum.accumulate(np.where(present, rows, n)[::-1])[::-1]
                inside = ~present & (following < n) & np.isfinite(before_value)
                nxt = np.minimum(following, n - 1)
                span = time[nxt] - before_time
                with np.errstate(invalid="ignore", divide="ignore"):
                    share = np.where(inside & (span > 0), (time - before_time) / span, 0.0)
                filled = np.where(inside, before_value + share * (values[nxt] - before_value),
                                  filled)
            too_old = ~present & ~(age <= state.max_age_s)
            out[name] = np.where(present, values, filled)
            state.filled += int(np.count_nonzero(~present & ~too_old))
            dropped = int(np.count_nonzero(too_old))
            if dropped and state.first_dropped_row is None:
                state.first_dropped_row = offset + int(np.argmax(too_old))
            state.dropped += dropped
            keep &= ~too_old
            if present.any():
                k = int(np.flatnonzero(present)[-1])
                state.last_time, state.last_value = float(time[k]), float(values[k])
        if keep.all():
            return out
        return {k: v[keep] for k, v in out.items()}

    # -- reporting --------------------------------------------------------------------
    def summary(self) -> Summary:
        """Each slow channel's period, how long a value is used, the cells filled and the
        rows dropped (its text: one line per channel, each a warning)."""
        where = escape(f"{self.source}: ") if self.source else ""
        how = "held (last value)" if self.mode == "hold" else "interpolated linearly in time"
        sections, lines = [], []
        for k, s in enumerate(self._reported()):
            # by place, not by name: a column's name may hold ':' or braces (a TDMS channel
            # named by its clock time), which a layout field cannot
            key = f"channels[{k}]"
            figures = [Figure(f"{key}.column", "column", s.column),
                       Figure(f"{key}.period_s", "logged every", s.period_s, "s",
                              definition="Median time between the channel's values."),
                       Figure(f"{key}.max_age_s", "used for up to", s.max_age_s, "s",
                              definition=f"Longest time a value is {how} (--hold-max-s)."),
                       Figure(f"{key}.filled", "cells filled", s.filled)]
            line = (f"{where}column '{escape(s.column)}' is logged every {{{key}.period_s:g}} s, "
                    f"slower than the file's rows: {how} for up to {{{key}.max_age_s:g}} s "
                    f"(--slow-channels {self.mode}, --hold-max-s); {{{key}.filled}} cells filled")
            if s.dropped:
                figures += [Figure(f"{key}.dropped", "rows dropped", s.dropped,
                                   definition="Rows farther than that from a value, dropped "
                                   "as a gap in the channel."),
                            Figure(f"{key}.first_dropped_row", "first dropped row",
                                   s.first_dropped_row)]
                line += (f", {{{key}.dropped}} rows dropped as a gap in the channel (farther "
                         f"than {{{key}.max_age_s:g}} s from a value; first at row "
                         f"{{{key}.first_dropped_row}})")
            sections.append((f"column {s.column}", tuple(figures)))
            lines.append(line)
        return Summary(f"slow channels ({self.mode})", tuple(sections), layout=tuple(lines))

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types: the mode and each slow channel's figures
        (:class:`SlowChannelsRecord`)."""
        return records.dump(self, SlowChannelsRecord, channels=self._reported())

    def _reported(self) -> list[ChannelFill]:
        """The channels to report: not a second name of the same cells (``--thermometer
        sensor`` reads its temperature column as ``freq_hz_<axis>`` too)."""
        return [s for s in self.channels.values() if s.alias_of is None]

    def warn(self) -> None:
        """Report each slow channel once as a :class:`~hrgtc.core.errors.SlowChannelWarning`."""
        for line in self.summary().text().splitlines():
            warnings.warn(line, SlowChannelWarning, stacklevel=3)


class SlowChannelsRecord(Record):
    """The record of :class:`SlowChannels`: the mode and the channels reported (not a
    second name of the same cells)."""

    mode: Literal["hold", "interpolate", "error"]
    channels: list[ChannelFillRecord]


def _same_cells(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two columns are the same array (one column mapped under two names)."""
    return a is b or (a.shape == b.shape and a.strides == b.strides
                      and a.__array_interface__["data"][0] == b.__array_interface__["data"][0])


def channel_period(time_s: np.ndarray) -> float:
    """The period of a channel: the median step between the times of its values. [s]"""
    return float(np.median(np.diff(time_s))) if time_s.size >= 2 else math.nan


def resample_channel(time_s: np.ndarray, sample_time_s: np.ndarray, sample_values: np.ndarray,
                     mode: str, max_age_s: float) -> tuple[np.ndarray, np.ndarray, int]:
    """A channel logged on its own time axis, at the times ``time_s`` of another.

    The rule of :class:`SlowChannels` for a channel of another stream: at each time,
    the channel's last value at or before it (``"hold"``), or the straight line to its
    next value (``"interpolate"``; after the last value, the last value); a time farther
    than ``max_age_s`` after the last value, or before the first, is too old.

    Parameters
    ----------
    time_s
        The times to give values at. [s]
    sample_time_s, sample_values
        The channel's times (increasing) and finite values. [s], [unit]
    mode
        ``"hold"`` or ``"interpolate"``.
    max_age_s
        Longest time a value is used for. [s]

    Returns
    -------
    values, too_old, exact
        The channel at ``time_s``, the mask of the times too far from a value (to be
        dropped as a gap in the channel), and the number of times that are times of a
        value (not filled).
    """
    last = np.searchsorted(sample_time_s, time_s, side="right") - 1
    known = last >= 0
    at = np.maximum(last, 0)
    if sample_time_s.size == 0:
        return np.full(time_s.shape, np.nan), np.ones(time_s.shape, dtype=bool), 0
    before_time = np.where(known, sample_time_s[at], -math.inf)
    values = np.where(known, sample_values[at], math.nan)
    if mode == "interpolate":
        nxt = np.minimum(at + 1, sample_time_s.size - 1)
        span = sample_time_s[nxt] - before_time
        inside = known & (nxt > at) & (span > 0)
        with np.errstate(invalid="ignore", divide="ignore"):
            share = np.where(inside, (time_s - before_time) / span, 0.0)
        values = np.where(inside, values + share * (sample_values[nxt] - values), values)
    too_old = ~(time_s - before_time <= max_age_s)
    return values, too_old, int(np.count_nonzero(before_time == time_s))


def fill_slow_channels(arrays: dict[str, np.ndarray], mode: str = "hold",
                       max_age_s: float | None = None,
                       source: str = "") -> tuple[dict[str, np.ndarray], SlowChannels]:
    """Batch form: the whole file's columns filled, and what was done."""
    slow = SlowChannels(mode, max_age_s, source)
    out = slow.fill(arrays)
    tail = slow.flush()
    if tail is not None:
        out = {k: np.concatenate([out[k], tail[k]]) for k in out}
    return out, slow
