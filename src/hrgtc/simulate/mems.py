"""A simulated three-axis MEMS gyro: large offsets, a die temperature sensor, g-sensitivity.

``mems-3`` is the kind of unit the real recordings of issue 20 come from (a CubeSat's
3-axis MEMS gyro in a cold test, an IMU left three days in a refrigerator). It has no
resonator frequency: a logger (:mod:`hrgtc.simulate.logger`) writes its die
temperature sensor instead, and ``resonator_c`` of the simulator is that die
temperature (every axis shares the one die: the three axes have the same thermal
network). Its parameters, chosen from the PAN cold test in ``tests/data/pan-cold-test``:

* offsets of several °/s at rest (x -3.9, y +3.4, z +1.65 °/s, as the PAN unit's
  -0.069, +0.059, +0.029 rad/s);
* temperature coefficients as the PAN unit's: while it cooled by 12.7 °C its burst means
  moved by -0.0086 (x), +0.0040 (y) and -0.0004 rad/s (z), i.e. +140, -65 and +7 °/h/°C;
  a small curvature, and a sensitivity to the housing - die gradient (a df/dt-like term);
* noise: ARW 0.26 °/√h (0.0043 °/s/√Hz), so that a 50 Hz sample scatters by 0.00053 rad/s
  rms as the PAN unit's do within a burst; bias instability 10 °/h, rate random walk
  3 °/h/√h;
* g-sensitivity (:data:`G_SENSITIVITY_DPH_PER_G`): each axis's offset moves by a few
  hundred °/h per g of gravity along the body axes, so turning the unit over changes
  its offsets (the orientation offsets of :mod:`hrgtc.simulate.handling`).

Its ``frequency_law`` is a placeholder the unit type requires (the Eq. 18 law of [1]);
a logger never writes a frequency for a MEMS unit.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math

from hrgtc.simulate.laws import BiasLaw, table1_frequency_law
from hrgtc.simulate.noise_sources import GyroNoise
from hrgtc.simulate.thermal import ThermalNetwork
from hrgtc.simulate.units import EARTH_RATE_DPH, MultiAxisUnit, Unit, register

__all__ = ["G_SENSITIVITY_DPH_PER_G", "LATITUDE_DEG", "MEMS_UNIT", "mems3"]

MEMS_UNIT = "mems-3"
#: Latitude of the simulated lab (the Earth-rate components of a level unit). [°]
LATITUDE_DEG = 40.0
#: Offset change of each axis per g of gravity along body x, y, z. [°/h/g]
#: Typical MEMS gyros list 0.05-0.2 °/s/g (180-720 °/h/g).
G_SENSITIVITY_DPH_PER_G: dict[str, tuple[float, float, float]] = {
    "x": (360.0, -90.0, 150.0),
    "y": (60.0, 300.0, -120.0),
    "z": (-100.0, 80.0, 250.0),
}
_SECONDS_PER_HOUR = 3600.0


def mems3() -> MultiAxisUnit:
    """The three-axis MEMS gyro ``mems-3`` (one die, level at 40° N, x north, z up)."""
    # One die: the same thermal network on every axis (resonator_c is the die temperature).
    thermal = ThermalNetwork(tau_housing_s=1500.0, tau_resonator_s=300.0)
    laws = {
        "x": BiasLaw(-3.9 * _SECONDS_PER_HOUR, 20.0, (140.0, 1.5, 0.0), gradient_dph_per_c=25.0),
        "y": BiasLaw(3.4 * _SECONDS_PER_HOUR, 20.0, (-65.0, -0.8, 0.0), gradient_dph_per_c=-15.0),
        "z": BiasLaw(1.65 * _SECONDS_PER_HOUR, 20.0, (7.0, 0.6, 0.0), gradient_dph_per_c=10.0),
    }
    axes = {
        axis: Unit(
            name=f"{MEMS_UNIT}:{axis}",
            description="MEMS rate gyro axis (no frequency output; die temperature sensor)",
            thermal=thermal,
            frequency_law=table1_frequency_law(),
            bias_law=law,
            gyro_noise=GyroNoise(0.26, 10.0, 3.0),
            frequency_noise_hz=0.0,
            housing_noise_c=0.05,
        )
        for axis, law in laws.items()
    }
    latitude = math.radians(LATITUDE_DEG)
    return MultiAxisUnit(
        name=MEMS_UNIT,
        description="three-axis MEMS gyro: offsets of several °/s, up to 140 °/h/°C, "
        "g-sensitivity, a die temperature sensor and no frequency output",
        axes=axes,
        input_rate_dph={
            "x": EARTH_RATE_DPH * math.cos(latitude),
            "y": 0.0,
            "z": EARTH_RATE_DPH * math.sin(latitude),
        },
        housing_noise_c=0.05,
    )


register(MEMS_UNIT, mems3)  # units.get('mems-3'); the package imports this module
