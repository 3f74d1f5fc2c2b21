"""``a_NAME``: an extra logged channel (``--aux NAME=COLUMN``) minus its training mean.

One entry stands for every channel: ``a_drive`` reads the column
``settings.aux_columns["drive"]`` and subtracts ``settings.aux_centres["drive"]``; its unit
is its column's. In C, ``step()`` takes one more input ``aux_drive`` (the logged value,
double or float as the build) and subtracts the centre ``AUX_CENTRE_drive``; the float32
mirror rounds the logged value to float as firmware passes it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.drift.variables.spec import DriftVariable, FirstPass, Inputs, Put

#: Prefix of the user's extra channels.
AUX_PREFIX = "a_"


def centre(settings: Any, name: str) -> float:
    """Training mean of the extra channel ``name`` (0 before it is known). [column unit]"""
    return float(settings.aux_centres.get(name, 0.0))


def compute(inputs: Inputs, variable: str) -> np.ndarray:
    """a_NAME = column - its training mean. [column unit]"""
    chunk, name = inputs.chunk, variable[len(AUX_PREFIX):]
    column = inputs.settings.aux_columns[name]
    if column not in chunk:
        where = f"{chunk.source}: " if chunk.source else ""
        raise InputError(
            f"{where}no column {column!r}, which the extra channel {name!r} (variable "
            f"{variable}) reads; the model was calibrated with --aux {name}={column}: log "
            f"that channel, or rename the file's column to {column!r} (--col)"
        )
    return np.asarray(chunk[column], dtype=np.float64) - centre(inputs.settings, name)


def check(settings: Any, thermometer: Any, variable: str) -> str | None:
    if variable[len(AUX_PREFIX):] not in settings.aux_columns:
        return f"variable(s) ['{variable}'] have no column: map each with --aux NAME=COLUMN"
    return None


class CCode:
    """a_NAME's C: the input ``aux_NAME`` minus its training mean; ``bias_dph(..., a_NAME)``."""

    def pieces(self, ctype: Any, double: Any, name: str, settings: Any, prefix: str,
               comment: Callable[[Any], str]) -> dict[str, str]:
        channel = name[len(AUX_PREFIX):]
        mean = ctype.literal(centre(settings, channel), f"aux_centres[{channel}]")
        return {
            "constants": (f"/* training mean of aux_{channel}, the logged column "
                          f"{comment(settings.aux_columns.get(channel, '?'))} */\n"
                          f"static const {ctype.name} AUX_CENTRE_{channel} = {mean};\n"),
            "values": (f"    const {ctype.name} a_{channel}_value = aux_{channel} - "
                       f"AUX_CENTRE_{channel};\n"),
            "bias": f", a_{channel}_value",
        }

    def inputs(self, name: str) -> tuple[str, ...]:
        return (f"aux_{name[len(AUX_PREFIX):]}",)

    def parameter(self, name: str) -> str:
        return name

    def readme(self, name: str, settings: Any) -> str:
        channel = name[len(AUX_PREFIX):]
        return (f"  {name} = aux_{channel} - {centre(settings, channel):.12g}: the logged "
                f"column {settings.aux_columns.get(channel, '?')!r} minus its training mean   "
                "[its unit]")

    def firmware_value(self, value: np.ndarray, name: str, settings: Any) -> np.ndarray:
        # firmware passes the logged value as a float and subtracts the float centre
        mean = centre(settings, name[len(AUX_PREFIX):])
        logged = (np.asarray(value, dtype=np.float64) + mean).astype(np.float32)
        return (logged - np.float32(mean)).astype(np.float32)


def params(names: tuple[str, ...], settings: Any, put: Put) -> None:
    """The extra channels' keys of the parameter file: their names, then each one's column
    and training mean."""
    channels = [name[len(AUX_PREFIX):] for name in names]
    put("aux_names", " ".join(channels),
        "Extra logged channels the terms use (a_NAME = aux_NAME - aux_centre_NAME).")
    for name in channels:
        column = settings.aux_columns.get(name, "?")
        put(f"aux_column_{name}", column, f"The logged column aux_{name} is read from.")
        put(f"aux_centre_{name}", settings.aux_centres.get(name, 0.0),
            f"Training mean of aux_{name}, subtracted. [unit of the column {column}]")


def columns(names: tuple[str, ...], given: Mapping[str, Any]) -> dict[str, Any]:
    """The channels' columns, from ``--aux NAME=COLUMN`` (``given["aux_columns"]``).

    Raises
    ------
    InputError
        A candidate's channel has no column.
    """
    mapped = {str(k): str(v) for k, v in dict(given.get("aux_columns") or {}).items()}
    unmapped = [n for n in names if n[len(AUX_PREFIX):] not in mapped]
    if unmapped:
        raise InputError(f"candidate variable(s) {unmapped} have no column; map each with "
                         "--aux NAME=COLUMN")
    return {"aux_columns": mapped}


def centres(names: tuple[str, ...], means: Mapping[str, np.ndarray]) -> dict[str, Any]:
    """Each channel's training mean, from the first pass's window means. [column unit]"""
    return {"aux_centres": {n[len(AUX_PREFIX):]: float(np.mean(means[n])) for n in names}}


VARIABLE = DriftVariable(
    name="a_NAME", unit="unit of its column", sensor_unit="unit of its column", kind="level",
    description="an extra logged channel (--aux NAME=COLUMN) minus its training mean",
    backends=frozenset({"numpy", "c_double", "c_float32", "params"}), columns=(),
    compute=compute, order=9, check=check, c_code=CCode(),
    settings_fields=(("aux_columns", dict[str, str], records.empty()),
                     ("aux_centres", dict[str, float], records.empty())), params=params,
    derive=columns, first_pass=FirstPass(reads=lambda names: names, derive=centres))
