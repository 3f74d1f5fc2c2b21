"""The command-line options that read what a simulated logger wrote."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def reading_options(info: Mapping[str, Any], axes: tuple[str | None, ...],
                    logger: Any) -> list[str]:
    """The ``hrgtc`` reading options for a logged file (its column names and units), which
    the sidecar JSON carries under ``hrgtc_options``.

    ``logger`` is the :class:`~hrgtc.simulate.logger.Logger` that wrote it.
    """
    roles = info["columns"]
    cols = [f"time_s={roles['time']}"]
    for axis in axes:
        key = "" if axis is None else f"_{axis}"
        cols.append(f"rate_dph{key}={roles[f'rate{key}']}")
        if logger.frequency:
            cols.append(f"freq_hz{key}={roles[f'freq{key}']}")
    if logger.temperature is not None:
        cols.append(f"temperature_c={roles['temperature']}")
    if logger.accelerometer:
        cols += [f"accel_{a}={roles[f'accel_{a}']}" for a in "xyz"]
    options = []
    for c in cols:
        options += ["--col", c]
    options += ["--time-unit", logger.time_unit, "--rate-unit", logger.rate_unit]
    if logger.time_unit == "timestamp" and logger.timezone is not None:
        # local clock times: a daylight-saving change is a ±1 h step without the zone
        options += ["--tz", logger.timezone]
    channel = logger.temperature
    if channel is not None and channel.lsb_c is not None and channel.bits is None:
        options += ["--temp-scale", f"{channel.lsb_c:.17g}",
                    "--temp-offset", f"{channel.offset_c:.17g}"]
    if not logger.frequency:
        options += ["--thermometer", "sensor"]
    if logger.kind == "burst" or logger.restarts_s:
        # Filters carried across each gap with its duration (the temperature kept changing).
        options += ["--gaps", "bridge"]
    return options
