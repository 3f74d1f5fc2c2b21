"""Lag or hysteresis? The chamber experiment that tells a thermal lag from a thermal memory.

A heating/cooling difference in a gyro's bias has two possible causes, which a model
must treat differently (docs/history.md):

* a **lag**: the bias depends on where the temperature is going (the housing - resonator
  gradient ``G = tau_r dT_r/dt`` of :class:`~hrgtc.simulate.laws.BiasLaw`, and its
  saturating ``h tanh(G/G_h)`` term). It has no memory: the difference between heating
  and cooling shrinks as the ramp rate goes to 0, and a soak settles to the same bias
  from above and from below.
* a **hysteresis** (a rate-independent memory, the play of :class:`~hrgtc.simulate.laws.BiasLaw`):
  the difference stays as the rate goes to 0, and a soak settles to a bias that depends
  on the side it was approached from (``s w`` for a play of width ``w`` and slope ``s``).

Two experiments, in the simulator, on the ground truth columns ``resonator_c`` and
``bias_dph`` (noise-free: the experiment characterises the unit's law):

1. **ramp-rate sweep** (:func:`ramp_splits`): from equilibrium at ``centre - span`` the
   chamber ramps to ``centre + span``, holds, ramps back and holds, at each rate; the
   split is the bias when the resonator passes ``centre`` heating minus when it passes
   it cooling. The line through the two slowest rates gives the split at rate 0.
2. **approach from above and below** (:func:`approach_soaks`): from equilibrium at
   ``centre ± span`` the chamber ramps to ``centre`` and holds ``hold_h``; the settled
   bias from above minus from below. What is left of the lag after the hold is bounded
   by :func:`settle_bound` (the cascade's step response, :mod:`hrgtc.simulate.thermal`).

:func:`classify` runs both and gives the verdict (:class:`HistoryVerdict`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.simulate.campaign import simulate_run
from hrgtc.simulate.profiles import Profile, Segment
from hrgtc.simulate.units import Unit, get

__all__ = ["HistoryExperiment", "HistoryVerdict", "approach_soaks", "classify",
           "ramp_splits", "settle_bound"]

#: Rounding allowance added to :func:`settle_bound` (the simulator's float64 sums). [°/h]
ROUNDING_DPH = 1e-9


@dataclass(frozen=True)
class HistoryExperiment:
    """The chamber programs of the lag-or-hysteresis experiment.

    Parameters
    ----------
    centre_c
        Temperature at which heating and cooling are compared and the soaks settle. [°C]
    span_c
        Excursion on each side of ``centre_c``; larger than any play width to be seen. [°C]
    rates_c_per_min
        Ramp rates of the sweep, fastest first; the last two give the split at rate 0.
        [°C/min]
    hold_h
        Hold after each ramp (the soaks' settling time). [h]
    sample_rate_hz
        Sample rate of the simulated runs (the thermal network is integrated exactly,
        so a low rate loses nothing but time resolution). [Hz]
    """

    centre_c: float = 20.0
    span_c: float = 10.0
    rates_c_per_min: tuple[float, ...] = (1.0, 0.3, 0.1, 0.03, 0.01)
    hold_h: float = 8.0
    sample_rate_hz: float = 0.05

    def __post_init__(self) -> None:
        rates = tuple(float(r) for r in self.rates_c_per_min)
        if len(rates) < 2 or not all(math.isfinite(r) and r > 0.0 for r in rates):
            raise InputError(f"rates_c_per_min needs at least two rates > 0 [°C/min], got "
                             f"{self.rates_c_per_min!r}")
        if not (self.span_c > 0.0 and self.hold_h > 0.0 and self.sample_rate_hz > 0.0):
            raise InputError(f"span_c, hold_h and sample_rate_hz must be > 0, got {self!r}")
        object.__setattr__(self, "rates_c_per_min", rates)


@dataclass(frozen=True)
class HistoryVerdict:
    """What the experiment found for one unit.

    Attributes
    ----------
    unit
        The unit's name.
    rates_c_per_min
        The sweep's rates. [°C/min]
    heating_dph, cooling_dph
        Bias when the resonator passed ``centre_c`` heating / cooling, per rate. [°/h]
    split_dph
        heating - cooling, per rate. [°/h]
    split_at_zero_rate_dph
        The line through the two slowest rates' splits, at rate 0. [°/h]
    from_above_dph, from_below_dph
        Settled bias at ``centre_c`` approached from above / below. [°/h]
    settled_difference_dph
        from above - from below. [°/h]
    tolerance_dph
        What a unit without memory can leave in ``settled_difference_dph`` after the hold
        (:func:`settle_bound`). [°/h]
    verdict
        ``"hysteresis"`` (the settled difference exceeds the tolerance: a memory),
        ``"lag"`` (no memory, and the split shrinks toward rate 0) or ``"none"`` (no
        split at any rate).
    """

    unit: str
    rates_c_per_min: tuple[float, ...]
    heating_dph: tuple[float, ...]
    cooling_dph: tuple[float, ...]
    split_dph: tuple[float, ...]
    split_at_zero_rate_dph: float
    from_above_dph: float
    from_below_dph: float
    settled_difference_dph: float
    tolerance_dph: float
    verdict: str

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types."""
        return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(self).items()}


