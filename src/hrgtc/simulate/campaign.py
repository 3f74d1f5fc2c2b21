"""Simulated chamber runs: recordings with ground truth, generated in chunks.

A run is a :class:`~hrgtc.simulate.profiles.Profile` played on a named
:class:`~hrgtc.simulate.units.Unit` at a sample rate. Each chunk of samples goes
through

1. the chamber program (piecewise-linear air temperature, ``chamber_c``, logged
   as the chamber's controller reports it, without noise);
2. the thermal network (housing and resonator temperatures, exact integration);
3. the frequency law (Eq. 15 or Eq. 17-18 of [1]) plus white measurement noise
   (``freq_hz``);
4. the bias law in resonator temperature and gradient (``bias_dph``, ground truth:
   the thermal bias B0 included, without the random noise terms);
5. the gyro noise: ``rate_dph = input_rate_dph + bias_dph + ARW + flicker + RRW``,
   or ``input_rate_dph (1 + scale_ppm 1e-6) + ...`` for a unit with a
   scale-factor law (``scale_ppm``, ground truth); the input is the constant
   input rate plus, on a rate-table run, the table's rate (the
   ``input_rate_dph`` column);
6. the housing thermistor: ``housing_c`` = true housing temperature + white noise.

A :class:`~hrgtc.simulate.units.MultiAxisUnit` runs steps 2-5 once per axis
behind the one housing and writes the per-axis columns ``<name>_<axis>``
(:func:`run_columns`); the housing thermistor and each axis's gyro and
frequency noise draw from their own generators.

``resonator_c`` is the true resonator temperature. Memory does not grow with
duration (chunks of ``chunk_rows`` rows), and a run depends only on its seed:
every noise source draws from its own generator spawned from the seed, in time
order, so the arrays are identical whatever ``chunk_rows`` is. Writing runs to
files: :mod:`hrgtc.simulate.output`.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

import hrgtc.settings.simulation as _settings
from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.recording import Metadata, Recording, concatenate
from hrgtc.simulate import units as _units
from hrgtc.simulate.noise_sources import WhiteNoiseStream
from hrgtc.simulate.profiles import Profile
from hrgtc.simulate.units import MultiAxisUnit, Unit

__all__ = [
    "COLUMNS",
    "DEFAULT_CHUNK_ROWS",
    "DEFAULT_INPUT_RATE_DPH",
    "Seed",
    "check_rate",
    "check_seed",
    "input_rates_dph",
    "iter_run_chunks",
    "row_count",
    "run_columns",
    "run_metadata",
    "simulate_run",
]

#: Columns of a simulated recording, in order.
COLUMNS = ("time_s", "freq_hz", "rate_dph", "chamber_c", "housing_c", "resonator_c", "bias_dph")
#: Rows per generated chunk (~60 MB of columns).
DEFAULT_CHUNK_ROWS = 1 << 19
#: Default known input rate on the sensitive axis, e.g. an Earth-rate component. [°/h]
DEFAULT_INPUT_RATE_DPH = _settings.DEFAULT_INPUT_RATE_DPH

Seed = int | np.random.SeedSequence | np.random.Generator


AnyUnit = Unit | MultiAxisUnit
_SECONDS_PER_HOUR = 3600.0


def _resolve_unit(unit: str | AnyUnit) -> AnyUnit:
    return unit if isinstance(unit, Unit | MultiAxisUnit) else _units.get(unit)


def check_rate(sample_rate_hz: float) -> float:
    """``sample_rate_hz`` as float if finite and positive, else InputError. [Hz]"""
    try:
        value = float(sample_rate_hz)
    except (TypeError, ValueError):
        value = math.nan
    if not (math.isfinite(value) and value > 0.0):
        raise InputError(f"sample_rate_hz must be finite and > 0 [Hz], got {sample_rate_hz!r}")
    return value


def check_seed(seed: Seed) -> Seed:
    """``seed`` if it is a non-negative integer, a SeedSequence or a Generator."""
    if isinstance(seed, np.random.SeedSequence | np.random.Generator):
        return seed
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise InputError(f"seed must be a non-negative integer, got {seed!r}")
    return int(seed)


def _generators(seed: Seed, count: int) -> list[np.random.Generator]:
    """Independent generators, one per noise source, from a seed (never mutated)."""
    if isinstance(seed, np.random.Generator):
        return list(seed.spawn(count))
    if isinstance(seed, np.random.SeedSequence):
        sequence = np.random.SeedSequence(seed.entropy, spawn_key=seed.spawn_key)
    else:
        sequence = np.random.SeedSequence(check_seed(seed))
    return [np.random.default_rng(child) for child in sequence.spawn(count)]


def _seed_record(seed: Seed) -> dict[str, Any]:
    if isinstance(seed, np.random.SeedSequence):
        return {"seed": int(seed.entropy), "spawn_key": list(seed.spawn_key)}
    if isinstance(seed, np.random.Generator):
        return {"seed": None}
    return {"seed": int(seed)}


def row_count(profile: Profile, sample_rate_hz: float) -> int:
    """Number of samples of a run: one every ``1 / sample_rate_hz`` over the profile's duration."""
    return max(1, round(profile.duration_s * check_rate(sample_rate_hz)))


