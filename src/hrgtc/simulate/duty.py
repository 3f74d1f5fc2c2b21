"""Which samples a logger keeps: power cycles and duty cycle, simulated chunk by chunk.

A logger is on from power-on to the next restart (then off for a while) and, if it is a
burst logger, keeps ``burst_s`` of every ``period_s`` counted from each power-on.
:func:`simulate_kept` runs the simulator at the logger's rate chunk by chunk
(:func:`hrgtc.simulate.campaign.iter_run_chunks`, so the samples are those of the
continuous run with the same seed) and keeps only those rows, plus a slow track of the
continuous run (about one sample a second) for what needs the temperatures between the
kept rows: the true dT/dt and df/dt, and a reference probe that lags behind the sensor.
Memory grows with the kept rows, not with the run: a day of 200 Hz in 5 s bursts
every 5 min is 1.4 M rows kept of 17 M simulated.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.simulate.campaign import Seed, iter_run_chunks, row_count
from hrgtc.simulate.profiles import Profile
from hrgtc.simulate.units import MultiAxisUnit, Unit

__all__ = ["TRACK_HZ", "DutyCycle", "KeptRun", "duplicate_rows", "segment_index", "simulate_kept",
           "track_derivative"]

#: Rate of the slow track of the continuous run. [Hz]
TRACK_HZ = 1.0
_CHUNK_ROWS = 1 << 18


@dataclass(frozen=True)
class DutyCycle:
    """Power cycles and bursts of a logger.

    Parameters
    ----------
    sample_rate_hz
        The logger's rate. [Hz]
    burst_s, period_s
        Burst length and period from each power-on; None: continuous. [s]
    restarts_s
        Times of the power cycles from the start of the run. [s]
    restart_off_s
        Time off at each restart. [s]
    """

    sample_rate_hz: float
    burst_s: float | None = None
    period_s: float | None = None
    restarts_s: tuple[float, ...] = ()
    restart_off_s: float = 10.0

    @property
    def power_on_s(self) -> np.ndarray:
        """Time of each power-on (the first at 0). [s]"""
        return np.array([0.0, *[r + self.restart_off_s for r in self.restarts_s]])

    def classify(self, time_s: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per sample: run index, time since power-on [s], burst index, kept."""
        t = np.asarray(time_s, dtype=np.float64)
        power_on = self.power_on_s
        run = np.searchsorted(power_on, t, side="right") - 1
        since_on = t - power_on[run]
        keep = np.ones(t.size, dtype=bool)
        for r in self.restarts_s:
            keep &= ~((t >= r) & (t < r + self.restart_off_s))
        if self.burst_s is None or self.period_s is None:
            burst = np.zeros(t.size, dtype=np.int64)
        else:
            burst = np.floor(since_on / self.period_s + 1e-9).astype(np.int64)
            keep &= since_on - burst * self.period_s < self.burst_s - 0.5 / self.sample_rate_hz
        return run, since_on, burst, keep


@dataclass
class KeptRun:
    """The kept rows of a simulated run and a slow track of the whole run.

    Attributes
    ----------
    columns
        The simulator's columns at the kept rows.
    run, since_on_s, burst
        Run index, time since power-on [s] and burst index of each kept row.
    track
        ``time_s``, ``chamber_c``, ``housing_c``, ``resonator_c[_axis]`` and the noiseless
        ``freq_true_hz[_axis]`` of the whole run, at about :data:`TRACK_HZ`, evenly spaced.
    simulated_rows
        Rows simulated.
    duration_s
        Time of the run's last sample. [s]
    """

    columns: dict[str, np.ndarray]
    run: np.ndarray
    since_on_s: np.ndarray
    burst: np.ndarray
    track: dict[str, np.ndarray]
    simulated_rows: int
    duration_s: float


