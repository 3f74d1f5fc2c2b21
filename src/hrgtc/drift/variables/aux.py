"""``a_NAME``: an extra logged channel (``--aux NAME=COLUMN``) minus its training mean.

One entry stands for every channel: ``a_drive`` reads the column
``settings.aux_columns["drive"]`` and subtracts ``settings.aux_centres["drive"]``; its unit
is its column's.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from hrgtc.drift.variables.spec import DriftVariable, Inputs
from hrgtc.errors import InputError

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


VARIABLE = DriftVariable(
    name="a_NAME", unit="unit of its column", sensor_unit="unit of its column", kind="level",
    description="an extra logged channel (--aux NAME=COLUMN) minus its training mean",
    backends=frozenset({"numpy", "c_double", "params"}), columns=(), compute=compute,
    order=7, check=check,
    settings_schema={"aux_columns": {"type": "object",
                                     "additionalProperties": {"type": "string"}},
                     "aux_centres": {"type": "object",
                                     "additionalProperties": {"type": "number"}}})