def input_rates_dph(
    unit: str | AnyUnit, input_rate_dph: float | Mapping[str, float] | None = None
) -> dict[str | None, float]:
    """Constant input rate of each axis (key None for a single-axis unit). [°/h]

    ``None`` gives :data:`DEFAULT_INPUT_RATE_DPH` for a single-axis unit and the
    unit's own rates (its Earth-rate components) for a multi-axis one; a number
    gives that rate on every axis; a mapping gives each axis its rate.
    """
    unit = _resolve_unit(unit)
    axes: tuple[str | None, ...] = (
        unit.axis_names if isinstance(unit, MultiAxisUnit) else (None,)
    )
    if input_rate_dph is None:
        if isinstance(unit, MultiAxisUnit):
            return dict(unit.input_rate_dph)
        input_rate_dph = DEFAULT_INPUT_RATE_DPH
    if isinstance(input_rate_dph, Mapping):
        if not isinstance(unit, MultiAxisUnit) or set(input_rate_dph) != set(axes):
            raise InputError(
                f"input_rate_dph {dict(input_rate_dph)} must give a rate for each axis of unit "
                f"{unit.name!r}: {', '.join(str(a) for a in axes)}"
            )
        rates = {a: input_rate_dph[a] for a in axes if a is not None}
    else:
        rates = dict.fromkeys(axes, input_rate_dph)
    for axis, value in rates.items():
        try:
            number = float(value)
        except (TypeError, ValueError):
            number = math.nan
        if not math.isfinite(number):
            where = "" if axis is None else f"[{axis!r}]"
            raise InputError(f"input_rate_dph{where} must be finite [°/h], got {value!r}")
        rates[axis] = number
    return rates


def _check_table_axes(profile: Profile, unit: AnyUnit) -> None:
    """The rate table's axes must be the unit's (none for a single-axis unit)."""
    table = profile.table_axes
    if isinstance(unit, MultiAxisUnit):
        if None in table:
            raise InputError(
                f"profile {profile.name!r} turns the rate table without naming an axis, but "
                f"unit {unit.name!r} has axes {', '.join(unit.axis_names)}; give each rate "
                "segment an axis (rate_table(..., axes=...))"
            )
        unknown = [a for a in table if a not in unit.axes]
        if unknown:
            raise InputError(
                f"profile {profile.name!r} turns axis(es) {unknown}, not axes of unit "
                f"{unit.name!r} ({', '.join(unit.axis_names)})"
            )
    elif any(a is not None for a in table):
        raise InputError(
            f"profile {profile.name!r} turns axis(es) {[a for a in table if a]} but unit "
            f"{unit.name!r} has a single axis; drop the segments' axis"
        )


def run_columns(profile: Profile, unit: str | AnyUnit = _units.DEFAULT_UNIT) -> tuple[str, ...]:
    """Columns of a run, in order.

    A single-axis unit: :data:`COLUMNS`, then ``scale_ppm`` if the unit has a
    scale-factor law and ``input_rate_dph`` if the profile turns a rate table.
    A multi-axis unit: ``time_s``, ``chamber_c``, ``housing_c``, then for each
    axis the :data:`AXIS_COLUMNS` it has, suffixed ``_<axis>``.
    """
    unit = _resolve_unit(unit)
    table = profile.has_rate_table

    def axis_columns(gyro: Unit, suffix: str) -> list[str]:
        names = [f"{n}{suffix}" for n in ("freq_hz", "rate_dph", "resonator_c", "bias_dph")]
        if gyro.scale_factor_law is not None:
            names.append(f"scale_ppm{suffix}")
        if table:
            names.append(f"input_rate_dph{suffix}")
        return names

    if isinstance(unit, MultiAxisUnit):
        out = ["time_s", "chamber_c", "housing_c"]
        for axis, gyro in unit.axes.items():
            out += axis_columns(gyro, f"_{axis}")
        return tuple(out)
    return COLUMNS + tuple(axis_columns(unit, "")[4:])


