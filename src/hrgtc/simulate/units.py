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
polynomial model of Eq. 21 cannot represent), and lower noise. That term is
``h tanh(G/G_h)`` of the gradient: no memory, a lag that saturates
(:mod:`hrgtc.simulate.history` tells the two apart; docs/history.md).

``unit-play`` is ``unit-b`` with a true thermal memory in the place of its tanh term: a
play (backlash) operator of width 2 °C on the resonator temperature
(the play of :class:`~hrgtc.simulate.laws.BiasLaw`, slope 0.4 °/h/°C), so that a soak settled after
coming down reads 0.8 °/h above one settled after coming up, at any ramp rate.

Neither has a scale-factor law (``scale_factor_law`` None: ``rate = input +
bias + noise``, as before the law existed).

``imu-3`` is a three-axis unit (:class:`MultiAxisUnit`, axes ``x``, ``y``,
``z``): three resonators of different shells (the Eq. 18 law of [1] at
~4.4 kHz, and shells of ~5.7 kHz and ~8.5 kHz from the shell model of Eq. 15),
each with its own bias law, scale-factor law (several hundred ppm over
-20...60 °C) and resonator lag behind the one housing they share (2000, 2700
and 3400 s: during a 1 °C/min ramp the resonators differ by several degrees), and
the Earth-rate components of a unit mounted level at 40° N with ``x`` north,
``y`` east and ``z`` up. Each axis is a :class:`Unit` itself
(``get("imu-3").axes["x"]`` simulates that axis alone).

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Annotated, Any

from msgspec import Meta

import hrgtc.settings.simulation as _settings
from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.simulate.laws import (
    BiasLaw,
    PolynomialFrequencyLaw,
    ScaleFactorLaw,
    ShellFrequencyLaw,
    table1_frequency_law,
)
from hrgtc.simulate.noise_sources import GyroNoise
from hrgtc.simulate.profiles import AXIS_NAME
from hrgtc.simulate.shell import FUSED_QUARTZ, Shell
from hrgtc.simulate.thermal import ThermalNetwork

__all__ = [
    "AXIS_NAME",
    "DEFAULT_UNIT",
    "EARTH_RATE_DPH",
    "MultiAxisUnit",
    "MultiAxisUnitRecord",
    "Unit",
    "UnitRecord",
    "get",
    "names",
    "unit_from_dict",
]

DEFAULT_UNIT = _settings.DEFAULT_UNIT
#: Earth's rotation rate, 360° per sidereal day (23.9345 h). [°/h]
EARTH_RATE_DPH = 360.0 / 23.9344696