def _unit(unit: str | Unit) -> Unit:
    gyro = get(unit) if isinstance(unit, str) else unit
    if not isinstance(gyro, Unit):
        raise InputError(f"the history experiment takes a single-axis unit, got {unit!r}; "
                         "pass one axis (get('imu-3').axes['x'])")
    return gyro


def _crossing(temperature: np.ndarray, bias: np.ndarray, level: float, rising: bool,
              start: int = 0) -> tuple[float, int]:
    """Bias (linearly interpolated) where ``temperature`` first crosses ``level`` after
    row ``start``, rising or falling, and the row after the crossing."""
    t = temperature[start:] - level
    hits = np.flatnonzero((t[:-1] < 0.0) & (t[1:] >= 0.0) if rising
                          else (t[:-1] > 0.0) & (t[1:] <= 0.0))
    if hits.size == 0:
        raise InputError(f"the resonator never crossed {level:g} °C "
                         f"{'rising' if rising else 'falling'}; lengthen hold_h")
    k = int(hits[0])
    share = t[k] / (t[k] - t[k + 1])
    i = start + k
    return float(bias[i] + share * (bias[i + 1] - bias[i])), i + 1


def ramp_splits(unit: str | Unit, experiment: HistoryExperiment = HistoryExperiment()
                ) -> list[tuple[float, float, float]]:
    """(rate, heating bias, cooling bias) at ``centre_c`` for each rate of the sweep.

    Returns
    -------
    list of (float, float, float)
        [°C/min], [°/h], [°/h]
    """
    gyro, e = _unit(unit), experiment
    low, high = e.centre_c - e.span_c, e.centre_c + e.span_c
    out = []
    for rate in e.rates_c_per_min:
        profile = Profile((Segment(high, ramp_c_per_min=rate), Segment(high, hold_h=e.hold_h),
                           Segment(low, ramp_c_per_min=rate), Segment(low, hold_h=e.hold_h)),
                          start_c=low, chamber_max_c_per_min=max(rate, 1.0),
                          name=f"sweep_{rate:g}", description=f"history sweep at {rate:g} C/min")
        run = simulate_run(profile, gyro, e.sample_rate_hz, seed=0)
        temperature, bias = run["resonator_c"], run["bias_dph"]
        heating, row = _crossing(temperature, bias, e.centre_c, rising=True)
        row = int(np.argmax(temperature))  # past the top before looking for the way down
        cooling, _ = _crossing(temperature, bias, e.centre_c, rising=False, start=row)
        out.append((rate, heating, cooling))
    return out


def approach_soaks(unit: str | Unit, experiment: HistoryExperiment = HistoryExperiment(),
                   rate_c_per_min: float | None = None) -> tuple[float, float]:
    """Settled bias at ``centre_c`` after approaching it from above and from below.

    The chamber starts in equilibrium at ``centre_c ± span_c``, ramps to ``centre_c`` at
    ``rate_c_per_min`` (the sweep's slowest rate by default) and holds ``hold_h``; the
    bias of the last sample.

    Returns
    -------
    float, float
        From above, from below. [°/h]
    """
    gyro, e = _unit(unit), experiment
    rate = e.rates_c_per_min[-1] if rate_c_per_min is None else float(rate_c_per_min)
    settled = []
    for side in (+1.0, -1.0):
        profile = Profile((Segment(e.centre_c, ramp_c_per_min=rate),
                           Segment(e.centre_c, hold_h=e.hold_h)),
                          start_c=e.centre_c + side * e.span_c,
                          chamber_max_c_per_min=max(rate, 1.0), name="approach",
                          description=f"approach {e.centre_c:g} C from "
                                      f"{'above' if side > 0 else 'below'}")
        run = simulate_run(profile, gyro, e.sample_rate_hz, seed=0)
        settled.append(float(run["bias_dph"][-1]))
    return settled[0], settled[1]


