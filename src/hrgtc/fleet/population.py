"""A simulated production population: units that differ the way real ones of one design do.

Each unit is :func:`hrgtc.simulate.units.get` ``("paper-unit")`` with every part
drawn around it. The spread (1 sigma, :data:`SPREAD`) and where each number
comes from:

* **f at 20 °C**: 4432.07 Hz (Table 1 of [1]) ± 18 Hz (0.4 %). Eq. (13)-(15) of
  [1]: f ∝ (h / R²) sqrt(E / ρ(1+μ)), so a 0.3 % tolerance on the shell thickness
  (± 2.5 µm on ~0.8 mm, a figure of a good lapping process; our assumption) and
  0.1 % on the mean radius give ~0.4 %: tens of Hz, as the issue states;
* **relative temperature coefficient** (the law f/f20 - 1 of Eq. 18 of [1]):
  scaled as a whole by 1 ± 3 %, the temperature coefficient of Young's modulus
  of fused quartz varying between melts (OH content, annealing) by a few %
  (the issue's figure; we know of no published spread, so this is an assumption),
  plus an independent ± 1 % on the quadratic and ± 2 % on the cubic term: the
  curvature comes from the same material law, so most of it moves with the
  linear term. The independent part is what two or three soaks cannot see; the
  2/3-soak errors of the prior (bench/bench_prior.py) scale with it;
* **thermal constants**: housing 720 s and resonator 2400 s (``paper-unit``,
  from the ~15,000 s settling of Section 3 of [1]) each × lognormal(10 %):
  mounting, getter and vacuum differ from unit to unit;
* **bias law**: B0 -1.5 ± 1.0 °/h (turn-on bias of tactical HRGs is of the order
  of 1 °/h), each temperature and gradient coefficient × (1 ± 20 %);
* **noise**: ARW, bias instability, RRW and frequency noise each × lognormal(20 %).

Each unit's draw is seeded by ``SeedSequence(seed, spawn_key=(k,))``, so unit k
is the same whatever the size of the fleet.

An **instrument** of the population (:func:`draw_instrument`, ``hrgtc fleet simulate
--axes 3``) holds one resonator per axis (x, y, z), each drawn as a unit is (axis j
of instrument k from ``SeedSequence(seed, spawn_key=(k, j))``) around the same design,
all in one housing: the first axis's drawn housing time constant is every axis's,
their resonator constants their own. The axes sense no rate but their bias.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any, Literal

import numpy as np
from numpy.polynomial import Polynomial

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.simulate import units as simulated_units
from hrgtc.simulate.laws import BiasLaw, PolynomialFrequencyLaw, table1_frequency_law
from hrgtc.simulate.noise_sources import GyroNoise
from hrgtc.simulate.thermal import ThermalNetwork
from hrgtc.simulate.units import MultiAxisUnit, Unit, UnitRecord

__all__ = ["AXES", "SPREAD", "DrawRecord", "FleetTruthRecord", "draw_instrument", "draw_unit",
           "draw_units", "relative_law"]

#: 1-sigma unit-to-unit spread (module docstring for the sources).
SPREAD: dict[str, float] = {
    "f20_hz": 18.0,
    "tc_scale": 0.03,
    "tc_quadratic": 0.01,
    "tc_cubic": 0.02,
    "thermal_log": 0.10,
    "bias0_dph": 1.0,
    "bias_coefficients": 0.20,
    "noise_log": 0.20,
}
#: f at 20 °C of the unit of [1] (Table 1). [Hz]
F20_HZ = 4432.07
REFERENCE_C = 20.0
#: The axes of a simulated instrument, in column order.
AXES = ("x", "y", "z")


def relative_law() -> np.ndarray:
    """(r1, r2, r3) of f/f(20 °C) = 1 + r1 x + r2 x² + r3 x³, x = T - 20 °C (Eq. 18 of [1])."""
    law = Polynomial(table1_frequency_law().coefficients)
    shifted = law(Polynomial([REFERENCE_C, 1.0])).coef
    return shifted[1:] / shifted[0]


def draw_unit(seed: int, k: int, spread: dict[str, float] | None = None) -> tuple[Unit, dict]:
    """Unit ``k`` of the population of ``seed``: ``(unit, draw)``, the draw in plain JSON."""
    if not isinstance(seed, int) or seed < 0 or not isinstance(k, int) or k < 0:
        raise InputError(f"seed and unit index must be non-negative integers, got {seed}, {k}")
    return _draw(seed, k, (k,), f"s{seed}-u{k:04d}",
                 f"unit {k} of the simulated population of seed {seed}", spread)


def draw_instrument(seed: int, k: int, n_axes: int = len(AXES),
                    spread: dict[str, float] | None = None) -> tuple[MultiAxisUnit,
                                                                     dict[str, dict]]:
    """Instrument ``k`` of the population of ``seed`` (module docstring): ``(instrument,
    draws)``, each axis's draw in plain JSON by axis."""
    if not isinstance(seed, int) or seed < 0 or not isinstance(k, int) or k < 0:
        raise InputError(f"seed and unit index must be non-negative integers, got {seed}, {k}")
    if not isinstance(n_axes, int) or not 1 <= n_axes <= len(AXES):
        raise InputError(f"an instrument has 1 to {len(AXES)} axes, got {n_axes!r}")
    name = f"s{seed}-u{k:04d}"
    drawn = {axis: _draw(seed, k, (k, j), f"{name}:{axis}",
                         f"axis {axis} of instrument {k} of the simulated population of seed "
                         f"{seed}", spread)
             for j, axis in enumerate(AXES[:n_axes])}
    housing_s = drawn[AXES[0]][0].thermal.tau_housing_s  # one housing for every axis
    axes = {axis: replace(unit, thermal=replace(unit.thermal, tau_housing_s=housing_s))
            for axis, (unit, _) in drawn.items()}
    instrument = MultiAxisUnit(
        name=name, description=f"instrument {k} of the simulated population of seed {seed}: "
        f"{n_axes} drawn resonators in one housing", axes=axes,
        housing_noise_c=axes[AXES[0]].housing_noise_c)
    return instrument, {axis: draw for axis, (_, draw) in drawn.items()}


