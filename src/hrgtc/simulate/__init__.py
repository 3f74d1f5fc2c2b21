"""Chamber-campaign simulator with ground truth.

Simulated recordings follow the recording contract (``time_s``, ``freq_hz``,
``rate_dph``, ``chamber_c``, ``housing_c``) and add the ground truth
``resonator_c`` and ``bias_dph``; a unit with a scale-factor law adds the truth
``scale_ppm``, and a rate-table run the known input ``input_rate_dph``. A
multi-axis unit (``imu-3``) writes these per axis (``rate_dph_x``, ...) beside
the shared ``time_s``, ``chamber_c`` and ``housing_c``
(:func:`~hrgtc.simulate.campaign.run_columns`). The parts, one module each:

- :mod:`~hrgtc.simulate.profiles`: the chamber program type and its JSON/YAML files;
- :mod:`~hrgtc.simulate.standard_profiles`: soaks, ramps, cool-down, warm-up, constant,
  rate table;
- :mod:`~hrgtc.simulate.thermal`: chamber -> housing -> resonator network;
- :mod:`~hrgtc.simulate.laws`: frequency law (Table 1 / Eq. 18 of [1], or the
  shell model), bias law, play memory and scale-factor law in physical variables;
- :mod:`~hrgtc.simulate.noise_sources`: ARW, bias instability, rate random walk;
- :mod:`~hrgtc.simulate.units`: named simulated gyros (``paper-unit``, ``unit-b``,
  ``unit-play`` with a play memory) and the three-axis ``imu-3``;
- :mod:`~hrgtc.simulate.history`: the experiment that tells a thermal lag from a
  hysteresis (ramp-rate sweep, soaks approached from above and below);
- :mod:`~hrgtc.simulate.campaign`: runs in chunks, with ground truth;
- :mod:`~hrgtc.simulate.output`: runs written to files, atomically;
- :mod:`~hrgtc.simulate.mems`: a three-axis MEMS gyro (``mems-3``) for the real-logger cases;
- :mod:`~hrgtc.simulate.logger`: what a real logger writes (bursts, ms/µs clocks that
  wrap, restarts, raw counts, spikes, handling), with the truth of every row, built on
  :mod:`~hrgtc.simulate.duty` (kept rows), :mod:`~hrgtc.simulate.handling`
  (orientations, handling) and :mod:`~hrgtc.simulate.reflog` (counts, hand log);
  written by :mod:`~hrgtc.simulate.logged_files`; named cases in
  :mod:`~hrgtc.simulate.logger_presets` (``pan-cold``, ``fridge-3day``).

Examples
--------
>>> from hrgtc import simulate
>>> rec = simulate.simulate_run(simulate.constant(20.0, 0.1), sample_rate_hz=10.0, seed=0)
>>> rec.names
('time_s', 'freq_hz', 'rate_dph', 'chamber_c', 'housing_c', 'resonator_c', 'bias_dph')

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

# mems registers the unit 'mems-3' with units.get (units does not import it back)
from hrgtc.simulate import mems, profiles, standard_profiles, units
from hrgtc.simulate.campaign import (
    COLUMNS,
    DEFAULT_INPUT_RATE_DPH,
    input_rates_dph,
    iter_run_chunks,
    run_columns,
    run_metadata,
    simulate_run,
)
from hrgtc.simulate.handling import Handling
from hrgtc.simulate.laws import (
    BiasLaw,
    PolynomialFrequencyLaw,
    ScaleFactorLaw,
    ShellFrequencyLaw,
    table1_frequency_law,
)
from hrgtc.simulate.logged_files import LoggedFiles, simulate_logged_files, write_logged
from hrgtc.simulate.logger import LoggedRun, Logger, log_run
from hrgtc.simulate.noise_sources import GyroNoise
from hrgtc.simulate.output import (
    SimulatedRun,
    WrittenFile,
    output_paths,
    simulate_files,
    simulate_to_file,
)
from hrgtc.simulate.profiles import Profile, Segment
from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel
from hrgtc.simulate.standard_profiles import (
    constant,
    cooldown,
    ramp,
    rate_table,
    soak,
    soak_campaign,
    soak_series,
    warmup,
)
from hrgtc.simulate.thermal import ThermalNetwork
from hrgtc.simulate.units import MultiAxisUnit, Unit, unit_from_dict

__all__ = [
    "COLUMNS",
    "DEFAULT_INPUT_RATE_DPH",
    "BiasLaw",
    "GyroNoise",
    "Handling",
    "LoggedFiles",
    "LoggedRun",
    "Logger",
    "MultiAxisUnit",
    "PolynomialFrequencyLaw",
    "Profile",
    "ReferenceLog",
    "ScaleFactorLaw",
    "Segment",
    "ShellFrequencyLaw",
    "SimulatedRun",
    "TemperatureChannel",
    "ThermalNetwork",
    "Unit",
    "WrittenFile",
    "constant",
    "cooldown",
    "input_rates_dph",
    "iter_run_chunks",
    "log_run",
    "mems",
    "output_paths",
    "profiles",
    "ramp",
    "rate_table",
    "run_columns",
    "run_metadata",
    "simulate_files",
    "simulate_logged_files",
    "simulate_run",
    "simulate_to_file",
    "soak",
    "soak_campaign",
    "soak_series",
    "standard_profiles",
    "table1_frequency_law",
    "unit_from_dict",
    "units",
    "warmup",
    "write_logged",
]
