"""Named simulated gyros: thermal constants, frequency law, bias law and noise.

``paper-unit`` (the default) is built to look like the unit of [1]:

* frequency: Eq. (18) of [1] at full precision (the least-squares cubic through
  Table 1), plus 2 mHz rms white measurement noise per sample;
* thermal: housing 12 min, resonator 40 min behind it, so that after a 30 °C
  chamber step (chamber slewing at 2 °C/min) the resonator comes within 0.1 °C
  of the set-point after ~15,000 s, as in Section 3 of [1];
* noise: ARW 0.024 °/√h, bias instability 0.22 °/h, RRW 0.1 °/h/√h, so that a
  5 h constant-temperature run has a 10 s bias stability of ~0.57 °/h, "the
  constant temperature precision" of Section 4.2 of [1] (0.5848 °/h after
  compensation);
* bias: falls as the resonator cools (linear and quadratic in temperature) and
  with a cooling gradient, no hysteresis, so that the 5 h cool-down
  20 -> -20 °C at 1 °C/min (:func:`hrgtc.simulate.profiles.cooldown`) has a raw
  10 s bias stability of ~3 °/h (3.0143 °/h in Section 4.2 of [1]).

``unit-b`` differs in every part, so that nothing downstream is tuned to one
unit: a smaller shell (r = 13 mm, h = 0.75 mm, ~5.7 kHz) whose frequency comes
from the shell model of :mod:`hrgtc.simulate.shell` (Eq. 15 of [1]) with fused-quartz
temperature coefficients, faster thermal constants (housing 7 min, resonator
30 min: within 0.1 °C ~11,000 s after a 30 °C step), a bias rising as the
unit cools and with the opposite gradient sign, a temperature-dependent
gradient sensitivity, a small cooling/heating hysteresis (0.2 °/h, which the
polynomial model of Eq. 21 cannot represent), and lower noise.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from typing import Any

from hrgtc.errors import InputError
from hrgtc.simulate.laws import BiasLaw, FrequencyLaw, ShellFrequencyLaw, table1_frequency_law
from hrgtc.simulate.noise import GyroNoise
from hrgtc.simulate.shell import FUSED_QUARTZ, Shell
from hrgtc.simulate.thermal import ThermalNetwork

__all__ = ["DEFAULT_UNIT", "Unit", "get", "names"]

DEFAULT_UNIT = "paper-unit"


@dataclass(frozen=True)
class Unit:
    """A simulated gyro.

    Parameters
    ----------
    name
        Name (the recording's ``unit`` metadata).
    description
        One line about the unit.
    thermal
        Chamber -> housing -> resonator network.
    frequency_law
        Natural frequency of the resonator against its temperature.
    bias_law
        Thermal bias against resonator temperature and gradient.
    gyro_noise
        ARW, bias instability and RRW of the rate output.
    frequency_noise_hz
        White measurement noise of the frequency, rms per sample. [Hz]
    housing_noise_c
        White noise of the housing thermistor, rms per sample. [°C]
    """

    name: str
    description: str
    thermal: ThermalNetwork
    frequency_law: FrequencyLaw
    bias_law: BiasLaw
    gyro_noise: GyroNoise
    frequency_noise_hz: float
    housing_noise_c: float

    def __post_init__(self) -> None:
        for field in ("frequency_noise_hz", "housing_noise_c"):
            value = float(getattr(self, field))
            if not (math.isfinite(value) and value >= 0.0):
                raise InputError(f"{field} must be finite and >= 0, got {value!r}")
            object.__setattr__(self, field, value)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (the simulator's ground truth for a recording)."""
        return {
            "name": self.name,
            "description": self.description,
            "thermal": self.thermal.to_dict(),
            "frequency_law": self.frequency_law.to_dict(),
            "bias_law": self.bias_law.to_dict(),
            "gyro_noise": self.gyro_noise.to_dict(),
            "frequency_noise_hz": self.frequency_noise_hz,
            "housing_noise_c": self.housing_noise_c,
        }

    def summary(self) -> str:
        """The unit's parameters as text."""
        law = self.bias_law
        noise = self.gyro_noise
        lines = [
            f"unit {self.name}: {self.description}",
            f"  thermal: tau_housing {self.thermal.tau_housing_s:g} s, "
            f"tau_resonator {self.thermal.tau_resonator_s:g} s",
            f"  frequency law: {self.frequency_law.to_dict()}",
            f"  frequency noise {self.frequency_noise_hz:g} Hz rms/sample, "
            f"housing thermistor noise {self.housing_noise_c:g} °C rms/sample",
            f"  bias law: B0 {law.bias0_dph:g} °/h, T0 {law.reference_c:g} °C, "
            f"c1..c3 {law.temperature_dph}, gradient {law.gradient_dph_per_c:g} °/h/°C, "
            f"gradient x T {law.gradient_temperature_dph_per_c2:g} °/h/°C², "
            f"hysteresis {law.hysteresis_dph:g} °/h over {law.hysteresis_width_c:g} °C",
            f"  noise: ARW {noise.arw_deg_per_sqrt_h:g} °/√h, bias instability "
            f"{noise.bias_instability_dph:g} °/h, RRW {noise.rrw_dph_per_sqrt_h:g} °/h/√h",
        ]
        return "\n".join(lines)


def _paper_unit() -> Unit:
    return Unit(
        name="paper-unit",
        description="looks like the HRG of [1]: Eq. (18) frequency law, ~15,000 s settling, "
        "~3 °/h raw and ~0.57 °/h constant-temperature 10 s bias stability",
        thermal=ThermalNetwork(tau_housing_s=720.0, tau_resonator_s=2400.0),
        frequency_law=table1_frequency_law(),
        bias_law=BiasLaw(
            bias0_dph=-1.5,
            reference_c=20.0,
            temperature_dph=(0.15, -2.5e-3, 0.0),
            gradient_dph_per_c=0.115,
            gradient_temperature_dph_per_c2=0.0,
            hysteresis_dph=0.0,
        ),
        gyro_noise=GyroNoise(
            arw_deg_per_sqrt_h=0.024, bias_instability_dph=0.22, rrw_dph_per_sqrt_h=0.1
        ),
        frequency_noise_hz=2.0e-3,
        housing_noise_c=0.01,
    )


def _unit_b() -> Unit:
    return Unit(
        name="unit-b",
        description="a smaller shell (r 13 mm, h 0.75 mm, ~5.7 kHz, frequency from the shell "
        "model), faster thermal path, opposite gradient sign, hysteresis, lower noise",
        thermal=ThermalNetwork(tau_housing_s=420.0, tau_resonator_s=1800.0),
        frequency_law=ShellFrequencyLaw(Shell(13.0e-3, 0.75e-3, FUSED_QUARTZ)),
        bias_law=BiasLaw(
            bias0_dph=4.0,
            reference_c=25.0,
            temperature_dph=(-0.08, 2.5e-3, 2.0e-5),
            gradient_dph_per_c=-0.25,
            gradient_temperature_dph_per_c2=4.0e-3,
            # A step in the sign of dT/dt: no polynomial in (f, df/dt) of Eq. (21) can
            # represent it. At 0.6 °/h a cool-down-trained model could not reach the
            # 3x warm-up improvement on any seed tried; 0.2 °/h keeps it visible.
            hysteresis_dph=0.2,
            hysteresis_width_c=1.0,
        ),
        gyro_noise=GyroNoise(
            arw_deg_per_sqrt_h=0.012, bias_instability_dph=0.12, rrw_dph_per_sqrt_h=0.06
        ),
        frequency_noise_hz=1.0e-3,
        housing_noise_c=0.02,
    )


_FACTORIES: dict[str, Callable[[], Unit]] = {
    "paper-unit": _paper_unit,
    "unit-b": _unit_b,
}


def names() -> list[str]:
    """Names of the simulated units, the default first."""
    return list(_FACTORIES)


@cache
def get(name: str = DEFAULT_UNIT) -> Unit:
    """The named unit.

    Raises
    ------
    InputError
        For an unknown name (the message lists the names).

    Examples
    --------
    >>> get("paper-unit").thermal.tau_resonator_s
    2400.0
    """
    try:
        factory = _FACTORIES[name]
    except (KeyError, TypeError):
        raise InputError(
            f"unknown simulated unit {name!r}; choose one of {', '.join(names())}"
        ) from None
    return factory()
