"""Handling between still periods: the unit picked up, turned and put down again.

A recording of a unit at rest is rarely one still period: between them someone picks
the unit up, turns it to its next orientation and puts it down (the three-day
refrigerator recording of issue 20 went through three orientations, with handling
bursts up to 560 °/s). :func:`handling_truth` plays such a schedule on a time axis:

* **orientations**: the unit rests in orientation ``k`` (a rotation ``R_k`` from body to
  the local level frame, :func:`orientation_matrix`) between handling windows. Its
  offset there differs from orientation 0 by the change of the Earth-rate projection
  on each axis (up to ±15 °/h for a gyro turned over, what an HRG sees) plus a MEMS
  gyro's g-sensitivity times the change of gravity in the body frame;
* **handling windows**: ``handling_s`` long, each axis turned by a few half-sine rate
  pulses whose peak over the window reaches ``max_rate_dps``; the accelerometer turns
  from the old gravity direction to the new one and shakes;
* **truth**: per row the orientation index (-1 while handled), the motion mask, the
  motion rate and the orientation offset of each axis, and the accelerometer (in g).

Axes named ``x``, ``y``, ``z`` are the body axes; a single-axis unit's sensitive axis is
body ``z`` (vertical in orientation 0).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.settings.simulation import PLAIN_LOGGER as _PLAIN
from hrgtc.simulate.units import EARTH_RATE_DPH, MultiAxisUnit, Unit

__all__ = ["Handling", "HandlingRecord", "HandlingTruth", "hand_warming", "handling_truth",
           "orientation_matrix", "warm_by_hand"]

_BODY = {"x": 0, "y": 1, "z": 2}
_SECONDS_PER_HOUR = 3600.0
#: Orientation k is this rotation (axis, angle in degrees) from body to level frame.
_TURNS: tuple[tuple[int, float], ...] = (
    (0, 0.0), (0, 90.0), (1, -90.0), (0, 180.0), (0, -90.0), (1, 90.0),
)


def orientation_matrix(k: int) -> np.ndarray:
    """Rotation of orientation ``k`` (body -> level frame, x north, y east, z up).

    0 is level; 1 turned 90° about x; 2 turned -90° about y; 3 upside down; 4 and 5
    the other two faces; then the cycle repeats.

    Examples
    --------
    >>> orientation_matrix(3) @ np.array([0.0, 0.0, 1.0])
    array([ 0.,  0., -1.])
    """
    axis, degrees = _TURNS[int(k) % len(_TURNS)]
    c, s = round(math.cos(math.radians(degrees)), 15), round(math.sin(math.radians(degrees)), 15)
    i, j = [a for a in range(3) if a != axis]
    out = np.eye(3)
    out[i, i], out[i, j], out[j, i], out[j, j] = c, -s, s, c
    return out


@dataclass(frozen=True)
class Handling(records.Written):
    """A schedule of orientations with handling between them.

    Parameters
    ----------
    orientations
        Number of orientations visited, in the order of :func:`orientation_matrix`.
    handling_s
        Length of each handling window. [s]
    max_rate_dps
        Peak rotation rate of a handling window, over all axes. [°/s]
    change_times_s
        Start of each handling window (``orientations - 1`` of them), seconds from the
        start of the run; None: evenly spread. [s]
    latitude_deg
        Latitude of the lab (the Earth-rate vector). [°]
    g_sensitivity_dph_per_g
        Axis -> offset change per g along body x, y, z (a MEMS gyro); empty for none
        (an HRG: only the Earth-rate projection changes). [°/h/g]
    accel_noise_g
        White noise of the accelerometer, rms per sample. [g]
    hand_warming_c
        A hand's warmth: the sensor warms by this much over each handling window, then
        cools back with ``hand_warming_tau_s`` (:func:`hand_warming`). [°C]
    hand_warming_tau_s
        Time constant of that cooling. [s]
    """

    forbid_unknown_fields = True  # a misspelt key of a hand-written input is refused

    orientations: Annotated[int, Meta(ge=1)] = 3
    handling_s: records.Positive = 60.0
    max_rate_dps: records.Positive = _PLAIN["handling_max_dps"]
    change_times_s: tuple[float, ...] | None = None
    latitude_deg: float = 40.0
    g_sensitivity_dph_per_g: dict[str, tuple[float, float, float]] = field(
        default_factory=dict
    )
    accel_noise_g: float = 0.002
    hand_warming_c: float = _PLAIN["hand_warming_c"]
    hand_warming_tau_s: float = 600.0

    def __post_init__(self) -> None:
        if int(self.orientations) < 1:
            raise InputError(f"orientations must be >= 1, got {self.orientations!r}")
        for name in ("handling_s", "max_rate_dps"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(f"handling {name} must be finite and > 0, got {value!r}")
        if self.change_times_s is not None:
            times = tuple(float(t) for t in self.change_times_s)
            if len(times) != int(self.orientations) - 1 or list(times) != sorted(times):
                raise InputError(
                    f"change_times_s {times} must give {int(self.orientations) - 1} increasing "
                    "start times, one per change of orientation [s]"
                )
            object.__setattr__(self, "change_times_s", times)
        object.__setattr__(self, "orientations", int(self.orientations))
        object.__setattr__(self, "g_sensitivity_dph_per_g",
                           {str(a): tuple(float(v) for v in g)
                            for a, g in dict(self.g_sensitivity_dph_per_g).items()})

    def starts_s(self, duration_s: float) -> list[float]:
        """Start of each handling window in a run of ``duration_s``. [s]"""
        if self.change_times_s is not None:
            starts = list(self.change_times_s)
        else:
            n = self.orientations
            starts = [k * duration_s / n - 0.5 * self.handling_s for k in range(1, n)]
        for start in starts:
            if start < 0.0 or start + self.handling_s > duration_s:
                raise InputError(
                    f"a handling window at {start:g} s does not fit in the {duration_s:g} s run; "
                    "give fewer orientations, a shorter handling_s or a longer run"
                )
        return starts


#: The record of :class:`Handling` (nested in other records).
HandlingRecord = records.record_of(Handling)


def hand_warming(time_s: np.ndarray, handling: Handling, duration_s: float) -> np.ndarray:
    """Warming of the sensor by the hands that turn it. [°C]

    A ramp from 0 to ``hand_warming_c`` across each handling window, then an exponential
    return with ``hand_warming_tau_s``; the windows' warmings add up.

    Examples
    --------
    >>> h = Handling(orientations=2, handling_s=60.0, hand_warming_c=3.0, change_times_s=(100,))
    >>> hand_warming(np.array([0.0, 130.0, 160.0, 760.0]), h, 1000.0).round(3).tolist()
    [0.0, 1.5, 3.0, 1.104]
    """
    t = np.asarray(time_s, dtype=np.float64)
    out = np.zeros(t.shape)
    if handling.hand_warming_c == 0.0:
        return out
    for start in handling.starts_s(duration_s):
        end = start + handling.handling_s
        ramp = np.clip((t - start) / handling.handling_s, 0.0, 1.0)
        decay = np.exp(-np.clip(t - end, 0.0, None) / handling.hand_warming_tau_s)
        out += handling.hand_warming_c * ramp * decay
    return out


@dataclass(frozen=True)
class HandlingTruth:
    """What the handling did to each row (arrays of the run's length).

    Attributes
    ----------
    orientation
        Orientation index at rest, -1 inside a handling window.
    motion
        True inside a handling window.
    motion_dph
        Axis -> rotation rate of the handling. [°/h]
    offset_dph
        Axis -> offset of the orientation against orientation 0. [°/h]
    accel_g
        Specific force along body x, y, z, shape (rows, 3). [g]
    windows
        One dict per handling window: start_s, end_s, peak_dps, from, to.
    table
        One dict per orientation: index, gravity_body, offset_dph.
    """

    orientation: np.ndarray
    motion: np.ndarray
    motion_dph: dict[str, np.ndarray]
    offset_dph: dict[str, np.ndarray]
    accel_g: np.ndarray
    windows: list[dict[str, Any]]
    table: list[dict[str, Any]]


def _orientation_offsets(handling: Handling, axes: Sequence[str]) -> list[dict[str, float]]:
    """Offset of each orientation against orientation 0, per axis. [°/h]"""
    lat = math.radians(handling.latitude_deg)
    earth = EARTH_RATE_DPH * np.array([math.cos(lat), 0.0, math.sin(lat)])
    up = np.array([0.0, 0.0, 1.0])
    rotations = [orientation_matrix(k) for k in range(handling.orientations)]
    out = []
    for rotation in rotations:
        offsets = {}
        for axis in axes:
            i = _BODY[axis]
            d_earth = (rotation.T @ earth)[i] - (rotations[0].T @ earth)[i]
            gs = np.asarray(handling.g_sensitivity_dph_per_g.get(axis, (0.0, 0.0, 0.0)))
            d_gravity = rotation.T @ up - rotations[0].T @ up
            offsets[axis] = float(d_earth + gs @ d_gravity)
        out.append(offsets)
    return out


def _rate_pulses(tw: np.ndarray, start: float, end: float, max_rate_dps: float,
                 rng: np.random.Generator) -> np.ndarray:
    """The body rates of one handling window: three cosine pulses per body axis. [°/s]

    ``tw`` holds the window's sample times; the result is ``(3, tw.size)``, scaled so that
    its peak is 80 to 100 % of ``max_rate_dps``.
    """
    pulses = np.zeros((3, tw.size))
    for i in range(3):  # body axes x, y, z
        for _ in range(3):
            half = rng.uniform(0.5, 3.0)
            centre = rng.uniform(start + half, max(start + half, end - half))
            shape = np.where(np.abs(tw - centre) < half,
                             np.cos(0.5 * np.pi * (tw - centre) / half), 0.0)
            pulses[i] += rng.choice((-1.0, 1.0)) * rng.uniform(0.3, 1.0) * shape
    peak = float(np.max(np.abs(pulses))) if tw.size else 0.0
    if peak > 0.0:
        pulses *= max_rate_dps * rng.uniform(0.8, 1.0) / peak
    return pulses


def handling_truth(
    time_s: np.ndarray,
    axes: Sequence[str],
    handling: Handling,
    rng: np.random.Generator,
    duration_s: float | None = None,
) -> HandlingTruth:
    """Play a handling schedule on a run's time axis.

    Parameters
    ----------
    time_s
        The run's sample times, increasing, from 0. [s]
    axes
        Body axes of the unit's gyros (``x``, ``y``, ``z``).
    handling
        The schedule.
    rng
        Draws the rate pulses and the accelerometer noise.
    duration_s
        Length of the run (the default windows spread over it); None: the span of
        ``time_s``. [s]

    Returns
    -------
    HandlingTruth
        Per-row orientation, motion, rates, offsets and accelerometer.
    """
    unknown = [a for a in axes if a not in _BODY]
    if unknown:
        raise InputError(f"handling needs body axes x, y, z; got axis names {unknown}")
    t = np.asarray(time_s, dtype=np.float64)
    n = t.size
    duration = (float(t[-1] - t[0]) if n else 0.0) if duration_s is None else float(duration_s)
    starts = handling.starts_s(duration)
    offsets = _orientation_offsets(handling, axes)
    up = np.array([0.0, 0.0, 1.0])
    gravity = [orientation_matrix(k).T @ up for k in range(handling.orientations)]
    orientation = np.zeros(n, dtype=np.int64)
    motion = np.zeros(n, dtype=bool)
    motion_dph = {a: np.zeros(n) for a in axes}
    offset_dph = {a: np.full(n, offsets[0][a]) for a in axes}
    accel = np.tile(gravity[0], (n, 1))
    windows = []
    for k, start in enumerate(starts, start=1):
        end = start + handling.handling_s
        after = t >= end
        orientation[after] = k
        for a in axes:
            offset_dph[a][after] = offsets[k][a]
        accel[after] = gravity[k]
        inside = (t >= start) & (t < end)
        rows = np.flatnonzero(inside)
        motion[rows] = True
        orientation[rows] = -1
        tw = t[rows]
        pulses = _rate_pulses(tw, start, end, handling.max_rate_dps, rng)
        for a in axes:
            motion_dph[a][rows] = pulses[_BODY[a]] * _SECONDS_PER_HOUR
        s = np.clip((tw - start) / handling.handling_s, 0.0, 1.0)
        blend = np.outer(1.0 - s, gravity[k - 1]) + np.outer(s, gravity[k])
        blend /= np.maximum(np.linalg.norm(blend, axis=1), 1e-9)[:, None]
        accel[rows] = blend + 0.3 * pulses.T / max(1.0, float(np.max(np.abs(pulses)) or 1.0))
        windows.append({
            "start_s": float(start), "end_s": float(end),
            "peak_dps": float(np.max(np.abs(pulses))) if rows.size else 0.0,
            "from": k - 1, "to": k,
        })
    accel = accel + rng.normal(0.0, handling.accel_noise_g, size=accel.shape)
    table = [
        {"index": k, "gravity_body_g": [float(v) for v in gravity[k]], "offset_dph": offsets[k]}
        for k in range(handling.orientations)
    ]
    return HandlingTruth(orientation, motion, motion_dph, offset_dph, accel, windows, table)


def warm_by_hand(gyro: Unit | MultiAxisUnit, axes: tuple[str | None, ...], handling: Handling,
                 rec: dict[str, np.ndarray], track: dict[str, np.ndarray],
                 duration: float) -> None:
    """The sensor warmed by the handling hands (in place): resonator temperature, its thermal
    bias through the unit's bias law, the rate, and the slow track (scale factor unchanged)."""
    warming = hand_warming(rec["time_s"], handling, duration)
    warming_track = hand_warming(track["time_s"], handling, duration)
    for axis in axes:
        key = "" if axis is None else f"_{axis}"
        law = (gyro.axes[axis] if isinstance(gyro, MultiAxisUnit) else gyro).bias_law
        resonator = rec[f"resonator_c{key}"]
        change = (law.bias_dph(resonator + warming, rec["housing_c"])
                  - law.bias_dph(resonator, rec["housing_c"]))
        rec[f"resonator_c{key}"] = resonator + warming
        rec[f"bias_dph{key}"] = rec[f"bias_dph{key}"] + change
        rec[f"rate_dph{key}"] = rec[f"rate_dph{key}"] + change
        axis_unit = gyro.axes[axis] if isinstance(gyro, MultiAxisUnit) else gyro
        if f"freq_hz{key}" in rec:  # a resonator's frequency follows its temperature
            law_f = axis_unit.frequency_law.frequency_hz
            rec[f"freq_hz{key}"] = rec[f"freq_hz{key}"] + (
                np.asarray(law_f(resonator + warming)) - np.asarray(law_f(resonator)))
        track[f"resonator_c{key}"] = track[f"resonator_c{key}"] + warming_track
        track[f"freq_true_hz{key}"] = np.asarray(
            axis_unit.frequency_law.frequency_hz(track[f"resonator_c{key}"]), dtype=np.float64)