def run_metadata(
    profile: Profile,
    unit: str | AnyUnit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float | Mapping[str, float] | None = None,
) -> Metadata:
    """Metadata of a simulated run (unit name, rate, input rate, profile text, truth).

    A multi-axis unit's constant input rates go to ``extra["axis_input_rate_dph"]``
    (``input_rate_dph`` is then 0).
    """
    unit = _resolve_unit(unit)
    seed = check_seed(seed)
    rates = input_rates_dph(unit, input_rate_dph)
    _check_table_axes(profile, unit)
    extra: dict[str, Any] = {"simulated": True, **_seed_record(seed)}
    if profile.setpoint_c is not None:
        extra["setpoint_c"] = profile.setpoint_c
    extra["chamber_program"] = profile.to_dict()
    extra["unit_parameters"] = unit.to_dict()
    if isinstance(unit, MultiAxisUnit):
        extra["axis_input_rate_dph"] = dict(rates)
    return Metadata(
        sample_rate_hz=check_rate(sample_rate_hz),
        unit=unit.name,
        input_rate_dph=rates.get(None, 0.0),
        profile=profile.description,
        extra=extra,
    )


def iter_run_chunks(
    profile: Profile,
    unit: str | AnyUnit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float | Mapping[str, float] | None = None,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    progress: Progress | None = None,
) -> Iterator[Recording]:
    """Simulate a run chunk by chunk.

    Parameters
    ----------
    profile
        The chamber program (and rate table, if it turns one).
    unit
        A unit name (:func:`hrgtc.simulate.units.names`), a :class:`Unit` or a
        :class:`MultiAxisUnit`.
    sample_rate_hz
        Sample rate. [Hz]
    seed
        Non-negative integer, :class:`numpy.random.SeedSequence` or
        :class:`numpy.random.Generator`; the same seed gives the same arrays.
    input_rate_dph
        Known constant rate on the sensitive axis (e.g. the Earth-rate
        component), added to the table's rate; per axis for a multi-axis unit
        (see :func:`input_rates_dph`; None: the unit's own). [°/h]
    chunk_rows
        Rows per chunk.
    progress
        Called as ``progress(rows_done, rows_total)`` after each chunk.

    Yields
    ------
    Recording
        Consecutive chunks with the columns of :func:`run_columns` and the run's metadata.
    """
    unit = _resolve_unit(unit)
    fs = check_rate(sample_rate_hz)
    if int(chunk_rows) < 1:
        raise InputError(f"chunk_rows must be >= 1, got {chunk_rows!r}")
    metadata = run_metadata(profile, unit, fs, seed, input_rate_dph)
    rates = input_rates_dph(unit, input_rate_dph)
    total = row_count(profile, fs)
    gyros: dict[str | None, Unit] = (
        dict(unit.axes) if isinstance(unit, MultiAxisUnit) else {None: unit}
    )
    streams, housing_noise = _noise_streams(unit, gyros, fs, seed)
    run = _Run(profile, *profile.breakpoints(), gyros, rates, fs, run_columns(profile, unit),
               metadata,
               {axis: gyro.thermal.initial_state(profile.start_c) for axis, gyro in gyros.items()})

    def draw_noise(count: int) -> tuple[dict[str | None, tuple[np.ndarray, np.ndarray]],
                                         np.ndarray]:
        drawn = {axis: (g.next(count), f.next(count)) for axis, (g, f) in streams.items()}
        return drawn, housing_noise.next(count)

    # The random draws of a chunk run in a worker thread while this thread does the
    # deterministic physics (numpy releases the GIL); each stream stays in time order.
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="hrgtc-noise") as pool:
        for start in range(0, total, int(chunk_rows)):
            stop = min(total, start + int(chunk_rows))
            noise = pool.submit(draw_noise, stop - start)
            yield _chunk(run, start, stop, noise)
            if progress is not None:
                progress(float(stop), float(total))


@dataclass
class _Run:
    """What each chunk of :func:`iter_run_chunks` reads, and the thermal state it advances.

    ``times``, ``temps`` are the chamber program's corners (:meth:`Profile.breakpoints`),
    ``gyros`` maps each axis (None for a single-axis unit) to its gyro, ``rates`` each
    axis to its constant input rate [°/h], ``names`` the run's columns in order and
    ``states`` each axis to its thermal network's state at the end of the last chunk,
    ``plays`` each axis to the state of its play memory
    (the play of its :class:`~hrgtc.simulate.laws.BiasLaw`, if it has one) likewise.
    """

    profile: Profile
    times: np.ndarray
    temps: np.ndarray
    gyros: dict[str | None, Unit]
    rates: Mapping[str | None, float]
    fs: float
    names: tuple[str, ...]
    metadata: Metadata
    states: dict[str | None, Any]
    plays: dict[str | None, float] = field(default_factory=dict)


