"""What a real logger writes, with ground truth: bursts, clocks, restarts, counts, spikes.

The simulator's runs (:mod:`hrgtc.simulate.campaign`) are continuous, in seconds, in
°/h, with a resonator frequency. A test bench's logger writes something else, and
:func:`log_run` turns a simulated run into it, keeping the truth of every row:

* **duty cycle**: ``burst`` keeps ``burst_s`` of every ``period_s`` (50 Hz bursts of 5 s
  every 300 s in the PAN cold test); ``continuous`` keeps every sample;
* **clock**: time in s, ms or µs since power-on (from ``clock_start_s``), with Gaussian
  jitter, optionally a ``counter_bits`` counter that wraps (a 32-bit µs counter every
  71.6 min); or wall-clock ISO 8601 timestamps, in a time zone whose daylight-saving
  change is a ±1 h step;
* **restarts**: at each ``restarts_s`` the logger is off for ``restart_off_s``, then its
  clock, burst schedule and the gyro's warm-up start again; each run may have its own
  turn-on offset (``run_offset_dph``, a nuisance constant) and warm-up transient;
* **rates** in °/h, °/s, rad/s or mrad/s, rounded to ``rate_digits`` significant digits
  as some loggers print them;
* **temperature** (:class:`~hrgtc.simulate.reflog.TemperatureChannel`): °C or a raw count,
  possibly slower than the rates (empty cells between), and a hand-written reference
  log (:class:`~hrgtc.simulate.reflog.ReferenceLog`);
* **spikes**: single-sample spikes of known size and row;
* **handling** (:class:`~hrgtc.simulate.handling.Handling`): still periods in several
  orientations with rotation bursts between them, and accelerometer columns.

The simulation runs at the logger's sample rate over the whole run, chunk by chunk, and
keeps the logged rows (:mod:`hrgtc.simulate.duty`; 2 h at 50 Hz of a three-axis unit
take about a second), so the kept samples are those of the continuous recording with
the same seed, cut into bursts, and memory grows with the rows kept.
Writing the files: :mod:`hrgtc.simulate.logged_files`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from datetime import datetime, timedelta
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.settings.simulation import LOGGER_RATE_UNITS, LOGGER_TIME_UNITS
from hrgtc.settings.simulation import PLAIN_LOGGER as _PLAIN
from hrgtc.simulate import units as _units
from hrgtc.simulate.clock import unwrap_counter, wall_clock
from hrgtc.simulate.duty import (
    DutyCycle,
    KeptRun,
    duplicate_rows,
    segment_index,
    simulate_kept,
    track_derivative,
)
from hrgtc.simulate.handling import Handling, HandlingTruth, handling_truth, warm_by_hand
from hrgtc.simulate.logger_options import reading_options
from hrgtc.simulate.logger_records import LoggedRunRecord, LoggerRecord
from hrgtc.simulate.profiles import Profile
from hrgtc.simulate.reflog import (
    ReferenceLog,
    TemperatureChannel,
    reference_log_info,
    reference_log_text,
)
from hrgtc.simulate.units import MultiAxisUnit, Unit

__all__ = [
    "RATE_FACTORS",
    "TIME_FACTORS",
    "LoggedRun",
    "Logger",
    "log_run",
    "unwrap_counter",
    "wall_clock",
]

#: °/h -> the rate unit written: value_written = rate_dph * factor.
RATE_FACTORS = dict(zip(LOGGER_RATE_UNITS, (
    1.0,
    1.0 / 3600.0,
    math.pi / 180.0 / 3600.0,
    1000.0 * math.pi / 180.0 / 3600.0,
), strict=True))
#: s -> the time unit written.
TIME_FACTORS = {"s": 1.0, "ms": 1e3, "us": 1e6}
_RATE_LABELS = {"dph": "deg/h", "dps": "deg/s", "radps": "rad/s", "mradps": "mrad/s"}


@dataclass(frozen=True)
class Logger(records.Written):
    """A data logger: what it keeps of a run and how it writes it.

    Parameters
    ----------
    kind
        ``continuous`` or ``burst``.
    sample_rate_hz
        Sample rate of the logger (the run is simulated at this rate). [Hz]
    burst_s, period_s
        A burst logger keeps ``burst_s`` of every ``period_s``, from each power-on. [s]
    time_unit
        ``s``, ``ms`` or ``us`` since power-on (ms and µs as integers), or ``timestamp``:
        ISO 8601 wall-clock times from ``start`` (they do not reset at a restart).
    counter_bits
        The time is an unsigned counter of this many bits that wraps; None: no wrap.
    clock_start_s
        Clock reading at the first sample after power-on. [s]
    jitter_s
        Rms jitter of each time stamp. [s]
    start
        Wall-clock time (naive, local) of the run's t = 0, for ``timestamp``.
    timezone
        IANA zone of the wall clock (e.g. ``Europe/Berlin``): a daylight-saving change
        inside the run is a ±1 h step in the timestamps; None: no zone, no step.
    restarts_s
        Times of power cycles, from the start of the run. [s]
    restart_off_s
        How long the logger stays off at a restart. [s]
    run_offset_dph
        Rms of a constant turn-on offset drawn for each run (the first run included). [°/h]
    warmup_dph, warmup_tau_s
        A warm-up transient ``warmup_dph * exp(-t/warmup_tau_s)`` after each power-on. [°/h], [s]
    rate_unit
        ``dph``, ``dps``, ``radps`` or ``mradps``.
    rate_digits
        Significant digits of the rates in the file; None: full precision.
    frequency
        Write the resonator frequency (an HRG); False for a gyro without one (MEMS).
    temperature
        The logged temperature channel, or None.
    reference_log
        A hand-written reference log beside the file, or None (needs ``temperature``).
    duplicates
        Number of rows written twice (a logger re-sending a line).
    spikes
        Number of single-sample spikes.
    spike_dph
        Size of each spike (sign included); 0: 50 times the rate noise, negative. [°/h]
    handling
        Orientations and handling between them, or None (at rest in one orientation).
    accelerometer
        Write accelerometer columns (``accel_unit``).
    accel_unit
        ``g`` or ``mps2``.
    columns
        Role -> the logger's column name; roles ``time``, ``rate_<axis>``, ``freq_<axis>``,
        ``temperature``, ``accel_x|y|z`` (``rate``/``freq`` for a single-axis unit).
        Roles not given get generic names (:meth:`column_names`).
    extra_columns
        Channels the logger also writes that hrgtc does not use (a magnetometer): name ->
        (mean, rms) of a white noise, written right after the time (as the PAN file does).
    """

    #: Its record: the sidecar's part (LoggedRunRecord) in the module below nests it.
    written_by = LoggerRecord

    kind: str = "continuous"
    sample_rate_hz: float = 50.0
    burst_s: float = _PLAIN["burst_s"]
    period_s: float = _PLAIN["period_s"]
    time_unit: str = _PLAIN["time_unit"]
    counter_bits: int | None = _PLAIN["counter_bits"]
    clock_start_s: float = _PLAIN["clock_start_s"]
    jitter_s: float = _PLAIN["jitter_ms"] * 1e-3
    start: str = _PLAIN["wall_start"]
    timezone: str | None = _PLAIN["tz"]
    restarts_s: tuple[float, ...] = _PLAIN["restarts"]
    restart_off_s: float = 10.0
    run_offset_dph: float = _PLAIN["run_offset_dph"]
    warmup_dph: float = _PLAIN["warmup_dph"]
    warmup_tau_s: float = _PLAIN["warmup_tau_s"]
    rate_unit: str = _PLAIN["rate_unit"]
    rate_digits: int | None = _PLAIN["rate_digits"]
    frequency: bool = True
    temperature: TemperatureChannel | None = None
    reference_log: ReferenceLog | None = None
    duplicates: int = _PLAIN["duplicates"]
    spikes: int = _PLAIN["spikes"]
    spike_dph: float = _PLAIN["spike_dph"]
    handling: Handling | None = None
    accelerometer: bool = _PLAIN["accelerometer"]
    accel_unit: str = "g"
    columns: Mapping[str, str] = field(default_factory=dict)
    extra_columns: Mapping[str, tuple[float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        choices = {"kind": ("continuous", "burst"),
                   "time_unit": LOGGER_TIME_UNITS,
                   "rate_unit": tuple(RATE_FACTORS), "accel_unit": ("g", "mps2")}
        for name, allowed in choices.items():
            if getattr(self, name) not in allowed:
                raise InputError(f"logger {name} {getattr(self, name)!r}: choose one of "
                                 f"{', '.join(allowed)}")
        positive = ["sample_rate_hz"] + (["burst_s", "period_s"] if self.kind == "burst" else [])
        for name in positive:
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(f"logger {name} must be finite and > 0, got {value!r}")
        if self.kind == "burst" and self.burst_s >= self.period_s:
            raise InputError(f"burst_s {self.burst_s:g} must be shorter than period_s "
                             f"{self.period_s:g} [s]; use kind='continuous' for no gaps")
        if self.counter_bits is not None:
            if self.time_unit not in ("ms", "us"):
                raise InputError(f"a wrapping counter needs time_unit ms or us, not "
                                 f"{self.time_unit}")
            if not 8 <= int(self.counter_bits) <= 63:
                raise InputError(f"counter_bits must be 8..63, got {self.counter_bits!r}")
        if not (0.0 <= self.jitter_s < 0.25 / self.sample_rate_hz):
            raise InputError(f"jitter_s {self.jitter_s!r} must be >= 0 and below a quarter "
                             f"of the sample period {1.0 / self.sample_rate_hz:g} s")
        restarts = tuple(float(t) for t in self.restarts_s)
        if list(restarts) != sorted(restarts) or any(t <= 0 for t in restarts):
            raise InputError(f"restarts_s {restarts} must be increasing times > 0 [s]")
        object.__setattr__(self, "restarts_s", restarts)
        if self.reference_log is not None and self.temperature is None:
            raise InputError("a reference log needs a logged temperature channel")
        if self.rate_digits is not None and not 1 <= int(self.rate_digits) <= 17:
            raise InputError(f"rate_digits must be 1..17, got {self.rate_digits!r}")
        object.__setattr__(self, "columns", dict(self.columns))
        object.__setattr__(self, "extra_columns", {
            str(k): (float(v[0]), float(v[1])) for k, v in dict(self.extra_columns).items()})

    def column_names(self, axes: tuple[str | None, ...]) -> dict[str, str]:
        """Role -> column name in the file, in column order."""
        time_name = {"s": "time_s", "ms": "time_ms", "us": "time_us",
                     "timestamp": "timestamp"}[self.time_unit]
        names = {"time": time_name}
        names.update({f"extra:{name}": name for name in self.extra_columns})
        label = _RATE_LABELS[self.rate_unit]
        for axis in axes:
            key = "" if axis is None else f"_{axis}"
            if self.frequency:
                names[f"freq{key}"] = f"f{key} [Hz]"
            names[f"rate{key}"] = f"gyro{key} [{label}]"
        if self.temperature is not None:
            names["temperature"] = "temp_raw" if self.temperature.lsb_c is not None else "temp [C]"
        if self.accelerometer:
            unit = "g" if self.accel_unit == "g" else "m/s^2"
            names.update({f"accel_{a}": f"acc_{a} [{unit}]" for a in "xyz"})
        unknown = sorted(set(self.columns) - set(names))
        if unknown:
            raise InputError(f"logger columns {unknown} are not roles of this file; roles: "
                             f"{', '.join(names)}")
        names.update(self.columns)
        if len(set(names.values())) != len(names):
            raise InputError(f"logger column names must be distinct, got {list(names.values())}")
        return names



@dataclass
class LoggedRun:
    """A run as a logger wrote it, and its truth.

    Attributes
    ----------
    columns
        Column name -> values as written (NaN: an empty cell), in file order.
    kinds
        Column name -> ``int`` or ``float`` and its digits, for writing.
    truth
        Per logged row: true time, run, segment, flags and the simulator's truth columns.
    info
        The sidecar (plain JSON types): logger, unit, maps, spikes, segments, ranges,
        and the ``hrgtc`` options that read the file.
    reference_log
        Text of the hand-written reference log, or None.
    """

    columns: dict[str, np.ndarray]
    kinds: dict[str, str]
    truth: dict[str, np.ndarray]
    info: dict[str, Any]
    reference_log: str | None = None

    def __len__(self) -> int:
        return len(next(iter(self.columns.values())))


def _round_significant(value: np.ndarray, digits: int) -> np.ndarray:
    """``value`` rounded to ``digits`` significant digits (as printf's %.{d-1}E)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        exponent = np.floor(np.log10(np.abs(value)))
    exponent = np.where(np.isfinite(exponent), exponent, 0.0)
    scale = 10.0 ** (digits - 1 - exponent)
    return np.round(value * scale) / scale


def log_run(
    profile: Profile,
    unit: str | Unit | MultiAxisUnit,
    logger: Logger,
    seed: int = 0,
    input_rate_dph: float | Mapping[str, float] | None = None,
) -> LoggedRun:
    """Simulate a run and write it as ``logger`` would, with the truth of every row.

    Parameters
    ----------
    profile
        The chamber program.
    unit
        A unit name or unit (``mems-3`` for a MEMS gyro: write it with ``frequency`` False).
    logger
        The logger.
    seed
        Non-negative integer; the same seed gives the same files.
    input_rate_dph
        Known constant input rate, as for :func:`hrgtc.simulate.simulate_run`. [°/h]

    Returns
    -------
    LoggedRun
        Columns as written, the truth per row and the sidecar.
    """
    gyro = unit if isinstance(unit, Unit | MultiAxisUnit) else _units.get(unit)
    axes: tuple[str | None, ...] = (gyro.axis_names if isinstance(gyro, MultiAxisUnit)
                                    else (None,))
    names = logger.column_names(axes)
    sim_seed, logger_seed = np.random.SeedSequence(int(seed)).spawn(2)
    rng = np.random.default_rng(logger_seed)
    fs = logger.sample_rate_hz
    burst_logger = logger.kind == "burst"
    duty = DutyCycle(fs, logger.burst_s if burst_logger else None,
                     logger.period_s if burst_logger else None,
                     logger.restarts_s, logger.restart_off_s)
    kept = simulate_kept(profile, gyro, duty, sim_seed, input_rate_dph)
    if logger.handling is not None and logger.handling.hand_warming_c:
        warm_by_hand(gyro, axes, logger.handling, kept.columns, kept.track, kept.duration_s)
    t = kept.columns["time_s"]
    body = {a: (a if a is not None else "z") for a in axes}
    handled = (handling_truth(t, list(body.values()), logger.handling, rng, kept.duration_s)
               if logger.handling is not None else None)
    run_offsets = rng.normal(0.0, logger.run_offset_dph, size=duty.power_on_s.size)
    log = _Log(logger, axes, names, rng, kept, handled, run_offsets)
    _write_clock(log)
    _write_rates(log, *_draw_spikes(log))
    temperature_info, reference_text = _write_temperature(log)
    _write_accel_and_extra(log)
    columns = {name: log.columns[name] for name in names.values() if name in log.columns}
    info = _sidecar(log, profile, gyro.name, int(seed), temperature_info)
    rows, truth = log.rows, log.truth
    info["duplicates"] = []
    truth["duplicate"] = np.zeros(rows.size, dtype=bool)
    if logger.duplicates:
        if int(logger.duplicates) > rows.size // 10:
            raise InputError(f"{logger.duplicates} duplicated rows of {rows.size}: give at most "
                             "one per ten rows")
        duplicate_rows(columns, truth, info,
                       rng.choice(rows.size, size=int(logger.duplicates), replace=False))
    info["hrgtc_options"] = reading_options(info, axes, logger)
    info = records.dump(None, LoggedRunRecord, **info)  # its record's order, types and checks
    return LoggedRun(columns, log.kinds, truth, info, reference_text)


@dataclass
class _Log:
    """What the stages of :func:`log_run` read (``kept``: the simulated run at the kept
    rows; ``handled``: the handling's truth or None; ``run_offsets``: each power-on's rate
    offset [°/h]) and write: ``columns`` and ``kinds`` as written, ``truth`` per row, and
    what the sidecar reports of spikes, rates of change and motion."""

    logger: Logger
    axes: tuple[str | None, ...]
    names: dict[str, str]
    rng: np.random.Generator
    kept: KeptRun
    handled: HandlingTruth | None
    run_offsets: np.ndarray
    t: np.ndarray = field(init=False)  # time of each kept row [s]
    rows: np.ndarray = field(init=False)  # every kept row
    truth: dict[str, np.ndarray] = field(init=False)
    columns: dict[str, np.ndarray] = field(default_factory=dict)
    kinds: dict[str, str] = field(default_factory=dict)
    spikes_info: list[dict[str, Any]] = field(default_factory=list)
    dfdt_info: dict[str, Any] = field(default_factory=dict)
    motion_rate_max: float = 0.0

    def __post_init__(self) -> None:
        self.t = self.kept.columns["time_s"]
        self.rows = rows = np.arange(self.t.size)
        run, handled = self.kept.run, self.handled
        truth: dict[str, np.ndarray] = {
            "time_s": self.t[rows],
            "run": run[rows],
            "segment": segment_index(run, self.kept.burst),
            "motion": (handled.motion[rows] if handled else np.zeros(rows.size, dtype=bool)),
            "orientation": (handled.orientation[rows] if handled
                            else np.zeros(rows.size, dtype=np.int64)),
            "chamber_c": self.kept.columns["chamber_c"][rows],
            "housing_c": self.kept.columns["housing_c"][rows],
        }
        restart = np.zeros(rows.size, dtype=bool)
        restart[0] = True
        restart[1:] = truth["run"][1:] != truth["run"][:-1]
        truth["restart"] = restart
        self.truth = truth


def _write_clock(log: _Log) -> None:
    """The time column: time since power-on from clock_start_s, jitter, unit, counter wrap;
    or the wall clock, which runs on through restarts."""
    logger, names, rows, t = log.logger, log.names, log.rows, log.t
    jitter = (log.rng.normal(0.0, logger.jitter_s, size=rows.size) if logger.jitter_s > 0.0
              else np.zeros(rows.size))
    if logger.time_unit == "timestamp":
        clock_s = np.round(t + jitter, 3)
        written_time = wall_clock(logger.start, clock_s, logger.timezone)
        log.kinds[names["time"]] = "str"
        log.truth["clock_s"] = clock_s
    else:
        clock_s = logger.clock_start_s + log.kept.since_on_s[rows] + jitter
        factor = TIME_FACTORS[logger.time_unit]
        if logger.time_unit == "s":
            written_time = np.round(clock_s, 6)
            log.kinds[names["time"]] = "float:.6f"
        else:
            written_time = np.round(clock_s * factor)
            log.kinds[names["time"]] = "int"
        log.truth["clock_s"] = written_time / factor
        if logger.counter_bits is not None:
            written_time = np.mod(written_time, 2.0 ** int(logger.counter_bits))
    log.columns[names["time"]] = written_time


def _draw_spikes(log: _Log) -> tuple[np.ndarray, list[str | None]]:
    """The rows and axes of the single-sample spikes (among the still rows)."""
    spike_rows = np.array([], dtype=np.int64)
    spike_axes: list[str | None] = []
    if log.logger.spikes:
        count = int(log.logger.spikes)
        candidates = np.flatnonzero(~log.truth["motion"])
        if count > candidates.size // 10:
            raise InputError(f"{log.logger.spikes} spikes in {candidates.size} still rows: "
                             "give at most one per ten rows (single-sample spikes)")
        spike_rows = np.sort(log.rng.choice(candidates, size=count, replace=False))
        spike_axes = [log.axes[int(i)]
                      for i in log.rng.integers(0, len(log.axes), size=spike_rows.size)]
    log.truth["spike"] = np.isin(log.rows, spike_rows)
    return spike_rows, spike_axes


def _write_rates(log: _Log, spike_rows: np.ndarray, spike_axes: list[str | None]) -> None:
    """Each axis's rate column (offsets, warm-up, motion and spikes added, in the rate unit
    and digits written), its frequency column, and their truth."""
    logger, names, rows, truth = log.logger, log.names, log.rows, log.truth
    rec, track, t, handled = log.kept.columns, log.kept.track, log.t, log.handled
    warmup = logger.warmup_dph * np.exp(-log.kept.since_on_s / logger.warmup_tau_s)
    still = ~truth["motion"]
    for axis in log.axes:
        key = "" if axis is None else f"_{axis}"
        offset = log.run_offsets[log.kept.run[rows]] + warmup[rows]
        motion_dph = np.zeros(rows.size)
        if handled is not None:
            body = axis if axis is not None else "z"
            offset = offset + handled.offset_dph[body][rows]
            motion_dph = handled.motion_dph[body][rows]
            log.motion_rate_max = max(log.motion_rate_max,
                                      float(np.max(np.abs(motion_dph))) / 3600.0)
        rate = rec[f"rate_dph{key}"][rows] + offset + motion_dph
        truth[f"rate_dph{key}"] = rate.copy()
        truth[f"bias_dph{key}"] = rec[f"bias_dph{key}"][rows]
        truth[f"offset_dph{key}"] = offset
        truth[f"motion_dph{key}"] = motion_dph
        truth[f"resonator_c{key}"] = rec[f"resonator_c{key}"][rows]
        if f"scale_ppm{key}" in rec:
            truth[f"scale_ppm{key}"] = rec[f"scale_ppm{key}"][rows]
        # The true rate of change of the thermometer, from the continuous run's slow track.
        dtdt = track_derivative(track, f"resonator_c{key}", t)
        truth[f"dtdt_c_per_s{key}"] = dtdt
        dfdt = track_derivative(track, f"freq_true_hz{key}", t)
        truth[f"dfdt_hz_per_s{key}"] = dfdt
        head = rec[f"rate_dph{key}"][:20000]
        same = np.diff(truth["segment"][:20000]) == 0
        sigma = float(np.std(np.diff(head)[same])) / math.sqrt(2.0) if same.any() else 0.0
        size = logger.spike_dph or -50.0 * sigma
        for r, a in zip(spike_rows, spike_axes, strict=True):
            if a == axis:
                rate[r] += size
                log.spikes_info.append({"row": int(r), "axis": axis,
                                        "column": names[f"rate{key}"], "size_dph": size,
                                        "size_written": size * RATE_FACTORS[logger.rate_unit]})
        written = rate * RATE_FACTORS[logger.rate_unit]
        if logger.rate_digits is not None:
            written = _round_significant(written, int(logger.rate_digits))
            log.kinds[names[f"rate{key}"]] = f"float:.{int(logger.rate_digits) - 1}E"
        else:
            log.kinds[names[f"rate{key}"]] = "float:.17g"
        if logger.frequency:
            log.columns[names[f"freq{key}"]] = rec[f"freq_hz{key}"][rows]
            log.kinds[names[f"freq{key}"]] = "float:.6f"
            truth[f"freq_hz{key}"] = rec[f"freq_hz{key}"][rows]
        log.columns[names[f"rate{key}"]] = written
        label = "x" if axis is None else axis
        for what, values in (("dtdt_c_per_s", dtdt[rows]), ("dfdt_hz_per_s", dfdt[rows])):
            kept = values[still]
            log.dfdt_info.setdefault(what, {})[label] = {
                "min": float(kept.min()), "max": float(kept.max()),
                "p01": float(np.percentile(kept, 1)), "p99": float(np.percentile(kept, 99)),
            }


def _write_temperature(log: _Log) -> tuple[dict[str, Any] | None, str | None]:
    """The logged temperature column and its truth; the sidecar's temperature entry and
    the reference log's text (None without them)."""
    logger, names, rows, truth = log.logger, log.names, log.rows, log.truth
    rec, track, t = log.kept.columns, log.kept.track, log.t
    die = "resonator_c" + ("" if log.axes[0] is None else f"_{log.axes[0]}")
    if logger.temperature is None:
        return None, None
    channel = logger.temperature
    source = rec[die] if channel.source == "die" else rec["housing_c"]
    written = channel.written(source[rows], log.rng)
    if channel.rate_hz is not None:
        tick = np.floor(t[rows] * channel.rate_hz + 1e-9)
        fresh = np.ones(rows.size, dtype=bool)
        fresh[1:] = tick[1:] != tick[:-1]
        written = np.where(fresh, written, np.nan)
        truth["temperature_fresh"] = fresh
    log.columns[names["temperature"]] = written
    log.kinds[names["temperature"]] = ("int" if channel.lsb_c is not None
                                       else f"float:.{int(channel.decimals)}f")
    truth["sensor_c"] = source[rows]
    temperature_info = {"column": names["temperature"], "source": channel.source,
                        "map": channel.map(), "rate_hz": channel.rate_hz,
                        "range_c": [float(source[rows].min()), float(source[rows].max())]}
    if logger.reference_log is None:
        return temperature_info, None
    reference_text, readings = reference_log_text(
        logger.reference_log, track["time_s"],
        track[die] if channel.source == "die" else track["housing_c"],
        track["housing_c"], track["chamber_c"], log.rng)
    # The wall-clock time at which the logger's clock read 0: hrgtc's t = 0 of a file
    # in s/ms/µs since power-on (the first run's, without a counter wrap).
    zero = (datetime.fromisoformat(logger.reference_log.start)
            - timedelta(seconds=logger.clock_start_s)
            if logger.time_unit != "timestamp" else datetime.fromisoformat(logger.start))
    temperature_info["reference_log"] = reference_log_info(logger.reference_log, zero, readings)
    return temperature_info, reference_text


def _write_accel_and_extra(log: _Log) -> None:
    """The accelerometer columns (gravity and handling, or level and still) and the extra
    columns (a mean and white noise)."""
    logger, names, rows, handled = log.logger, log.names, log.rows, log.handled
    if logger.accelerometer:
        accel = (handled.accel_g[rows] if handled is not None
                 else np.tile([0.0, 0.0, 1.0], (rows.size, 1))
                 + log.rng.normal(0.0, 0.002, size=(rows.size, 3)))
        scale = 1.0 if logger.accel_unit == "g" else 9.80665
        for i, a in enumerate("xyz"):
            log.columns[names[f"accel_{a}"]] = np.round(accel[:, i] * scale, 4)
            log.kinds[names[f"accel_{a}"]] = "float:.4f"
    digits = logger.rate_digits
    for name, (mean, rms) in logger.extra_columns.items():
        values = mean + log.rng.normal(0.0, rms, size=rows.size)
        log.columns[name] = values if digits is None else _round_significant(values,
                                                                             int(digits))
        log.kinds[name] = "float:.17g" if digits is None else f"float:.{int(digits) - 1}E"


def _sidecar(log: _Log, profile: Profile, unit_name: str, seed: int,
             temperature_info: dict[str, Any] | None) -> dict[str, Any]:
    """The sidecar's entries (before the duplicates and the reading options)."""
    truth, rows, handled, logger = log.truth, log.rows, log.handled, log.logger
    segment_first = np.flatnonzero(np.diff(truth["segment"], prepend=-1))
    segment_last = np.concatenate((segment_first[1:] - 1, [rows.size - 1]))
    return {
        "simulated": True, "seed": seed, "unit": unit_name, "profile": profile.description,
        "chamber_program": profile.to_dict(), "logger": logger.to_dict(),
        "rows": int(rows.size), "simulated_rows": int(log.kept.simulated_rows),
        "duration_s": log.kept.duration_s,
        "columns": {role: name for role, name in log.names.items()},
        "rate_unit": logger.rate_unit, "time_unit": logger.time_unit,
        "segments": [
            {"first_row": int(a), "last_row": int(b), "run": int(truth["run"][a]),
             "start_s": float(truth["time_s"][a]), "end_s": float(truth["time_s"][b])}
            for a, b in zip(segment_first, segment_last, strict=True)
        ],
        "restarts": [{"row": int(r), "time_s": float(truth["time_s"][r]),
                      "run_offset_dph": float(log.run_offsets[truth["run"][r]])}
                     for r in np.flatnonzero(truth["restart"])],
        "spikes": log.spikes_info, "temperature": temperature_info,
        "dfdt_still": log.dfdt_info, "motion_rows": int(truth["motion"].sum()),
        "motion_peak_dps": log.motion_rate_max,
        "orientations": handled.table if handled is not None else [],
        "handling_windows": handled.windows if handled is not None else [],
    }