def _draw(seed: int, k: int, key: tuple[int, ...], name: str, description: str,
          spread: dict[str, float] | None) -> tuple[Unit, dict]:
    """A unit drawn from ``SeedSequence(seed, spawn_key=key)`` (index ``k`` in its draw)."""
    s = {**SPREAD, **(spread or {})}
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))
    base = simulated_units.get("paper-unit")
    f20 = F20_HZ + s["f20_hz"] * rng.standard_normal()
    scale = 1.0 + s["tc_scale"] * rng.standard_normal()
    quad = 1.0 + s["tc_quadratic"] * rng.standard_normal()
    cubic = 1.0 + s["tc_cubic"] * rng.standard_normal()
    r1, r2, r3 = relative_law()
    relative = np.array([1.0, scale * r1, scale * r2 * quad, scale * r3 * cubic])
    # f(T) = f20 (1 + r(T - 20)): to ascending powers of T.
    coefficients = f20 * Polynomial(relative)(Polynomial([-REFERENCE_C, 1.0])).coef
    thermal = ThermalNetwork(
        tau_housing_s=base.thermal.tau_housing_s * float(np.exp(s["thermal_log"]
                                                              * rng.standard_normal())),
        tau_resonator_s=base.thermal.tau_resonator_s * float(np.exp(s["thermal_log"]
                                                                  * rng.standard_normal())))
    law = base.bias_law

    def vary(value: float) -> float:
        return float(value * (1.0 + s["bias_coefficients"] * rng.standard_normal()))

    bias = BiasLaw(
        bias0_dph=float(law.bias0_dph + s["bias0_dph"] * rng.standard_normal()),
        reference_c=law.reference_c,
        temperature_dph=tuple(vary(c) for c in law.temperature_dph),
        gradient_dph_per_c=vary(law.gradient_dph_per_c),
        gradient_temperature_dph_per_c2=law.gradient_temperature_dph_per_c2,
        hysteresis_dph=law.hysteresis_dph,
    )
    noise = base.gyro_noise

    def lognormal() -> float:
        return float(np.exp(s["noise_log"] * rng.standard_normal()))

    gyro_noise = GyroNoise(arw_deg_per_sqrt_h=noise.arw_deg_per_sqrt_h * lognormal(),
                           bias_instability_dph=noise.bias_instability_dph * lognormal(),
                           rrw_dph_per_sqrt_h=noise.rrw_dph_per_sqrt_h * lognormal())
    unit = replace(
        base, name=name, description=description, thermal=thermal,
        frequency_law=PolynomialFrequencyLaw(
            tuple(float(c) for c in coefficients),
            source=f"population draw around Eq. (18) of [1] (seed {seed}, unit {k})"),
        bias_law=bias, gyro_noise=gyro_noise,
        frequency_noise_hz=base.frequency_noise_hz * lognormal(),
    )
    draw: dict[str, Any] = {"seed": seed, "index": k, "f20_hz": float(f20),
                            "tc_scale": float(scale), "tc_quadratic": float(quad),
                            "tc_cubic": float(cubic),
                            "relative_law_x_minus_20": [float(v) for v in relative[1:]],
                            "spread": s}
    return unit, draw


def draw_units(n: int, seed: int, first: int = 0,
               spread: dict[str, float] | None = None) -> list[tuple[Unit, dict]]:
    """Units ``first .. first + n - 1`` of the population of ``seed``."""
    if not isinstance(n, int) or n < 1:
        raise InputError(f"the number of units must be a positive integer, got {n!r}")
    return [draw_unit(seed, k, spread) for k in range(first, first + n)]


class DrawRecord(records.Record, kw_only=True):
    """How a population unit was drawn (:func:`draw_unit`): its seed and index, the drawn
    f(20 °C) and temperature-coefficient scales, the relative law and the spreads."""

    seed: int
    index: records.Count
    f20_hz: records.Positive
    tc_scale: float
    tc_quadratic: float
    tc_cubic: float
    relative_law_x_minus_20: list[float]
    spread: dict[str, float]


class FleetTruthRecord(records.Record, kw_only=True):
    """A population unit's ``truth.json``: the unit (:class:`UnitRecord`) and its draw."""

    schema: Literal["hrgtc.fleet-truth"] = "hrgtc.fleet-truth"
    unit: UnitRecord
    draw: DrawRecord


def truth(unit: Unit, draw: dict) -> dict[str, Any]:
    """The unit's ground truth as written beside its files (``truth.json``), as
    :class:`FleetTruthRecord` writes it."""
    return records.dump(unit, FleetTruthRecord, unit=unit.to_dict(), draw=draw)


def true_frequency_hz(truth_record: dict[str, Any], temperature_c: Any) -> np.ndarray:
    """The true f(T) of a unit from its ``truth.json`` record (checked against
    :class:`FleetTruthRecord`). [Hz]"""
    records.load(truth_record, FleetTruthRecord, "fleet truth")
    law = truth_record["unit"]["frequency_law"]
    if law.get("kind") != "polynomial":
        raise InputError("truth record without a polynomial frequency law")
    return Polynomial(law["coefficients"])(np.asarray(temperature_c, dtype=np.float64))