def simulate_kept(
    profile: Profile,
    unit: Unit | MultiAxisUnit,
    duty: DutyCycle,
    seed: Seed,
    input_rate_dph: float | Mapping[str, float] | None = None,
) -> KeptRun:
    """Simulate a run at the logger's rate and keep the rows the logger keeps.

    Raises
    ------
    InputError
        If a restart leaves nothing after it, or fewer than 2 rows are kept.
    """
    fs = duty.sample_rate_hz
    total = row_count(profile, fs)
    duration = (total - 1) / fs
    if duty.restarts_s and duty.power_on_s[-1] >= duration:
        raise InputError(f"a restart at {duty.restarts_s[-1]:g} s leaves no run before the "
                         f"end of the {duration:g} s run")
    gyros = dict(unit.axes) if isinstance(unit, MultiAxisUnit) else {None: unit}
    step = max(1, round(fs / TRACK_HZ))
    kept: dict[str, list[np.ndarray]] = {}
    track: dict[str, list[np.ndarray]] = {}
    flags: dict[str, list[np.ndarray]] = {"run": [], "since_on_s": [], "burst": []}
    done = 0
    for chunk in iter_run_chunks(profile, unit, fs, seed, input_rate_dph, _CHUNK_ROWS):
        t = chunk["time_s"]
        run, since_on, burst, keep = duty.classify(t)
        rows = np.flatnonzero(keep)
        for name in chunk.names:
            kept.setdefault(name, []).append(chunk[name][rows])
        flags["run"].append(run[rows])
        flags["since_on_s"].append(since_on[rows])
        flags["burst"].append(burst[rows])
        slow = np.flatnonzero((np.arange(done, done + t.size) % step) == 0)
        sampled = {"time_s": t[slow], "chamber_c": chunk["chamber_c"][slow],
                   "housing_c": chunk["housing_c"][slow]}
        for axis, gyro in gyros.items():
            key = "" if axis is None else f"_{axis}"
            resonator = chunk[f"resonator_c{key}"][slow]
            sampled[f"resonator_c{key}"] = resonator
            sampled[f"freq_true_hz{key}"] = np.asarray(
                gyro.frequency_law.frequency_hz(resonator), dtype=np.float64)
        for name, values in sampled.items():
            track.setdefault(name, []).append(values)
        done += t.size
    columns = {name: np.concatenate(parts) for name, parts in kept.items()}
    if columns["time_s"].size < 2:
        raise InputError("the logger keeps fewer than 2 samples of this run; log longer runs")
    return KeptRun(
        columns=columns,
        run=np.concatenate(flags["run"]),
        since_on_s=np.concatenate(flags["since_on_s"]),
        burst=np.concatenate(flags["burst"]),
        track={name: np.concatenate(parts) for name, parts in track.items()},
        simulated_rows=done,
        duration_s=duration,
    )


def duplicate_rows(
    columns: dict[str, np.ndarray],
    truth: dict[str, np.ndarray],
    info: dict,
    rows: np.ndarray,
) -> None:
    """Write each of ``rows`` twice, as a logger that re-sends a line does (in place).

    The copies follow their originals; ``truth["duplicate"]`` marks them, and the row
    numbers in ``info`` (spikes, segments, restarts) move to the rows' new places.
    """
    n = len(truth["time_s"])
    rows = np.unique(np.asarray(rows, dtype=np.int64))
    take = np.sort(np.concatenate([np.arange(n), rows]))
    shifted = np.arange(n) + np.searchsorted(rows, np.arange(n), side="left")
    for table in (columns, truth):
        for name in list(table):
            table[name] = table[name][take]
    duplicate = np.zeros(take.size, dtype=bool)
    duplicate[1:] = take[1:] == take[:-1]
    truth["duplicate"] = duplicate
    truth["restart"] = truth["restart"] & ~duplicate
    for spike in info.get("spikes", []):
        spike["row"] = int(shifted[spike["row"]])
    for segment in info.get("segments", []):
        last = segment["last_row"]
        segment["first_row"] = int(shifted[segment["first_row"]])
        segment["last_row"] = int(shifted[last] + (1 if last in set(rows.tolist()) else 0))
    for restart in info.get("restarts", []):
        restart["row"] = int(shifted[restart["row"]])
    info["rows"] = int(take.size)
    info["duplicates"] = [int(shifted[r]) + 1 for r in rows.tolist()]


def segment_index(r: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Segment index of each kept row (run ``r``, burst ``b``): a new one at each burst or run."""
    new = np.ones(r.size, dtype=bool)
    new[1:] = (r[1:] != r[:-1]) | (b[1:] != b[:-1])
    return np.cumsum(new) - 1


def track_derivative(track: Mapping[str, np.ndarray], name: str, time_s: np.ndarray) -> np.ndarray:
    """d(track[name])/dt at ``time_s`` (the slow track's central differences, interpolated)."""
    t = track["time_s"]
    if t.size < 2:
        return np.zeros(np.shape(time_s))
    return np.interp(time_s, t, np.gradient(track[name], t))
