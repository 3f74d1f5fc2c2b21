"""The drift-variable registry: every variable of the term grammar, one module each.

Each module of this package (``f``, ``df``, ``h``, ``dh``, ``dpos``, ``d2``, ``g``, ``aux``
for the extra channels ``a_NAME``) builds one :class:`~hrgtc.drift.variables.spec.DriftVariable`
with its unit, kind, docs line, backends, numpy reference, settings and C pieces;
:data:`DRIFT_VARIABLES` collects them in grammar order (a package entry point could add
more later). Every way hrgtc computes the drift model reads this list to know what it
can do, so a variable cannot be known to one backend and missing from another without a
test saying so (``tests/drift/test_variables.py`` is generated from it):

=============  =============================================================
backend        what it is
=============  =============================================================
``numpy``      the reference: :class:`hrgtc.drift.features.FeatureStream` (each
               variable's ``compute``) and :meth:`hrgtc.drift.DriftModel.predict`
``numba``      the fused kernel of :mod:`hrgtc.compensate._kernel`; a model with
               a variable it lacks runs on the numpy engine (same numbers)
``c_double``   ``hrgtc export-c`` (C99, double)
``c_float32``  ``hrgtc export-c --precision single``
``params``     ``hrgtc export-c --format params`` (the plain parameter file)
=============  =============================================================

An export that lacks a variable refuses the model with a message naming the variable
and what to do (:func:`refusal`); the numba kernel falls back to numpy instead.

Units: a model whose thermometer is the resonator (an HRG) has f in Hz; a model whose
thermometer is the gyro's temperature sensor (``calibrate --thermometer sensor``) reads
that sensor in the place of the frequency, so f is in °C and its rates in °C/s
(:attr:`DriftVariable.sensor_unit`).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import importlib
import os
import re
import sys
from pathlib import Path
from typing import Any

from hrgtc.drift.variables.aux import AUX_PREFIX
from hrgtc.drift.variables.spec import BACKENDS, DriftVariable
from hrgtc.settings.drift_variables import DECLARATIONS, Declaration

__all__ = ["AUX_PREFIX", "BACKENDS", "BACKEND_NAMES", "DRIFT_VARIABLES", "FIXED",
           "DriftVariable", "ascii_unit", "docs_table", "is_aux", "refusal",
           "settings_fields", "settings_schema", "supported", "unit", "unsupported", "variable"]

#: What each backend is called in messages.
BACKEND_NAMES = {
    "numpy": "the numpy compensator",
    "numba": "the fused (numba) compensation kernel",
    "c_double": "the C export (hrgtc export-c)",
    "c_float32": "the float32 C export (hrgtc export-c --precision single)",
    "params": "the parameter file (hrgtc export-c --format params)",
}
#: What to do when an export lacks a variable.
_INSTEAD = {
    "c_double": "calibrate without {v} terms for on-board use",
    "c_float32": "export it with --precision double, or calibrate without {v} terms",
    "params": "export C (--format c), or calibrate without {v} terms",
}


#: Modules of this package that are not variables.
NOT_VARIABLES = frozenset({"registry", "spec"})


def variable_modules(directory: Path | str) -> list[str]:
    """Names of the drift variables' modules in ``directory``, sorted: every ``NAME.py``
    but ``_*``, ``registry`` and ``spec``."""
    names = (name[:-3] for name in os.listdir(directory) if name.endswith(".py"))
    return sorted(n for n in names if n not in NOT_VARIABLES and not n.startswith("_"))


def check_declared(found: tuple[DriftVariable, ...],
                   declarations: tuple[Declaration, ...] = DECLARATIONS) -> None:
    """Refuse variables that :mod:`hrgtc.settings.drift_variables` does not declare, in
    the same order (the command line reads the names and options there, without numpy).

    Raises
    ------
    RuntimeError
        Naming the variables missing from the declarations, or declared and missing
        here, or the two orders.
    """
    names, declared = [v.name for v in found], [d.name for d in declarations]
    if names == declared:
        return
    missing, extra = sorted(set(names) - set(declared)), sorted(set(declared) - set(names))
    what = (f"not declared: {missing}; " if missing else "") + (
        f"declared without a module: {extra}; " if extra else "") or "the order differs; "
    raise RuntimeError(
        f"the drift variables {names} (in the order of their modules' order=) are not the "
        f"declarations {declared} of hrgtc/settings/drift_variables.py: {what}add a "
        "Declaration(name, options) there for each variable module, in the grammar's order")


def _discover() -> tuple[DriftVariable, ...]:
    """The ``VARIABLE`` of every module of this package, in grammar order, checked against
    the declarations (:func:`check_declared`)."""
    package = sys.modules[__package__]
    found = []
    for directory in package.__path__:
        for name in variable_modules(directory):
            module = importlib.import_module(f"{__package__}.{name}")
            found.append(module.VARIABLE)
    found.sort(key=lambda v: v.order)
    orders = [v.order for v in found]
    if len(set(orders)) != len(orders) or len({v.name for v in found}) != len(found):
        raise RuntimeError(f"drift variables with the same order or name: {found}")
    check_declared(tuple(found))
    return tuple(found)


#: Every drift variable, in the grammar's order (the order of terms' factors): the
#: ``VARIABLE`` of each module of this package.
DRIFT_VARIABLES: tuple[DriftVariable, ...] = _discover()
_BY_NAME = {v.name: v for v in DRIFT_VARIABLES}
_AUX_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9]*$")
#: The fixed variables' names (every one but ``a_NAME``), in grammar order.
FIXED = tuple(v.name for v in DRIFT_VARIABLES if v.name != "a_NAME")


def is_aux(name: str) -> bool:
    """Whether ``name`` is a user's extra channel ``a_NAME``."""
    return name.startswith(AUX_PREFIX) and bool(_AUX_NAME.match(name[len(AUX_PREFIX):]))


