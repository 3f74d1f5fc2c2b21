"""Field recordings of an aged simulated unit, for the in-field update's tests.

The unit is the ``paper-unit`` whose bias has aged since calibration: its offset B0 and
its slope in temperature (the c1 of :class:`hrgtc.simulate.laws.BiasLaw`) moved by
:data:`AGED_OFFSET_DPH` and :data:`AGED_SLOPE_DPH_PER_C`; its name (the serial) is kept.
"""

from __future__ import annotations

from dataclasses import replace

from hrgtc.simulate import units
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
