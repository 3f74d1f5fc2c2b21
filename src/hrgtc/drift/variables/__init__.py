"""The drift variables: one module per variable, collected by :mod:`.registry`.

Adding a variable is one module here (copy the one of a variable of the same kind: ``d2``
for a filtered rate, ``g`` for a variable computed from other columns, ``aux`` for a logged
channel; the registry finds it), and a test; see ``docs/architecture.md``.
"""

from hrgtc.drift.variables.registry import (
    AUX_PREFIX,
    BACKEND_NAMES,
    BACKENDS,
    DRIFT_VARIABLES,
    FIXED,
    DriftVariable,
    ascii_unit,
    docs_table,
    is_aux,
    refusal,
    settings_fields,
    settings_schema,
    supported,
    unit,
    unsupported,
    variable,
)
from hrgtc.drift.variables.spec import Inputs

__all__ = ["AUX_PREFIX", "BACKENDS", "BACKEND_NAMES", "DRIFT_VARIABLES", "FIXED",
           "DriftVariable", "Inputs", "ascii_unit", "docs_table", "is_aux", "refusal",
           "settings_fields", "settings_schema", "supported", "unit", "unsupported", "variable"]