def settle_bound(unit: str | Unit, experiment: HistoryExperiment = HistoryExperiment()) -> float:
    """Largest settled difference from above minus below that a unit without memory leaves.

    After a chamber step of ``span_c`` (a ramp ending at the same time leaves less: it is
    an average of steps that started earlier), the resonator is
    ``ε_r = span (tau_r e^(-t/tau_r) - tau_h e^(-t/tau_h)) / (tau_r - tau_h)`` from the
    set-point and the gradient is ``|G| <= span tau_r |e^(-t/tau_r) - e^(-t/tau_h)| /
    |tau_r - tau_h|`` (:func:`hrgtc.simulate.thermal.step_response`), ``t = hold_h`` (for the
    gradient, which rises to a peak before it falls, ``t`` no earlier than that peak). The
    lag part of :class:`~hrgtc.simulate.laws.BiasLaw` moves at most
    ``L_T ε_r + L_G |G|`` on each side, with ``L_T`` the largest ``|dB/dT_r|`` over
    ``centre ± span`` (and that ``|G|``) and ``L_G = |g| + |g_T| span + |h|/G_h``; the
    bound is twice that (both sides) plus :data:`ROUNDING_DPH`. A play
    (of :class:`~hrgtc.simulate.laws.BiasLaw`) with ``span_c >= w`` is engaged on both
    monotone approaches, so it adds exactly ``s w`` to the difference.

    Returns
    -------
    float
        [°/h]
    """
    gyro, e = _unit(unit), experiment
    tau_h, tau_r = gyro.thermal.tau_housing_s, gyro.thermal.tau_resonator_s
    t = e.hold_h * 3600.0
    if tau_r == tau_h:
        raise InputError("settle_bound needs tau_resonator_s != tau_housing_s")
    resonator = e.span_c * abs(tau_r * math.exp(-t / tau_r) - tau_h * math.exp(-t / tau_h)) \
        / abs(tau_r - tau_h)
    # the gradient's step response rises to a peak, then falls: its largest value from t on
    peak = math.log(tau_r / tau_h) * tau_r * tau_h / (tau_r - tau_h)
    t_gradient = max(t, peak)
    gradient = e.span_c * tau_r * abs(math.exp(-t_gradient / tau_r)
                                      - math.exp(-t_gradient / tau_h)) / abs(tau_r - tau_h)
    law = gyro.bias_law
    c1, c2, c3 = law.temperature_dph
    dt = np.linspace(-e.span_c, e.span_c, 2001) + (e.centre_c - law.reference_c)
    slope_t = np.abs(c1 + 2.0 * c2 * dt + 3.0 * c3 * dt ** 2) \
        + abs(law.gradient_temperature_dph_per_c2) * gradient
    slope_g = (abs(law.gradient_dph_per_c) + abs(law.gradient_temperature_dph_per_c2)
               * float(np.abs(dt).max()) + abs(law.hysteresis_dph) / law.hysteresis_width_c)
    return 2.0 * (float(slope_t.max()) * resonator + slope_g * gradient) + ROUNDING_DPH


def classify(unit: str | Unit, experiment: HistoryExperiment = HistoryExperiment()
             ) -> HistoryVerdict:
    """Run the sweep and the two approaches on ``unit`` and say lag, hysteresis or none."""
    gyro, e = _unit(unit), experiment
    sweep = ramp_splits(gyro, e)
    rates = tuple(r for r, _, _ in sweep)
    splits = tuple(h - c for _, h, c in sweep)
    (r1, s1), (r2, s2) = sorted(zip(rates, splits, strict=True))[:2]
    at_zero = s1 - r1 * (s2 - s1) / (r2 - r1)
    above, below = approach_soaks(gyro, e)
    tolerance = settle_bound(gyro, e)
    difference = above - below
    if abs(difference) > tolerance:
        verdict = "hysteresis"
    elif max(abs(s) for s in splits) > tolerance:
        verdict = "lag"
    else:
        verdict = "none"
    return HistoryVerdict(
        unit=gyro.name, rates_c_per_min=rates,
        heating_dph=tuple(h for _, h, _ in sweep), cooling_dph=tuple(c for _, _, c in sweep),
        split_dph=splits, split_at_zero_rate_dph=float(at_zero), from_above_dph=above,
        from_below_dph=below, settled_difference_dph=difference, tolerance_dph=tolerance,
        verdict=verdict)
