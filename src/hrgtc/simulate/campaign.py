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
5. the gyro noise: ``rate_dph = input_rate_dph + bias_dph + ARW + flicker + RRW``;
6. the housing thermistor: ``housing_c`` = true housing temperature + white noise.

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
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np

from hrgtc.errors import InputError
from hrgtc.progress import Progress
from hrgtc.recording import Metadata, Recording, concatenate
from hrgtc.simulate import units as _units
from hrgtc.simulate.noise import WhiteNoiseStream
from hrgtc.simulate.profiles import Profile
from hrgtc.simulate.units import Unit

__all__ = [
    "COLUMNS",
    "DEFAULT_CHUNK_ROWS",
    "DEFAULT_INPUT_RATE_DPH",
    "Seed",
    "check_rate",
    "check_seed",
    "iter_run_chunks",
    "row_count",
    "run_metadata",
    "simulate_run",
]

#: Columns of a simulated recording, in order.
COLUMNS = ("time_s", "freq_hz", "rate_dph", "chamber_c", "housing_c", "resonator_c", "bias_dph")
#: Rows per generated chunk (~60 MB of columns).
DEFAULT_CHUNK_ROWS = 1 << 19
#: Default known input rate on the sensitive axis, e.g. an Earth-rate component. [°/h]
DEFAULT_INPUT_RATE_DPH = 10.0

Seed = int | np.random.SeedSequence | np.random.Generator


def _resolve_unit(unit: str | Unit) -> Unit:
    return unit if isinstance(unit, Unit) else _units.get(unit)


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


def run_metadata(
    profile: Profile,
    unit: str | Unit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float = DEFAULT_INPUT_RATE_DPH,
) -> Metadata:
    """Metadata of a simulated run (unit name, rate, input rate, profile text, truth)."""
    unit = _resolve_unit(unit)
    seed = check_seed(seed)
    if not math.isfinite(float(input_rate_dph)):
        raise InputError(f"input_rate_dph must be finite [°/h], got {input_rate_dph!r}")
    extra: dict[str, Any] = {"simulated": True, **_seed_record(seed)}
    if profile.setpoint_c is not None:
        extra["setpoint_c"] = profile.setpoint_c
    extra["chamber_program"] = profile.to_dict()
    extra["unit_parameters"] = unit.to_dict()
    return Metadata(
        sample_rate_hz=check_rate(sample_rate_hz),
        unit=unit.name,
        input_rate_dph=float(input_rate_dph),
        profile=profile.description,
        extra=extra,
    )


def iter_run_chunks(
    profile: Profile,
    unit: str | Unit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float = DEFAULT_INPUT_RATE_DPH,
    chunk_rows: int = DEFAULT_CHUNK_ROWS,
    progress: Progress | None = None,
) -> Iterator[Recording]:
    """Simulate a run chunk by chunk.

    Parameters
    ----------
    profile
        The chamber program.
    unit
        A unit name (:func:`hrgtc.simulate.units.names`) or a :class:`Unit`.
    sample_rate_hz
        Sample rate. [Hz]
    seed
        Non-negative integer, :class:`numpy.random.SeedSequence` or
        :class:`numpy.random.Generator`; the same seed gives the same arrays.
    input_rate_dph
        Known rate on the sensitive axis, added to the output. [°/h]
    chunk_rows
        Rows per chunk.
    progress
        Called as ``progress(rows_done, rows_total)`` after each chunk.

    Yields
    ------
    Recording
        Consecutive chunks with the columns of :data:`COLUMNS` and the run's metadata.
    """
    unit = _resolve_unit(unit)
    fs = check_rate(sample_rate_hz)
    if int(chunk_rows) < 1:
        raise InputError(f"chunk_rows must be >= 1, got {chunk_rows!r}")
    metadata = run_metadata(profile, unit, fs, seed, input_rate_dph)
    total = row_count(profile, fs)
    white, slow, freq_rng, housing_rng = _generators(seed, 4)
    gyro = unit.gyro_noise.stream(fs, white, slow)
    freq_noise = WhiteNoiseStream(unit.frequency_noise_hz, freq_rng)
    housing_noise = WhiteNoiseStream(unit.housing_noise_c, housing_rng)
    network = unit.thermal
    state = network.initial_state(profile.start_c)
    times, temps = profile.breakpoints()
    dt = 1.0 / fs

    def draw_noise(count: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return gyro.next(count), freq_noise.next(count), housing_noise.next(count)

    # The random draws of a chunk run in a worker thread while this thread does the
    # deterministic physics (numpy releases the GIL); each stream stays in time order.
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="hrgtc-noise") as pool:
        for start in range(0, total, int(chunk_rows)):
            stop = min(total, start + int(chunk_rows))
            noise = pool.submit(draw_noise, stop - start)
            time_s = np.arange(start, stop, dtype=np.float64) / fs
            chamber = np.interp(time_s, times, temps)
            housing, resonator, state = network.response(chamber, dt, state)
            bias = unit.bias_law.bias_dph(resonator, housing)
            freq = unit.frequency_law.frequency_hz(resonator)
            rate, freq_error, housing_logged = noise.result()
            freq += freq_error
            rate += bias
            rate += float(input_rate_dph)
            housing_logged += housing
            columns = {
                "time_s": time_s,
                "freq_hz": freq,
                "rate_dph": rate,
                "chamber_c": chamber,
                "housing_c": housing_logged,
                "resonator_c": resonator,
                "bias_dph": bias,
            }
            yield Recording(columns, metadata)
            if progress is not None:
                progress(float(stop), float(total))


def simulate_run(
    profile: Profile,
    unit: str | Unit = _units.DEFAULT_UNIT,
    sample_rate_hz: float = 200.0,
    seed: Seed = 0,
    input_rate_dph: float = DEFAULT_INPUT_RATE_DPH,
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
