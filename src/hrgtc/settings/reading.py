"""Settings of reading a user's files (stage 1): the reading options of every command.

:class:`ReadSettings` holds the fields of :class:`hrgtc.recording.ReadOptions` (which
adds the methods that read) and their defaults; ``hrgtc`` generates its shared reading
options (``--gaps``, ``--spikes``, ``--spike-k``, ...) from the fields that name one.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from hrgtc.settings import setting

#: Gap policies (:mod:`hrgtc.recording.gaps`).
GAP_POLICIES = ("error", "split", "bridge", "ignore")
#: What reading does with samples no gyro can produce (:mod:`hrgtc.recording.spikes`).
SPIKE_POLICIES = ("error", "drop")
#: What the robust spike filter does with the spikes it finds.
SPIKE_FILTERS = ("off", "drop", "flag")
#: What calibration and evaluation do with samples not at rest (:mod:`hrgtc.recording.motion`).
MOTION_POLICIES = ("exclude", "keep", "error")
#: Channels logged slower than the rows (:mod:`hrgtc.recording.resample`).
SLOW_MODES = ("hold", "interpolate", "error")
#: Kinds of thermometer: the resonator's frequency, or a temperature sensor.
THERMOMETERS = ("resonator", "sensor")
#: Signed temperature counts stored unsigned.
TEMP_UNWRAPS = ("auto", "off", "16", "32")
#: Rows per chunk when :func:`hrgtc.recording.iter_chunks`, :func:`hrgtc.recording.describe`
#: or :meth:`hrgtc.recording.ReadOptions.chunks` stream a file (about 20 MB of float64
#: columns for a ten-column file).
CHUNK_ROWS = 250_000
#: Longest gap that is a dropout, bridged and counted by default: half the df/dt filter's
#: default time constant (:class:`hrgtc.settings.drift.DriftSettings`, 10 s). [s]
DROPOUT_S = 5.0
#: Default maximum age of a held value of a slow channel, in periods of the channel.
DEFAULT_MAX_AGE_PERIODS = 3.0

_INPUT = "Input recordings"


@dataclass(frozen=True)
class ReadSettings:
    """How to read a user's files; see :class:`hrgtc.recording.ReadOptions`."""

    columns: Mapping[str, str] | Sequence[str] | None = None
    units: Mapping[str, str] | None = None
    metadata: Mapping[str, Any] | None = None
    gaps: str = setting(
        "error", "Gaps longer than 2 sample periods: fail (error), process the segments "
        "separately (split: the df/dt filter restarts after each gap), or carry the filters "
        "across each gap with its duration (bridge, e.g. a burst logger; ignore is an old name "
        "for it). Windows, bias stability and Allan deviation never cross a gap.",
        choices=GAP_POLICIES, panel=_INPUT)
    dropout_s: float = setting(
        DROPOUT_S, "Gaps no longer than this are dropouts (a lost record, a late time stamp): "
        "bridged and counted whatever --gaps says, as they change no result (the df/dt "
        "filter's default τ is 10 s: a dropout of half of it moves df/dt by less than its "
        "noise). Only longer gaps need --gaps.", unit="s", metavar="S", panel=_INPUT)
    chunk_rows: int = CHUNK_ROWS
    freq_band_hz: tuple[float, float] | None = None
    freq_span_hz: tuple[float, float] | None = None
    temp_scale: float = setting(
        1.0, "Temperature logged as a raw sensor count: temperature_c = raw * K + C for every "
        "temperature_c* column (with --temp-offset C).", cli="--temp-scale", metavar="K",
        panel=_INPUT)
    temp_offset_c: float = setting(
        0.0, "Offset of --temp-scale: temperature_c = raw * K + C.", unit="°C",
        cli="--temp-offset", metavar="C", panel=_INPUT)
    spikes: str = setting(
        "error", "Samples no gyro can produce (NaN, beyond 1000 °/s, impossible temperatures "
        "or frequencies): fail naming the row (error) or drop those rows (drop: their number "
        "is reported).", choices=SPIKE_POLICIES, panel=_INPUT)
    thermometer: str = setting(
        "resonator", "The gyro's thermometer: its resonator frequency (resonator; freq_hz "
        "columns) or, for gyros without a frequency output, its temperature sensor (sensor: "
        "the temperature_c or temperature_c_<axis> column takes the place of freq_hz).",
        choices=THERMOMETERS, panel=_INPUT)
    axis: str | None = None
    rate_scale: float | None = setting(
        None, "With --rate-unit lsb: the datasheet's sensitivity K in LSB per °/s "
        "(rate [°/h] = count × 3600 / K).", metavar="K", panel=_INPUT)
    temp_unwrap: str = setting(
        "auto", "A raw temperature count that sits just under 2^16 or 2^32 is a signed count "
        "stored unsigned and is unwrapped (65236 -> -300), with a warning (auto); off reads "
        "it as it is; 16 or 32 always unwraps that width.", choices=TEMP_UNWRAPS,
        panel=_INPUT)
    spike_filter: str | None = setting(
        None, "Single-sample spikes of plausible value in the rate and thermometer columns "
        "(beyond max(k·σ_MAD, m·LSB) from both neighbours, σ_MAD over --spike-window-s "
        "windows that never span a gap): remove their rows (drop), mark them in a 'spike' "
        "column (flag, which never drops) or leave them (off). Their number is reported.",
        choices=SPIKE_FILTERS, default_text="drop for calibrate and evaluate, flag for "
        "compensate and info, off in the library", panel=_INPUT)
    spike_k: float = setting(8.0, "Spike threshold in robust σ (MAD).", metavar="K",
                             panel=_INPUT)
    spike_lsb: float = setting(
        4.0, "Spike threshold floor in steps of the channel's resolution (LSB), so a "
        "quantised stream keeps its pulses.", metavar="M", panel=_INPUT)
    spike_window_s: float = setting(10.0, "Window of the spike filter's σ_MAD.", unit="s",
                                    metavar="S", panel=_INPUT)
    motion: str = setting(
        "exclude", "Samples not at rest (handling, turning, shaking, clipping; found against "
        "the local still level, the at-rest noise and any accel_x/y/z columns, with a guard "
        "time): left out of calibration and evaluation and counted (exclude), used (keep), "
        "or an error naming the first one (error).", choices=MOTION_POLICIES, panel=_INPUT)
    start: str | None = setting(
        None, "Read from this time on: seconds since the file's first sample (e.g. 600) or, "
        "for a file with clock times, an ISO time (e.g. 2020-03-07T16:30). Rows before are "
        "counted, not used.", metavar="SECONDS|ISO", default_text="the first sample",
        panel=_INPUT)
    end: str | None = setting(
        None, "Read up to (not including) this time: seconds since the file's first sample "
        "or an ISO clock time, as for --start.", metavar="SECONDS|ISO",
        default_text="the last sample", panel=_INPUT)
    slow_channels: str = setting(
        "hold", "A channel logged slower than the rows (e.g. a 1 Hz temperature in a 10 Hz "
        "file: empty cells): hold its last value (hold), interpolate linearly in time, or "
        "refuse the empty cells (error). What was done is reported.", choices=SLOW_MODES,
        panel=_INPUT)
    hold_max_s: float | None = setting(
        None, "Longest time a slow channel's value is used for; rows farther from a value "
        "are dropped as a gap in that channel.", unit="s", metavar="S",
        default_text=f"{DEFAULT_MAX_AGE_PERIODS:g} of the channel's periods", panel=_INPUT)
    tz: str | None = setting(
        None, "Time zone the clock times (--time-unit timestamp) were written in, an IANA "
        "name (e.g. Europe/Berlin): they are read as UTC, so the daylight-saving step is gone; "
        "--start/--end clock times too.", metavar="ZONE",
        default_text="none (a 3600 s step is an error)", panel=_INPUT)


