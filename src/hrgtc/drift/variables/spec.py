"""What one drift variable declares: the entry type of the registry, and what its code reads.

Each variable of the term grammar is one module of :mod:`hrgtc.drift.variables` that builds
one :class:`DriftVariable`: its name, units, kind and docs line, the backends that compute
it, its numpy reference (``compute``: how it is made from the recording's columns, the
settings and the other variables), what it needs of the settings (``check``), the
settings it owns in the model file (``settings_fields``: their types, bounds and defaults,
from which the model file's record and JSON Schema are generated), where the fit gives
them their values (``derive`` from the fit's options, ``first_pass`` from the training
runs; a command-line option of its own is declared in
:mod:`hrgtc.settings.drift_variables`),
and, for the variables beyond the paper's f, df, h and dh, its pieces of the C export
(``c_code``, in double and in float32) and its keys of the parameter file (``params``).
The registry (:mod:`hrgtc.drift.variables.registry`)
collects the modules; every consumer reads the entries from it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

#: The backends: the numpy reference, the fused numba kernel, the C export in double and
#: in float32, the plain parameter file.
BACKENDS = ("numpy", "numba", "c_double", "c_float32", "params")


class Inputs:
    """What a variable's numpy reference reads for one chunk of a run.

    Parameters
    ----------
    chunk
        The chunk (a :class:`~hrgtc.recording.Recording`: ``chunk[column]``, ``time_s``).
    settings
        The feature settings (:class:`hrgtc.drift.features.FeatureSettings`).
    thermometer
        The unit's thermometer, or None.
    lookup
        Variable name -> its :class:`DriftVariable` (the registry's ``variable``).
    rate
        ``rate(key, level, tau_s)``: the stream's causal rate filter ``key`` (its state
        carried across chunks) run over the level's values. [unit/s]
    memory
        The stream's own state of the variables that remember (the play's output), by
        key, carried across the chunks of one run and emptied at its start; None: a new one.
    restart
        Boolean mask of the chunk's rows where the stream restarts (a segment start), or
        None.
    """

    def __init__(self, chunk: Any, settings: Any, thermometer: Any,
                 lookup: Callable[[str], DriftVariable],
                 rate: Callable[[str, np.ndarray, float], np.ndarray],
                 memory: dict[str, Any] | None = None, restart: np.ndarray | None = None):
        self.chunk, self.settings, self.thermometer = chunk, settings, thermometer
        self.memory: dict[str, Any] = {} if memory is None else memory
        self.restart = restart
        self._lookup, self._rate = lookup, rate
        self._values: dict[str, np.ndarray] = {}
        self._rates: dict[str, np.ndarray] = {}

    def value(self, name: str) -> np.ndarray:
        """Variable ``name`` of this chunk (computed once, then shared)."""
        if name not in self._values:
            self._values[name] = self._lookup(name).compute(self, name)
        return self._values[name]

    def rate(self, level: str, tau_s: float, key: str) -> np.ndarray:
        """Causal rate of the variable ``level`` by the filter ``key`` (computed once)."""
        if key not in self._rates:
            self._rates[key] = self._rate(key, self.value(level), tau_s)
        return self._rates[key]


class CCode(Protocol):
    """The C pieces of a variable beyond f, df, h and dh (see :mod:`hrgtc.export.c.variables`).

    ``ctype`` is the export's floating type (``ctype.name`` is ``double`` or ``float``,
    ``ctype.literal(value, what)`` prints a constant), ``double`` the double type (for the
    constants a float build keeps in double), ``name`` the variable's spelling
    (``a_drive``), ``prefix`` the export's, ``comment`` makes text safe in a C comment.
    """

    def pieces(self, ctype: Any, double: Any, name: str, settings: Any, prefix: str,
               comment: Callable[[Any], str]) -> dict[str, str]:
        """Text of (some of) the slots ``constants``, ``state``, ``reset``, ``start``,
        ``values``, ``rate`` (each filter step), ``gradient`` (after the temperature) and
        ``bias`` (the argument of ``bias_dph()``); a slot left out is empty."""

    def inputs(self, name: str) -> tuple[str, ...]:
        """Inputs of ``step()`` it reads beyond freq_hz and rate_dph (``housing_c``)."""

    def parameter(self, name: str) -> str:
        """Its parameter of ``bias_dph()`` (``d2_hz_per_s``)."""

    def readme(self, name: str, settings: Any) -> str:
        """Its line of THE MODEL in the generated header's README block."""

    def firmware_value(self, value: np.ndarray, name: str, settings: Any) -> np.ndarray:
        """The float32 value the float build computes where the double model has ``value``
        (the float mirror's input, :mod:`hrgtc.export.c.float32`)."""


