"""Field recordings of an aged simulated unit, for the in-field update's tests.

The unit is the ``paper-unit`` whose bias has aged since calibration: its offset B0 and
its slope in temperature (the c1 of :class:`hrgtc.simulate.laws.BiasLaw`) moved by
:data:`AGED_OFFSET_DPH` and :data:`AGED_SLOPE_DPH_PER_C`; its name (the serial) is kept.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from hrgtc.settings.update import EARTH_RATE_DPH
from hrgtc.simulate import units
from hrgtc.simulate.handling import orientation_matrix
from hrgtc.simulate.profiles import Profile, Segment

#: How the bias aged: offset and slope. [°/h], [°/h/°C]
AGED_OFFSET_DPH = 0.8
AGED_SLOPE_DPH_PER_C = 0.015
#: The known input rate of a simulated run (the simulator's default). [°/h]
INPUT_RATE_DPH = 10.0


def aged_unit(name: str = "paper-unit", offset_dph: float = AGED_OFFSET_DPH,
              slope_dph_per_c: float = AGED_SLOPE_DPH_PER_C) -> units.Unit:
    """``name`` with its bias aged by ``offset_dph`` and ``slope_dph_per_c``."""
    unit = units.get(name)
    law = unit.bias_law
    c1, c2, c3 = law.temperature_dph
    return replace(unit, bias_law=replace(law, bias0_dph=law.bias0_dph + offset_dph,
                                          temperature_dph=(c1 + slope_dph_per_c, c2, c3)))


def field_profile(setpoints_c: tuple[float, ...] = (20.0, 5.0, -10.0, 30.0),
                  hold_h: float = 3.0) -> Profile:
    """A day in the field: the unit still at a few temperatures, each held ``hold_h``."""
    return Profile(tuple(Segment(sp, hold_h=hold_h) for sp in setpoints_c), start_c=20.0,
                   name="field", description="field: still at " + ", ".join(
                       f"{sp:g}" for sp in setpoints_c) + " C")


def ramp_profile() -> Profile:
    """A warm-up at 0.5 °C/min with no settled temperature: still, but on a ramp."""
    return Profile((Segment(-20.0, hold_h=0.25), Segment(40.0, ramp_c_per_min=0.5)),
                   start_c=-20.0, name="ramp", description="ramp -20 -> 40 C")


# -- a triad (imu-3) whose offsets aged, at rest in several orientations -------------

#: How each axis's offset aged since calibration. [°/h]
AGED_DPH = {"x": 0.9, "y": -0.7, "z": 0.6}
#: Hours in each orientation, and the handling left out at each change. [h], [s]
HOLD_H, HANDLING_S = 3.0, 300.0
LATITUDE_DEG = 40.0


def aged_triad():
    """``imu-3`` with each axis's offset moved by :data:`AGED_DPH`."""
    imu = units.get("imu-3")
    return replace(imu, axes={name: replace(unit, bias_law=replace(
        unit.bias_law, bias0_dph=unit.bias_law.bias0_dph + AGED_DPH[name]))
        for name, unit in imu.axes.items()})


def at_rest_in(orientations, seed=3):
    """The aged triad at 20 °C, still in each of ``orientations``
    (:func:`hrgtc.simulate.handling.orientation_matrix`) for :data:`HOLD_H`: each axis's
    rate holds that orientation's Earth-rate projection (x north, y east, z up at 40° N in
    orientation 0, the simulator's); and the still intervals, the handling left out. The
    metadata's input rates are dropped: the update does not know them."""
    from hrgtc.simulate import simulate_run

    hours = HOLD_H * len(orientations)
    run = simulate_run(Profile((Segment(20.0, hold_h=hours),), start_c=20.0, name="field",
                               description="still at 20 C"),
                       aged_triad(), sample_rate_hz=1.0, seed=seed)
    lat = math.radians(LATITUDE_DEG)
    level = EARTH_RATE_DPH * np.array([math.cos(lat), 0.0, math.sin(lat)])
    t = run.time_s
    columns, still = {}, []
    for k, orientation in enumerate(orientations):
        inside = (t >= k * HOLD_H * 3600.0) & (t < (k + 1) * HOLD_H * 3600.0)
        body = orientation_matrix(orientation).T @ level
        for i, axis in enumerate("xyz"):
            column = columns.setdefault(axis, run[f"rate_dph_{axis}"].copy())
            column[inside] += body[i] - level[i]
        still.append((k * HOLD_H * 3600.0 + HANDLING_S, (k + 1) * HOLD_H * 3600.0 - HANDLING_S))
    extra = {k: v for k, v in run.metadata.extra.items() if k != "axis_input_rate_dph"}
    moved = run.with_columns(**{f"rate_dph_{a}": v for a, v in columns.items()})
    moved.metadata = replace(run.metadata, extra=extra)
    return moved, still


def target_offsets(model, recording, still):
    """What the data call for: each intercept plus the mean of (true bias - the model's
    bias) over the still intervals. [°/h]"""
    from hrgtc.recording import axis_view

    out = {}
    for axis, part in model.axes.items():
        view = axis_view(recording, axis)
        gap = view["bias_dph"] - part.drift.predict_recording(view, part.thermometer)
        inside = np.zeros(len(view), dtype=bool)
        for start, end in still:
            inside |= (view.time_s >= start) & (view.time_s <= end)
        out[axis] = part.drift.intercept_dph + float(gap[inside].mean())
    return out