@dataclass(frozen=True)
class Unit(records.Written):
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
    scale_factor_law
        Scale-factor error against resonator temperature; None for none
        (``rate = input + bias + noise``).
    """

    #: Its record (:data:`UnitRecord`, a recording's ``unit_parameters``); the frequency
    #: law is told by its ``kind`` (:data:`~hrgtc.simulate.laws.FrequencyLawRecord`).
    omit_when_default = ("scale_factor_law",)

    name: str
    description: str
    thermal: ThermalNetwork
    frequency_law: PolynomialFrequencyLaw | ShellFrequencyLaw
    bias_law: BiasLaw
    gyro_noise: GyroNoise
    frequency_noise_hz: records.NonNegative
    housing_noise_c: records.NonNegative
    scale_factor_law: ScaleFactorLaw | None = None

    def __post_init__(self) -> None:
        for attribute in ("frequency_noise_hz", "housing_noise_c"):
            value = float(getattr(self, attribute))
            if not (math.isfinite(value) and value >= 0.0):
                raise InputError(f"{attribute} must be finite and >= 0, got {value!r}")
            object.__setattr__(self, attribute, value)

    def summary(self) -> Summary:
        """The unit's parameters (thermal time constants, noise, bias and scale-factor
        laws); its text the description ``hrgtc simulate --list`` prints."""
        law = self.bias_law
        noise = self.gyro_noise
        figures = (
            Figure("thermal.tau_housing_s", "housing time constant",
                   self.thermal.tau_housing_s, "s"),
            Figure("thermal.tau_resonator_s", "resonator time constant",
                   self.thermal.tau_resonator_s, "s"),
            Figure("frequency_noise_hz", "frequency noise", self.frequency_noise_hz, "Hz",
                   definition="RMS frequency noise per sample."),
            Figure("housing_noise_c", "housing thermistor noise", self.housing_noise_c, "°C",
                   definition="RMS housing thermistor noise per sample."),
            Figure("bias_law.bias0_dph", "B0", law.bias0_dph, "°/h",
                   definition="True bias at the reference temperature."),
            Figure("bias_law.reference_c", "T0", law.reference_c, "°C"),
            Figure("bias_law.gradient_dph_per_c", "gradient", law.gradient_dph_per_c,
                   "°/h/°C", definition="Bias per °C of housing minus resonator temperature."),
            Figure("bias_law.gradient_temperature_dph_per_c2", "gradient x T",
                   law.gradient_temperature_dph_per_c2, "°/h/°C²"),
            Figure("bias_law.hysteresis_dph", "hysteresis", law.hysteresis_dph, "°/h"),
            Figure("bias_law.hysteresis_width_c", "hysteresis width", law.hysteresis_width_c,
                   "°C"),
            Figure("gyro_noise.arw_deg_per_sqrt_h", "ARW", noise.arw_deg_per_sqrt_h, "°/√h",
                   definition="Angle random walk of the simulated rate."),
            Figure("gyro_noise.bias_instability_dph", "bias instability",
                   noise.bias_instability_dph, "°/h"),
            Figure("gyro_noise.rrw_dph_per_sqrt_h", "RRW", noise.rrw_dph_per_sqrt_h, "°/h/√h",
                   definition="Rate random walk of the simulated rate."))
        layout = [
            escape(f"unit {self.name}: {self.description}"),
            "  thermal: tau_housing {thermal.tau_housing_s:g} s, "
            "tau_resonator {thermal.tau_resonator_s:g} s",
            escape(f"  frequency law: {self.frequency_law.to_dict()}"),
            "  frequency noise {frequency_noise_hz:g} Hz rms/sample, "
            "housing thermistor noise {housing_noise_c:g} °C rms/sample",
            "  bias law: B0 {bias_law.bias0_dph:g} °/h, T0 {bias_law.reference_c:g} °C, "
            + escape(f"c1..c3 {law.temperature_dph}")
            + ", gradient {bias_law.gradient_dph_per_c:g} °/h/°C, "
            "gradient x T {bias_law.gradient_temperature_dph_per_c2:g} °/h/°C², "
            "hysteresis {bias_law.hysteresis_dph:g} °/h over {bias_law.hysteresis_width_c:g} °C",
            "  noise: ARW {gyro_noise.arw_deg_per_sqrt_h:g} °/√h, bias instability "
            "{gyro_noise.bias_instability_dph:g} °/h, RRW {gyro_noise.rrw_dph_per_sqrt_h:g} "
            "°/h/√h",
        ]
        if self.scale_factor_law is not None:
            sf = self.scale_factor_law
            figures += (Figure("scale_factor_law.reference_c", "scale factor T0",
                               sf.reference_c, "°C"),)
            layout.append(escape(f"  scale factor: k0..kn {sf.coefficients_ppm} ppm/°C^j about ")
                          + "T0 {scale_factor_law.reference_c:g} °C")
        if law.has_play:
            figures += (
                Figure("bias_law.play_dph_per_c", "play slope", law.play_dph_per_c, "°/h/°C",
                       definition="Bias per °C of the play state minus the resonator "
                       "temperature."),
                Figure("bias_law.play_width_c", "play width", law.play_width_c, "°C"),
                Figure("bias_law.play_initial_offset_c", "play state at power-on",
                       law.play_initial_offset_c, "°C"))
            layout.append("  play memory: {bias_law.play_dph_per_c:g} °/h/°C × (p - T_r), "
                          "width {bias_law.play_width_c:g} °C, p - T_r at power-on "
                          "{bias_law.play_initial_offset_c:g} °C")
        return Summary(f"unit {self.name}", (("parameters", figures),), layout=tuple(layout))


@dataclass(frozen=True)
class MultiAxisUnit(records.Written):
    """A unit of several gyros (axes) sharing one housing in the chamber.

    Parameters
    ----------
    name
        Name (the recording's ``unit`` metadata).
    description
        One line about the unit.
    axes
        Axis name -> the gyro on that axis, in column order. Each axis has its own
        resonator (frequency, bias and scale-factor laws, noise and resonator lag);
        all share the housing, so their thermal networks must have the same
        ``tau_housing_s``.
    input_rate_dph
        Axis name -> constant rate on that axis, e.g. its Earth-rate component. [°/h]
    housing_noise_c
        White noise of the one housing thermistor, rms per sample. [°C]
    """

    name: str
    description: str
    axes: Annotated[dict[str, Unit], Meta(min_length=1)]
    input_rate_dph: dict[str, float] = field(default_factory=dict)
    housing_noise_c: records.NonNegative = 0.01

    def __post_init__(self) -> None:
        axes = dict(self.axes)
        if not axes:
            raise InputError(f"unit {self.name!r}: a multi-axis unit needs at least one axis")
        for axis, gyro in axes.items():
            if not (isinstance(axis, str) and AXIS_NAME.fullmatch(axis)):
                raise InputError(
                    f"unit {self.name!r}: axis name {axis!r} must be a letter then letters or "
                    "digits (no underscore), e.g. x, y, z"
                )
            if not isinstance(gyro, Unit):
                raise InputError(f"unit {self.name!r}: axis {axis} must be a Unit")
        housing = {gyro.thermal.tau_housing_s for gyro in axes.values()}
        if len(housing) != 1:
            raise InputError(
                f"unit {self.name!r}: the axes share one housing but have tau_housing_s "
                f"{sorted(housing)} s; give them the same"
            )
        rates = {str(k): float(v) for k, v in dict(self.input_rate_dph).items()}
        if set(rates) - set(axes) or not all(math.isfinite(v) for v in rates.values()):
            raise InputError(
                f"unit {self.name!r}: input_rate_dph {rates} must be finite rates of axes "
                f"{list(axes)}"
            )
        noise = float(self.housing_noise_c)
        if not (math.isfinite(noise) and noise >= 0.0):
            raise InputError(f"housing_noise_c must be finite and >= 0, got {noise!r}")
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "input_rate_dph", {a: rates.get(a, 0.0) for a in axes})
        object.__setattr__(self, "housing_noise_c", noise)

    @property
    def axis_names(self) -> tuple[str, ...]:
        """The axes, in column order."""
        return tuple(self.axes)

    @property
    def thermal(self) -> ThermalNetwork:
        """The first axis's network (its housing is every axis's housing)."""
        return next(iter(self.axes.values())).thermal

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MultiAxisUnit:
        """Inverse of :meth:`to_dict` (checked against :class:`MultiAxisUnitRecord`; an
        axis's refusal names the axis, which msgspec's place ``$.axes[...]`` does not)."""
        axes = data.get("axes") if isinstance(data, Mapping) else None
        for axis, gyro in (axes.items() if isinstance(axes, Mapping) else ()):
            records.load(gyro, Unit, f"simulated unit's axis {axis!r}")
        return records.load(data, cls, "simulated multi-axis unit")  # type: ignore[no-any-return]

    def summary(self) -> Summary:
        """Each axis's parameters (:meth:`Unit.summary`, after ``axes.<axis>.``) and input
        rate; its text axis by axis."""
        sections: list[tuple[str, tuple[Figure, ...]]] = []
        layout = [escape(f"unit {self.name}: {self.description}")]
        for axis, gyro in self.axes.items():
            key = f"axes.{axis}."
            inner = gyro.summary().renamed(key)
            rate = Figure(f"{key}input_rate_dph", "input rate", self.input_rate_dph[axis], "°/h")
            sections += [(f"axis {axis}", (rate, *inner.sections[0][1]))]
            layout.append(f"axis {escape(axis)} (input {{{key}input_rate_dph:g}} °/h):")
            layout += inner.lines("  ")
        return Summary(f"unit {self.name}", tuple(sections), layout=tuple(layout))


#: The record of :class:`Unit`, generated from its fields.
UnitRecord = records.record_of(
    Unit, doc="A :class:`Unit` in the simulator's ground truth (a recording's "
    "``unit_parameters``).")
#: The record of :class:`MultiAxisUnit`, generated from its fields.
MultiAxisUnitRecord = records.record_of(
    MultiAxisUnit, doc="A :class:`MultiAxisUnit` in the simulator's ground truth.")


def unit_from_dict(data: Mapping[str, Any]) -> Unit | MultiAxisUnit:
    """A :class:`Unit` or :class:`MultiAxisUnit` from its ``to_dict`` form."""
    return MultiAxisUnit.from_dict(data) if "axes" in data else Unit.from_dict(data)


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


def _unit_play() -> Unit:
    """unit-b with a true play-type memory (the play of its :class:`BiasLaw`) instead of
    its tanh term."""
    base = _unit_b()
    return replace(
        base, name="unit-play",
        description="unit-b with a true thermal memory: a play operator of width 2 °C on the "
        "resonator temperature (0.8 °/h between coming down and coming up), no tanh term",
        bias_law=replace(base.bias_law, hysteresis_dph=0.0, play_dph_per_c=0.4,
                         play_width_c=2.0),
    )


def _imu3() -> MultiAxisUnit:
    housing_s = 600.0
    latitude = math.radians(40.0)
    x = Unit(
        name="imu-3:x",
        description="Eq. (18) frequency law of [1] (~4.4 kHz), fastest resonator",
        thermal=ThermalNetwork(tau_housing_s=housing_s, tau_resonator_s=2000.0),
        frequency_law=table1_frequency_law(),
        bias_law=BiasLaw(-1.2, 20.0, (0.12, -2.0e-3, 0.0), gradient_dph_per_c=0.10),
        gyro_noise=GyroNoise(0.02, 0.2, 0.08),
        frequency_noise_hz=2.0e-3,
        housing_noise_c=0.01,
        scale_factor_law=ScaleFactorLaw((150.0, 6.0, 0.02), reference_c=20.0),
    )
    y = Unit(
        name="imu-3:y",
        description="shell r 13 mm, h 0.75 mm (~5.7 kHz, shell model)",
        thermal=ThermalNetwork(tau_housing_s=housing_s, tau_resonator_s=2700.0),
        frequency_law=ShellFrequencyLaw(Shell(13.0e-3, 0.75e-3, FUSED_QUARTZ)),
        bias_law=BiasLaw(2.5, 25.0, (-0.09, 1.5e-3, 1.0e-5), gradient_dph_per_c=-0.18,
                         gradient_temperature_dph_per_c2=2.0e-3),
        gyro_noise=GyroNoise(0.015, 0.15, 0.06),
        frequency_noise_hz=1.5e-3,
        housing_noise_c=0.01,
        scale_factor_law=ScaleFactorLaw((-80.0, -4.5, 0.035, 2.0e-4), reference_c=25.0),
    )
    z = Unit(
        name="imu-3:z",
        description="shell r 11 mm, h 0.8 mm (~8.5 kHz, shell model), slowest resonator",
        thermal=ThermalNetwork(tau_housing_s=housing_s, tau_resonator_s=3400.0),
        frequency_law=ShellFrequencyLaw(Shell(11.0e-3, 0.8e-3, FUSED_QUARTZ)),
        bias_law=BiasLaw(0.6, 20.0, (0.2, 1.0e-3, -1.5e-5), gradient_dph_per_c=0.22),
        gyro_noise=GyroNoise(0.025, 0.25, 0.1),
        frequency_noise_hz=3.0e-3,
        housing_noise_c=0.01,
        scale_factor_law=ScaleFactorLaw((40.0, 7.5, -0.03), reference_c=20.0),
    )
    return MultiAxisUnit(
        name="imu-3",
        description="three resonators (x ~4.4 kHz, y ~5.7 kHz, z ~8.5 kHz) in one housing, "
        "each with its own bias, scale factor and lag; level at 40° N, x north, z up",
        axes={"x": x, "y": y, "z": z},
        input_rate_dph={
            "x": EARTH_RATE_DPH * math.cos(latitude),
            "y": 0.0,
            "z": EARTH_RATE_DPH * math.sin(latitude),
        },
        housing_noise_c=0.01,
    )


_FACTORIES: dict[str, Callable[[], Unit | MultiAxisUnit]] = {
    "paper-unit": _paper_unit,
    "unit-b": _unit_b,
    "unit-play": _unit_play,
    "imu-3": _imu3,
    # "mems-3" is registered by hrgtc.simulate.mems (imported by the package), which builds on
    # this module's types: importing it from here would close an import circle.
}


def register(name: str, factory: Callable[[], Unit | MultiAxisUnit]) -> None:
    """Add a named unit that another module of the package builds (``mems-3``)."""
    if _FACTORIES.get(name, factory) is not factory:
        raise InputError(f"a simulated unit named {name!r} is already registered")
    _FACTORIES[name] = factory


def names() -> list[str]:
    """Names of the simulated units, the default first."""
    return list(_FACTORIES)


@cache
def get(name: str = DEFAULT_UNIT) -> Unit | MultiAxisUnit:
    """The named unit (a :class:`MultiAxisUnit` for ``imu-3`` and ``mems-3``).

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
