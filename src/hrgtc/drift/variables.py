"""The drift variables: one list, with each variable's unit, kind, backends and docs line.

Every way hrgtc computes the drift model reads this list to know what it can do, so a
variable cannot be known to one backend and missing from another without a test
saying so (``tests/drift/test_variables.py`` is generated from :data:`DRIFT_VARIABLES`):

=============  =============================================================
backend        what it is
=============  =============================================================
``numpy``      the reference: :class:`hrgtc.drift.features.FeatureStream` and
               :meth:`hrgtc.drift.DriftModel.predict` (every variable)
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

This is the seed of the variable registry of issue 22: adding a variable starts here.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import re
from dataclasses import dataclass

#: The backends, in the order of the table above.
BACKENDS = ("numpy", "numba", "c_double", "c_float32", "params")
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
_ALL = frozenset(BACKENDS)


@dataclass(frozen=True)
class DriftVariable:
    """One variable of the drift model's term grammar.

    Attributes
    ----------
    name
        Its spelling in terms (``a_NAME`` stands for every extra channel).
    unit
        Unit with the resonator as thermometer (an HRG) (:func:`ascii_unit` for exports).
    sensor_unit
        Unit when the thermometer is the gyro's temperature sensor.
    kind
        ``"level"`` (checked for ``in_range``) or ``"rate"`` (``rate_in_range``).
    description
        The docs line: what the variable is.
    backends
        Where it is computed (see :data:`BACKENDS`).
    columns
        Recording columns it reads (``a_NAME``: the mapped column, not named here).
    """

    name: str
    unit: str
    sensor_unit: str
    kind: str
    description: str
    backends: frozenset[str]
    columns: tuple[str, ...]

    def unit_for(self, thermometer_source: str = "resonator") -> str:
        """The unit for a model whose thermometer is ``"resonator"`` or ``"sensor"``."""
        return self.sensor_unit if thermometer_source == "sensor" else self.unit

    def supports(self, backend: str) -> bool:
        """Whether ``backend`` computes this variable."""
        if backend not in BACKENDS:
            raise ValueError(f"unknown backend {backend!r}; one of {', '.join(BACKENDS)}")
        return backend in self.backends


#: Every drift variable, in the grammar's order (the order of terms' factors).
DRIFT_VARIABLES: tuple[DriftVariable, ...] = (
    DriftVariable("f", "Hz", "°C", "level",
                  "frequency change freq_hz - f_ref (f_ref: the thermometer at reference_c)",
                  _ALL, ("freq_hz",)),
    DriftVariable("df", "Hz/s", "°C/s", "rate",
                  "causal rate of f (two first-order stages of time constant rate_tau_s)",
                  _ALL, ("freq_hz",)),
    DriftVariable("h", "°C", "°C", "level",
                  "housing temperature change housing_c - reference_c", _ALL, ("housing_c",)),
    DriftVariable("dh", "°C/s", "°C/s", "rate",
                  "causal rate of h (the same filter as df)", _ALL, ("housing_c",)),
    DriftVariable("dpos", "Hz/s", "°C/s", "rate",
                  "heating/cooling switch: the heating part of df, df*(1 + tanh(df/delta))/2 "
                  "(delta: switch_hz_per_s)",
                  frozenset({"numpy"}), ("freq_hz",)),
    DriftVariable("d2", "Hz/s", "°C/s", "rate",
                  "causal rate of f through a second filter of time constant rate_tau2_s",
                  frozenset({"numpy", "c_double", "params"}), ("freq_hz",)),
    DriftVariable("g", "°C", "°C", "level",
                  "housing - resonator gradient housing_c - T(freq_hz), T the thermometer's "
                  "inverse", _ALL, ("freq_hz", "housing_c")),
    DriftVariable("a_NAME", "unit of its column", "unit of its column", "level",
                  "an extra logged channel (--aux NAME=COLUMN) minus its training mean",
                  frozenset({"numpy", "c_double", "params"}), ()),
)
_BY_NAME = {v.name: v for v in DRIFT_VARIABLES}
#: Prefix of the user's extra channels.
AUX_PREFIX = "a_"
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