#: ``put(key, value, comment)``: writes one ``key = value`` line of the parameter file,
#: with its ``#`` comment above it.
Put = Callable[[str, Any, str], None]


#: ``derive(names, given)``: the feature settings a variable takes from the fit's options.
#: ``names`` are the candidates' variables of this entry (``a_drive``, ``a_tilt``),
#: ``given`` the fit's options by name: ``rate_tau_s``, ``aux_columns`` (``--aux``) and
#: the options the variables declare (:mod:`hrgtc.settings.drift_variables`: ``rate_tau2_s``).
Derive = Callable[[tuple[str, ...], Mapping[str, Any]], dict[str, Any]]


@dataclass(frozen=True)
class FirstPass:
    """Feature settings a variable learns from a first pass over the training runs.

    Attributes
    ----------
    reads
        ``reads(names)``: the variables whose training window means it needs (``df``
        for dpos's switch, the channels themselves for their centres).
    derive
        ``derive(names, means)``: the settings, from those window means (variable ->
        its windows' means over every run).
    """

    reads: Callable[[tuple[str, ...]], tuple[str, ...]]
    derive: Callable[[tuple[str, ...], Mapping[str, np.ndarray]], dict[str, Any]]


def _nothing(settings: Any, thermometer: Any, name: str) -> str | None:
    return None


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
        The docs line: what the variable is (ASCII: it goes into C comments).
    backends
        Where it is computed (see :data:`BACKENDS`).
    columns
        Recording columns it reads (``a_NAME``: the mapped column, not named here).
    compute
        The numpy reference: ``compute(inputs, name)`` -> its values over a chunk.
    check
        ``check(settings, thermometer, name)`` -> what is missing to compute it, or None.
    settings_fields
        The feature settings it owns, as ``(field, type, default)`` of the model file's
        record (:class:`hrgtc.drift.features.FeatureSettingsRecord` is generated with them,
        and so its JSON Schema).
    c_code
        Its C pieces (:class:`CCode`), for a variable beyond f, df, h and dh.
    order
        Position in the grammar (the order of a term's factors).
    rate_of
        For a plain causal rate: (the level it is the rate of, the settings field of the
        filter's time constant), e.g. ``("f", "rate_tau2_s")`` for d2.
    params
        Its keys of the parameter file (``hrgtc export-c --format params``), for a variable
        beyond f, df, h and dh: ``params(names, settings, put)`` writes them with ``put``
        (:data:`Put`), ``names`` the model's variables of this entry (``a_drive``,
        ``a_tilt``: every extra channel at once), called once per model in grammar order.
    derive
        Where the fit takes its settings' values from the fit's options (:data:`Derive`):
        d2's ``rate_tau2_s`` from ``--rate-tau2-s``. Called by
        :func:`hrgtc.drift.fit` for each variable the candidates use, before the warm-up
        is known (the longest of ``rate_tau_s`` and the derived time constants of the
        ``rate_of`` variables sets it).
    first_pass
        What it learns from a first pass over the runs (:class:`FirstPass`): dpos's
        ``switch_hz_per_s``, the extra channels' ``aux_centres``; one pass serves every
        variable that has one.
    omit_default_settings
        Its settings are written to the model file only when they differ from their
        defaults (a variable added after model files were written: those files, and the
        models that do not use it, keep their text and hash).
    """

    name: str
    unit: str
    sensor_unit: str
    kind: str
    description: str
    backends: frozenset[str]
    columns: tuple[str, ...]
    compute: Callable[[Inputs, str], np.ndarray]
    order: int
    check: Callable[[Any, Any, str], str | None] = _nothing
    settings_fields: tuple[tuple[str, Any, Any], ...] = ()
    c_code: CCode | None = None
    rate_of: tuple[str, str] | None = None
    params: Callable[[tuple[str, ...], Any, Put], None] | None = None
    derive: Derive | None = None
    first_pass: FirstPass | None = None
    omit_default_settings: bool = False

    def unit_for(self, thermometer_source: str = "resonator") -> str:
        """The unit for a model whose thermometer is ``"resonator"`` or ``"sensor"``."""
        return self.sensor_unit if thermometer_source == "sensor" else self.unit

    def supports(self, backend: str) -> bool:
        """Whether ``backend`` computes this variable."""
        if backend not in BACKENDS:
            raise ValueError(f"unknown backend {backend!r}; one of {', '.join(BACKENDS)}")
        return backend in self.backends


#: Every backend.
ALL = frozenset(BACKENDS)
