"""How much chamber time the population prior saves, measured on simulated units.

A prior is built from units of the simulated population calibrated the paper's
way (seven soaks, Table 1 of [1]); units that were not in it are then
calibrated from two soaks (-10 and 30 °C), three (-20, 10, 40 °C) with the
prior (:func:`hrgtc.thermometry.prior.fit_with_prior`) and seven without, and
each thermometer is compared with the unit's true frequency law over the
range: the error of the temperature read from frequency, T(f_true(T)) - T.
Soaks are simulated in memory (:func:`hrgtc.simulate.simulate_run`) and go
through plateau detection and settling extrapolation like files do.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from hrgtc.fleet.population import draw_unit, true_frequency_hz, truth
from hrgtc.settings.fleet import SETPOINTS_C
from hrgtc.simulate import simulate_run
from hrgtc.simulate import standard_profiles as profiles
from hrgtc.thermometry import fit
from hrgtc.thermometry.plateaus import find_plateaus
from hrgtc.thermometry.prior import ThermometerPrior, fit_with_prior

__all__ = ["SUBSETS", "measure_prior", "soak_points"]

#: The soaks kept for the prior fits. [°C] Two soaks inside the range: what two soaks
#: cannot see is mostly the curvature, whose error vanishes at the soaks, and soaks near
#: z = ±0.7 (as Chebyshev nodes) halve its largest value over the range compared with
#: soaks at the ends (measured: 0.048 against 0.058 °C, bench/bench_prior.py). Three: the
#: ends and the middle.
SUBSETS: dict[int, tuple[float, ...]] = {2: (-10.0, 30.0), 3: (-20.0, 10.0, 40.0)}


def soak_points(seed: int, index: int, sample_rate_hz: float, soak_hours: float,
                setpoints_c: Sequence[float] = SETPOINTS_C,
                spread: dict[str, float] | None = None) -> dict[str, Any]:
    """Simulate one unit's soaks and find their plateaus: temperatures, frequencies, errors."""
    unit, draw = draw_unit(seed, index, spread)
    temperatures, frequencies, stds = [], [], []
    for k, setpoint in enumerate(setpoints_c):
        recording = simulate_run(profiles.soak(setpoint, soak_hours), unit=unit,
                                 sample_rate_hz=sample_rate_hz,
                                 seed=np.random.SeedSequence(seed, spawn_key=(index, k)))
        (plateau,) = find_plateaus(recording)
        temperatures.append(plateau.chamber_c)
        frequencies.append(plateau.settled_freq_hz)
        stds.append(plateau.settled_freq_std_hz)
    return {"truth": truth(unit, draw), "temperatures_c": np.array(temperatures),
            "frequencies_hz": np.array(frequencies), "std_hz": np.array(stds)}


def _max_error(thermometer: Any, record: dict, grid: np.ndarray) -> float:
    read = thermometer.temperature(true_frequency_hz(record, grid), warn=False)
    return float(np.max(np.abs(read - grid)))


def measure_prior(n_prior: int, n_held_out: int, seed: int = 1, sample_rate_hz: float = 1.0,
                  soak_hours: float = 5.0, spread: dict[str, float] | None = None
                  ) -> dict[str, Any]:
    """Max temperature error over -20...40 °C of held-out units with 2, 3 and 7 soaks.

    ``spread`` overrides entries of :data:`hrgtc.fleet.population.SPREAD` (to see how
    the saving depends on the assumed population).

    Returns
    -------
    dict
        ``max_error_c``: ``{2: [...], 3: [...], 7: [...]}`` one value per held-out
        unit [°C]; ``band_c``: the prior fits' largest 1-sigma temperature
        uncertainty per unit, same keys; and the prior's summary.
    """
    prior_units = [soak_points(seed, k, sample_rate_hz, soak_hours, spread=spread)
                    for k in range(n_prior)]
    thermometers = [fit(u["temperatures_c"], u["frequencies_hz"]) for u in prior_units]
    prior = ThermometerPrior.from_thermometers(
        thermometers, [u["truth"]["unit"]["name"] for u in prior_units])
    grid = np.linspace(-20.0, 40.0, 601)
    errors: dict[int, list[float]] = {2: [], 3: [], 7: []}
    band: dict[int, list[float]] = {2: [], 3: []}
    for k in range(n_prior, n_prior + n_held_out):  # units not in the prior
        unit = soak_points(seed, k, sample_rate_hz, soak_hours, spread=spread)
        t, f, s = unit["temperatures_c"], unit["frequencies_hz"], unit["std_hz"]
        errors[7].append(_max_error(fit(t, f), unit["truth"], grid))
        for n, subset in SUBSETS.items():
            keep = np.isin(np.round(t), subset)
            result = fit_with_prior(t[keep], f[keep], prior, s[keep])
            errors[n].append(_max_error(result.thermometer, unit["truth"], grid))
            band[n].append(result.max_temperature_std_c)
    return {"max_error_c": errors, "band_c": band, "prior": prior.summary().text(),
            "n_prior": n_prior, "n_held_out": n_held_out}