def variable(name: str) -> DriftVariable:
    """The registry entry of a variable (``a_drive`` -> the ``a_NAME`` entry).

    Raises
    ------
    KeyError
        ``name`` is not a drift variable.
    """
    if name in _BY_NAME and name != "a_NAME":
        return _BY_NAME[name]
    if is_aux(name):
        return _BY_NAME["a_NAME"]
    raise KeyError(name)


def unit(name: str, thermometer_source: str = "resonator") -> str:
    """Unit of variable ``name`` (an extra channel's: ``unit of its column``)."""
    return variable(name).unit_for(thermometer_source)


def ascii_unit(name: str, thermometer_source: str = "resonator") -> str:
    """:func:`unit` in ASCII, as the exports write it (``degC/s``)."""
    return unit(name, thermometer_source).replace("°C", "degC")


def supported(backend: str) -> tuple[str, ...]:
    """Names of the variables ``backend`` computes (``a_NAME`` for the extra channels)."""
    return tuple(v.name for v in DRIFT_VARIABLES if v.supports(backend))


def unsupported(names: object, backend: str) -> list[str]:
    """The variables among ``names`` that ``backend`` does not compute, in the given order."""
    return [n for n in names if not variable(n).supports(backend)]  # type: ignore[attr-defined]


def refusal(names: object, backend: str, terms: object = ()) -> str | None:
    """The message of an export that lacks some of the variables ``names`` (None: it has all).

    Names the variables, the backend, what each is, and what to do instead.
    """
    missing = unsupported(names, backend)
    if not missing:
        return None
    what = "; ".join(f"{n}: {variable(n).description}" for n in missing)
    listed = ", ".join(missing)
    used = f" (terms {', '.join(terms)})" if terms else ""  # type: ignore[arg-type]
    instead = _INSTEAD.get(backend, "use another backend").format(v=listed)
    return (f"the drift model uses {listed}{used}, which {BACKEND_NAMES[backend]} does not "
            f"compute ({what}); {instead}")


def settings_fields() -> list[tuple[str, Any, Any]]:
    """The feature settings the variables own, ``(field, type, default)`` each:
    :class:`hrgtc.drift.features.FeatureSettingsRecord` (the model file's
    ``drift.settings``) is generated with them beside the settings every model has."""
    return [entry for v in DRIFT_VARIABLES for entry in v.settings_fields]


def settings_schema() -> dict[str, dict[str, Any]]:
    """The JSON Schema of each setting a variable owns, as the model file's schema has it."""
    import msgspec

    from hrgtc.core import records

    part = msgspec.defstruct("VariableSettings", settings_fields(), bases=(records.Record,),
                             kw_only=True)
    (_, components) = msgspec.json.schema_components([part])
    return dict(components["VariableSettings"]["properties"])


def docs_table() -> str:
    """The docs' table of the variables and their backends (Markdown), from the registry.

    ``docs/reliability.md`` holds it between ``<!-- table: drift_variables -->`` markers,
    written by :mod:`hrgtc.cli.options_tables`; a test fails while the two differ.
    """
    said = {"numpy": "yes", "numba": "yes", "c_double": "yes", "c_float32": "yes",
            "params": "yes"}
    missing = {"numba": "numpy instead"}
    rows = ["| variable | unit (resonator / sensor) | numpy | numba kernel | C double "
            "| C float32 | parameter file |",
            "|---|---|---|---|---|---|---|"]
    for v in DRIFT_VARIABLES:
        units = v.unit if v.unit == v.sensor_unit else f"{v.unit} / {v.sensor_unit}"
        units = "its column's" if v.name == "a_NAME" else units
        cells = [said[b] if v.supports(b) else missing.get(b, "refused") for b in BACKENDS]
        rows.append(f"| `{v.name}` | {units} | " + " | ".join(cells) + " |")
    return "\n".join(rows)
