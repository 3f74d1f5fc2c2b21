"""Thermometry: stage 2a, the resonator as a thermometer (Eq. 16-18, Tables 1-2 of [1]).

Takes soak recordings and gives each soak's settled frequency (``plateaus``,
with ``settling`` extrapolating soaks that ended early: Table 1), then the
polynomial f(T) fitted to them and its exact inverse T(f) (``thermometer``:
Eq. 18 and Table 2).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from hrgtc.thermometry.plateaus import (
    DEFAULT_HZ_PER_C,
    Plateau,
    find_plateaus,
    plateau_table,
    plateaus_from_recordings,
)
from hrgtc.thermometry.sensor import identity
from hrgtc.thermometry.settling import TransientFit, fit_transient
from hrgtc.thermometry.thermometer import Thermometer, fit

__all__ = [
    "DEFAULT_HZ_PER_C",
    "Plateau",
    "Thermometer",
    "TransientFit",
    "find_plateaus",
    "fit",
    "fit_transient",
    "identity",
    "plateau_table",
    "plateaus_from_recordings",
]