def with_fields(options: ReadSettings | None, fields: Mapping[str, Any],
                caller: str) -> ReadSettings:
    """``options`` (the defaults when None) with ``fields`` in place of their values.

    The functions that read (:func:`hrgtc.recording.read`, ``iter_chunks``,
    ``describe``) take one options object and, for convenience, any of its fields by
    name (``read(path, spikes="drop")``); this is where those names are checked, so the
    list of reading options is written once, in :class:`ReadSettings`.

    Raises
    ------
    TypeError
        ``options`` is not reading options (e.g. a column mapping given by position), or
        a name in ``fields`` is not a field of :class:`ReadSettings`; the message lists them.
    """
    if options is not None and not isinstance(options, ReadSettings):
        raise TypeError(f"{caller}(path, options): options must be ReadOptions (or None), "
                        f"not {type(options).__name__}; give a column mapping by name "
                        "(columns=...)")
    names = [field.name for field in dataclasses.fields(ReadSettings)]
    unknown = sorted(set(fields) - set(names))
    if unknown:
        raise TypeError(f"{caller}() got unknown reading option(s) {', '.join(unknown)}; the "
                        f"reading options (hrgtc.settings.reading.ReadSettings) are "
                        f"{', '.join(names)}")
    base = ReadSettings() if options is None else options
    return dataclasses.replace(base, **fields) if fields else base