def _noise_streams(unit: AnyUnit, gyros: dict[str | None, Unit], fs: float, seed: Seed,
                   ) -> tuple[dict[str | None, tuple[Any, WhiteNoiseStream]], WhiteNoiseStream]:
    """Each axis's (gyro noise, frequency noise) streams and the housing thermistor's."""
    if isinstance(unit, MultiAxisUnit):
        # the housing thermistor, then (white, slow, frequency) per axis
        housing_rng, *rngs = _generators(seed, 1 + 3 * len(gyros))
    else:  # the order of the first single-axis runs
        white, slow, freq_rng, housing_rng = _generators(seed, 4)
        rngs = [white, slow, freq_rng]
    streams = {
        axis: (
            gyro.gyro_noise.stream(fs, rngs[3 * k], rngs[3 * k + 1]),
            WhiteNoiseStream(gyro.frequency_noise_hz, rngs[3 * k + 2]),
        )
        for k, (axis, gyro) in enumerate(gyros.items())
    }
    return streams, WhiteNoiseStream(unit.housing_noise_c, housing_rng)


def _chunk(run: _Run, start: int, stop: int, noise: Future[Any]) -> Recording:
    """Rows ``start:stop`` of the run: the physics here, the noise from ``noise``."""
    profile, fs = run.profile, run.fs
    table = profile.has_rate_table
    dt = 1.0 / fs
    time_s = np.arange(start, stop, dtype=np.float64) / fs
    chamber = np.interp(time_s, run.times, run.temps)
    physics = {}
    for axis, gyro in run.gyros.items():
        housing, resonator, run.states[axis] = gyro.thermal.response(chamber, dt,
                                                                     run.states[axis])
        bias = gyro.bias_law.bias_dph(resonator, housing)
        if gyro.bias_law.has_play:  # a memory: its state carried from chunk to chunk
            state = run.plays.get(axis)
            if state is None:
                state = gyro.bias_law.play_state(resonator[0])
            played, run.plays[axis] = gyro.bias_law.play_dph(resonator, state)
            bias += played
        freq = gyro.frequency_law.frequency_hz(resonator)
        physics[axis] = (housing, resonator, bias, freq)
    drawn, housing_logged = noise.result()
    housing_logged += physics[next(iter(run.gyros))][0]  # the axes share the housing
    axis_columns: dict[str, np.ndarray] = {}
    for axis, gyro in run.gyros.items():
        _, resonator, bias, freq = physics[axis]
        rate, freq_error = drawn[axis]
        freq += freq_error
        rate += bias
        suffix = "" if axis is None else f"_{axis}"
        axis_columns[f"freq_hz{suffix}"] = freq
        axis_columns[f"rate_dph{suffix}"] = rate
        axis_columns[f"resonator_c{suffix}"] = resonator
        axis_columns[f"bias_dph{suffix}"] = bias
        applied: float | np.ndarray = run.rates[axis]
        if table:
            applied = profile.table_rate_dps(time_s, axis) * _SECONDS_PER_HOUR
            applied += run.rates[axis]
        if gyro.scale_factor_law is not None:
            # rate = input (1 + k 1e-6) + bias + noise
            scale = gyro.scale_factor_law.ppm(resonator)
            axis_columns[f"scale_ppm{suffix}"] = scale
            rate += applied * (1.0 + scale * 1e-6)
        else:
            rate += applied
        if table:
            axis_columns[f"input_rate_dph{suffix}"] = np.asarray(applied)
    axis_columns.update(time_s=time_s, chamber_c=chamber, housing_c=housing_logged)
    return Recording({name: axis_columns[name] for name in run.names}, run.metadata)


def simulate_run(
    profile: Profile,
    unit: str | AnyUnit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float | Mapping[str, float] | None = None,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    progress: Progress | None = None,
) -> Recording:
    """Simulate a run into memory (see :func:`iter_run_chunks` for the parameters).

    Examples
    --------
    >>> from hrgtc.simulate.standard_profiles import soak
    >>> rec = simulate_run(soak(-10.0, 0.5), sample_rate_hz=1.0, seed=1)
    >>> len(rec), rec.metadata.unit, rec.metadata.profile
    (1800, 'paper-unit', 'soak -10 C, 0.5 h from 20 C')
    """
    return concatenate(
        list(iter_run_chunks(profile, unit, sample_rate_hz, seed, input_rate_dph, chunk_rows,
                             progress))
    )
