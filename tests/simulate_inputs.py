"""Simulator inputs whose ``to_dict`` text is pinned (``tests/data/simulate-truth/inputs.json``):
the standard chamber programs, the loggers of the presets and of ``--logger``, a logger
with every part, and a logged run's paths."""

from __future__ import annotations

from typing import Any

from hrgtc.simulate import standard_profiles as sp
from hrgtc.simulate.handling import Handling
from hrgtc.simulate.logged_files import LoggedFiles
from hrgtc.simulate.logger import Logger
from hrgtc.simulate.logger_presets import PRESETS, plain_logger, preset
from hrgtc.simulate.mems import MEMS_UNIT
from hrgtc.simulate.reflog import ReferenceLog, TemperatureChannel


def profiles() -> dict[str, Any]:
    """Name -> a standard chamber program."""
    out = {
        "soak": sp.soak(-10.0, 5.0),
        "ramp": sp.ramp(20.0, 60.0, 1.0, hold_h=0.5),
        "cooldown": sp.cooldown(),
        "warmup": sp.warmup(),
        "constant": sp.constant(20.0, 1.0),
        "rate_table": sp.rate_table([-10.0, 30.0], [0.0, 10.0, -300.0], hold_s=30.0,
                                    soak_h=0.5, axes=("x", "y", "z")),
    }
    for index, profile in enumerate(sp.soak_campaign([-20.0, 0.0, 40.0], 2.0)):
        out[f"soak_campaign_{index}"] = profile
    out.update({f"preset:{name}": preset(name).profile for name in PRESETS})
    return out


def loggers() -> dict[str, Any]:
    """Name -> a logger."""
    out = {f"preset:{name}": preset(name).logger for name in PRESETS}
    out["burst"] = plain_logger("burst", "paper-unit")
    out["continuous-mems"] = plain_logger("continuous", MEMS_UNIT)
    out["every-part"] = Logger(
        temperature=TemperatureChannel(lsb_c=0.00625, offset_c=23.375, bits=16,
                                       rate_hz=1.0, source="housing"),
        reference_log=ReferenceLog(every_s=300.0, fahrenheit=True),
        handling=Handling(orientations=3, change_times_s=(600.0, 1200.0),
                          g_sensitivity_dph_per_g={"x": (1.0, 2.0, 3.0)}),
        restarts_s=(100.0, 200.0), columns={"time": "t"},
        extra_columns={"mag_x": (0.2, 0.01)},
    )
    return out


def logged_files() -> dict[str, Any]:
    """A logged run's paths, with and without a reference log."""
    return {"with-reflog": LoggedFiles("run.csv", "run.truth.json", "run.truth.csv",
                                       "run_reflog.csv", 1000),
            "without": LoggedFiles("run.csv", "run.truth.json", "run.truth.csv", None, 10)}


def documents() -> dict[str, Any]:
    """Every pinned input as its ``to_dict``."""
    return {"profiles": {k: v.to_dict() for k, v in profiles().items()},
            "loggers": {k: v.to_dict() for k, v in loggers().items()},
            "logged_files": {k: v.to_dict() for k, v in logged_files().items()}}
