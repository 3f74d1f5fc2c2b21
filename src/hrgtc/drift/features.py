"""Drift-model inputs: the frequency change f, its rate df/dt, and the term grammar.

Section 4.2 of [1] models the bias from "the frequency change" f and "the
frequency change rate" df/dt (Eq. 21). Here f = freq_hz - f_ref, with f_ref the
thermometer's frequency at a reference temperature (20 °C by default), and
df/dt comes from a causal filter whose settings are stored in the model file,
so deployment computes the same numbers sample by sample as training did.

The rate filter (:mod:`hrgtc.drift.rate_filter`) is the derivative of a twice low-passed signal,
D(s) = s / (tau s + 1)^2: y1 follows f through the exact update of a first-order lag
over each step's own Δt (the samples' times, so jittered clocks, bursts and gaps
are handled: a gap is bridged with its Δt), y2 follows y1 likewise, and the rate
is (y1 - y2) / tau. Two state variables per input, no differencing of noisy
samples; the response to a ramp is exactly its slope once settled, whatever the
steps; the group delay at low frequency is 2 tau.

Variables of the grammar (all relative to the reference point):

=========  ====================================================  ========
name       meaning                                                unit
=========  ====================================================  ========
``f``      frequency change freq_hz - f_ref                       Hz
``df``     causal rate of ``f``                                   Hz/s
``h``      housing temperature change housing_c - reference_c     °C
``dh``     causal rate of ``h``                                   °C/s
``dpos``   heating part of ``df``: df·(1 + tanh(df/δ))/2          Hz/s
``d2``     causal rate of ``f`` through a second, slower filter   Hz/s
``g``      housing - resonator gradient housing_c - T(f)          °C
``a_NAME`` a logged channel the user maps (``--aux NAME=COLUMN``) its unit
=========  ====================================================  ========

``d2`` is the rate filter of ``df`` with its own time constant
(``FeatureSettings.rate_tau2_s``), so a fit can mix a fast and a slow rate (a
thermal lag between the resonator and the part of the gyro whose temperature
drives the bias). ``g`` needs the unit's thermometer (T(f), Eq. 18 of [1]
inverted) and a housing thermistor; :class:`FeatureStream` takes the thermometer.
``a_NAME`` is the mapped column minus its training mean (``aux_centres``), the
column's name stored in ``aux_columns``; compensation reads the same column.

``dpos`` is a smooth switch between heating (df > 0: dpos ≈ df) and cooling
(dpos ≈ 0), so ``df`` + ``dpos`` give heating and cooling their own rate
coefficients (HRG drift differs between the two: Li et al., Sci. Rep. 13:6019,
2023); δ (``FeatureSettings.switch_hz_per_s``) is set in training from the
spread of the training df/dt. It is computed by the numpy compensator only:
the fused kernel falls back to numpy and ``export_c`` refuses such a model.

A term is a product of powers: ``f``, ``f^2``, ``f*df``, ``f^2*df``, ``h^3``.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, make_dataclass
from typing import Annotated, Any

import msgspec
import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.drift.rate_filter import (  # noqa: F401  (re-exported: imported from here)
    RateFilterState,
    causal_rate,
    rate_filter_coefficients,
    restart_mask,
)
from hrgtc.drift.variables import AUX_PREFIX, DRIFT_VARIABLES, FIXED, Inputs
from hrgtc.drift.variables import settings_fields as variable_settings_fields
from hrgtc.drift.variables import variable as _registered
from hrgtc.drift.variables.aux import centre as _aux_centre
from hrgtc.drift.variables.dpos import (  # noqa: F401  (re-exported)
    SWITCH_FRACTION,
    heating_part,
)
from hrgtc.recording.schema import Recording
from hrgtc.settings.drift import EQ21_TERMS as _EQ21_TERMS
from hrgtc.settings.drift import DriftSettings

#: Variable name -> (unit, description), from the one list of :mod:`hrgtc.drift.variables`.
VARIABLES: dict[str, tuple[str, str]] = {
    v.name: (v.unit, v.description) for v in DRIFT_VARIABLES if v.name in FIXED}
#: Variables that are levels (checked against the calibrated/training range as ``in_range``)
#: and rates of change (``rate_in_range``); ``a_NAME`` channels are levels too.
LEVEL_VARIABLES = tuple(v for v in FIXED if _registered(v).kind == "level")
RATE_VARIABLES = tuple(v for v in FIXED if _registered(v).kind == "rate" and v != "dpos")
#: An extra channel's name (the part after ``a_``): a letter, then letters and digits.
AUX_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9]*$")
_TERM_FACTOR = re.compile(
    r"^\s*([a-z][a-z0-9]*|a_[A-Za-z][A-Za-z0-9]*)\s*(?:\^\s*(\d+))?\s*$")


def is_aux(variable: str) -> bool:
    """Whether ``variable`` is a user's extra channel ``a_NAME``."""
    return variable.startswith(AUX_PREFIX) and bool(AUX_NAME.match(variable[len(AUX_PREFIX):]))


def is_variable(variable: str) -> bool:
    """Whether ``variable`` belongs to the grammar (a fixed variable or an ``a_NAME``)."""
    return variable in VARIABLES or is_aux(variable)


def variable_key(variable: str) -> tuple[int, str]:
    """Canonical order of variables: the fixed ones in :data:`VARIABLES` order, then a_NAME."""
    order = list(VARIABLES)
    return (order.index(variable), "") if variable in VARIABLES else (len(order), variable)


def variable_unit(variable: str) -> str:
    """Unit of a variable (an extra channel's is its column's, unknown here)."""
    return VARIABLES[variable][0] if variable in VARIABLES else "aux"


# -- terms ---------------------------------------------------------------------------
@dataclass(frozen=True)
class Term:
    """A product of powers of variables, e.g. ``f^2*df``.

    Attributes
    ----------
    powers
        ((variable, power), ...) in canonical variable order.
    """

    powers: tuple[tuple[str, int], ...]

    @property
    def name(self) -> str:
        """Canonical text, e.g. ``f^2*df``."""
        return "*".join(v if p == 1 else f"{v}^{p}" for v, p in self.powers)

    @property
    def variables(self) -> tuple[str, ...]:
        return tuple(v for v, _ in self.powers)

    @property
    def unit(self) -> str:
        """Unit of the term's value, e.g. ``Hz^2·Hz/s`` (a resonator thermometer's)."""
        return self.unit_for("resonator")

    def unit_for(self, thermometer_source: str = "resonator") -> str:
        """Unit of the term's value for a model whose thermometer is ``"resonator"``
        (``Hz^2·Hz/s``) or ``"sensor"`` (f is T in °C: ``(°C)^2·°C/s``)."""
        parts = []
        for v, p in self.powers:
            unit = (variable_unit(v) if v not in VARIABLES or thermometer_source != "sensor"
                    else _registered(v).unit_for(thermometer_source))
            parts.append(unit if p == 1 else f"({unit})^{p}")
        return "·".join(parts)

    def evaluate(
        self,
        values: Mapping[str, np.ndarray],
        powers: dict[tuple[str, int], np.ndarray] | None = None,
    ) -> np.ndarray:
        """The term's value from variable arrays.

        ``powers`` is an optional cache of x**p shared between terms (products,
        not ``**``: both faster and exact for small integer powers).
        """
        cache = {} if powers is None else powers
        out = None
        for v, p in self.powers:
            factor = _power(values, v, p, cache)
            out = factor if out is None else out * factor
        assert out is not None
        return out

    def parents(self) -> tuple[Term, ...]:
        """The terms one power lower, e.g. ``f^2*df`` -> ``f*df``, ``f^2``."""
        out = []
        for k, (v, p) in enumerate(self.powers):
            powers = list(self.powers)
            if p == 1:
                del powers[k]
            else:
                powers[k] = (v, p - 1)
            if powers:
                out.append(Term(tuple(powers)))
        return tuple(out)

    def derivative(self, variable: str) -> tuple[int, Term | None]:
        """d(term)/d(variable) as ``(multiplier, term)``; term None means the constant 1.

        Returns ``(0, None)`` when the term does not contain the variable.
        """
        power = self.power_of(variable)
        if power == 0:
            return 0, None
        rest = tuple((v, p - 1 if v == variable else p) for v, p in self.powers)
        rest = tuple((v, p) for v, p in rest if p > 0)
        return power, (Term(rest) if rest else None)

    def power_of(self, variable: str) -> int:
        """Power of ``variable`` in the term (0 when absent)."""
        return dict(self.powers).get(variable, 0)

    def scale_factor(self, scales: Mapping[str, float]) -> float:
        """prod(scale_v ** p): a term of scaled variables times this is the raw term."""
        return math.prod(scales[v] ** p for v, p in self.powers)

    def __str__(self) -> str:
        return self.name


def _power(values: Mapping[str, np.ndarray], variable: str, power: int,
           cache: dict[tuple[str, int], np.ndarray]) -> np.ndarray:
    if power == 1:
        return values[variable]
    key = (variable, power)
    if key not in cache:
        cache[key] = _power(values, variable, power - 1, cache) * values[variable]
    return cache[key]


def parse_term(text: str) -> Term:
    """Parse ``"f^2*df"`` into a :class:`Term`.

    Examples
    --------
    >>> parse_term("df * f^2").name
    'f^2*df'
    """
    if not isinstance(text, str) or not text.strip():
        raise InputError(f"empty term {text!r}; write terms like 'f', 'f^2', 'f*df'")
    powers: dict[str, int] = {}
    for factor in text.split("*"):
        match = _TERM_FACTOR.match(factor)
        if match is None:
            raise InputError(
                f"cannot read term {text!r} at {factor.strip()!r}; write products of powers "
                "like 'f^2*df'"
            )
        name, power = match.group(1), int(match.group(2) or 1)
        if not is_variable(name):
            raise InputError(
                f"unknown variable {name!r} in term {text!r}; known: {', '.join(VARIABLES)} "
                "and a_NAME for a channel mapped with --aux NAME=COLUMN"
            )
        if power < 1:
            raise InputError(f"power must be at least 1 in term {text!r}")
        powers[name] = powers.get(name, 0) + power
    return Term(tuple(sorted(powers.items(), key=lambda item: variable_key(item[0]))))


def parse_terms(texts: Iterable[str]) -> tuple[Term, ...]:
    """Parse several terms; duplicates are an error."""
    terms = tuple(parse_term(t) for t in texts)
    names = [t.name for t in terms]
    duplicates = sorted({n for n in names if names.count(n) > 1})
    if duplicates:
        raise InputError(f"term(s) listed twice: {', '.join(duplicates)}")
    if not terms:
        raise InputError("no terms given")
    return terms


class ParsedTerms:
    """Mixin of the frozen dataclasses that hold ``selected`` term texts and a ``_terms``
    field (the drift and scale-factor models): the texts are parsed once, at
    construction, into :attr:`terms`."""

    selected: tuple[str, ...]
    _terms: tuple[Term, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "_terms", parse_terms(self.selected) if self.selected else ())

    @property
    def terms(self) -> tuple[Term, ...]:
        """The selected terms, parsed (in ``selected`` order)."""
        return self._terms


#: Eq. (21) of [1]: the nine candidate terms of the drift model, f = frequency
#: change, df = its rate of change df/dt.
EQ21_TERMS = _EQ21_TERMS
#: The nine candidate terms of Eq. (21) of [1], parsed.
EQ21 = parse_terms(EQ21_TERMS)


def hierarchy(terms: Sequence[Term]) -> dict[str, list[str]]:
    """Term name -> names of its parents among ``terms`` (the marginality principle)."""
    names = {t.name for t in terms}
    return {t.name: [p.name for p in t.parents() if p.name in names] for t in terms}


def required_columns(terms: Sequence[Term]) -> tuple[str, ...]:
    """Recording columns the terms need (``freq_hz`` and/or ``housing_c``; not a_NAME's)."""
    needed: list[str] = []
    for term in terms:
        for v in term.variables:
            needed.extend(c for c in _registered(v).columns if c not in needed)
    return tuple(needed)


# -- feature settings and computation ---------------------------------------------------
class _FeatureSettingsMethods(records.Written):
    """What :class:`FeatureSettings` does beyond holding its fields (``to_dict``/``from_dict``
    by its record, :data:`FeatureSettingsRecord`, generated from them)."""

    __slots__ = ()
    reference_freq_hz: float
    sample_rate_hz: float


#: The settings every model has, as fields of :func:`dataclasses.make_dataclass`.
_COMMON_SETTINGS: tuple[tuple[str, Any] | tuple[str, Any, Any], ...] = (
    # A sensor thermometer reads °C in the place of f: any finite reference.
    ("reference_freq_hz", float),
    ("sample_rate_hz", records.Positive),
    ("reference_c", float, 20.0),
    ("rate_tau_s", records.Positive, DriftSettings.rate_tau_s),
    ("warmup_s", records.NonNegative, 600.0),
    ("scales", dict[str, records.Positive], field(default_factory=dict)),
)
#: The type of msgspec's ``field(default_factory=...)`` (``records.empty()``).
_MSGSPEC_FIELD = type(msgspec.field())

_FEATURE_SETTINGS_DOC = """Everything needed to compute the drift-model variables from a recording.

    A frozen dataclass generated from the settings every model has and those the drift
    variables own (each variable's ``settings_fields`` in :mod:`hrgtc.drift.variables`), so
    a variable's setting is declared once, in its module (as :data:`FeatureSettingsRecord`,
    the model file's record, is).

    Attributes
    ----------
    reference_freq_hz
        f_ref: frequency at the reference temperature. [Hz]
    reference_c
        Reference temperature (also the origin of ``h``). [°C]
    sample_rate_hz
        Sample rate of the (first) training run, for the C export's fixed-rate filter
        and its settling count. Python's compensation does not depend on it: the settling
        time is in seconds on the time axis and the rate filter steps over each sample's
        own Δt, so a model applies to a recording at any rate (a real clock drifts by
        tenths of a percent between runs). [Hz]
    rate_tau_s
        Time constant of each stage of the rate filter. [s]
    warmup_s
        Start of each run discarded in training while the filter settles. [s]
    scales
        Variable -> scale used internally so every variable is of order one.
"""


def _variable_setting(name: str, kind: Any, default: Any) -> tuple[str, Any, Any]:
    """A variable's ``(field, type, default)`` as a dataclass field (a msgspec
    ``default_factory`` becomes the dataclass's)."""
    if isinstance(default, _MSGSPEC_FIELD):
        return (name, kind, field(default_factory=default.default_factory))
    return (name, kind, field(default=default))


def _feature_settings_doc() -> str:
    """The docstring, with a line for each setting a variable owns (its variable's)."""
    lines = [_FEATURE_SETTINGS_DOC.rstrip("\n")]
    for v in DRIFT_VARIABLES:
        for name, _, _ in v.settings_fields:
            lines += [f"    {name}", f"        A setting of ``{v.name}``: {v.description}."]
    return "\n".join(lines) + "\n    "


#: Everything needed to compute the drift-model variables from a recording: the common
#: settings, then those the variables own, in grammar order (their modules' fields).
FeatureSettings = make_dataclass(
    "FeatureSettings",
    [*_COMMON_SETTINGS, *(_variable_setting(*entry) for entry in variable_settings_fields())],
    bases=(_FeatureSettingsMethods,), frozen=True,
    namespace={"__module__": __name__, "__qualname__": "FeatureSettings",
               "__doc__": _feature_settings_doc(),
               "required": ("reference_c", "rate_tau_s", "warmup_s"),  # in every file
               # a variable added after model files were written: only when not its default
               "omit_when_default": tuple(name for v in DRIFT_VARIABLES
                                          if v.omit_default_settings
                                          for name, _, _ in v.settings_fields)})


#: A drift term as the model file writes it (``f^2*df``, ``a_drive``); parsed on loading.
_VARIABLE = r"(?:[a-z][a-z0-9]*|a_[A-Za-z][A-Za-z0-9]*)"
TermName = Annotated[str, Meta(pattern=rf"^{_VARIABLE}(\^[0-9]+)?(\*{_VARIABLE}(\^[0-9]+)?)*$")]


#: :class:`FeatureSettings` in a file (the drift model's ``settings``), generated from its
#: fields: the settings every model has, then those the drift variables own.
FeatureSettingsRecord = records.record_of(
    FeatureSettings, "FeatureSettingsRecord",
    ":class:`FeatureSettings` in a file (the drift model's ``settings``).")


def settle_rows(settings: FeatureSettings) -> int:
    """Samples in the first ``warmup_s`` of a continuous run (the C export's count).

    Training skips the first ``warmup_s`` seconds (5 tau by default) after the filter
    (re)starts, on the time axis; the compensator flags them (``in_range`` 0) and the
    evaluation leaves them out of its figures, the same way, in seconds (a burst file's
    gaps count as the time they last). On a continuous file this many samples. The filter
    starts at rest on the first sample, whose noise then reads as a rate for a few tau.
    """
    return max(round(settings.warmup_s * settings.sample_rate_hz), 0)


class FeatureStream:
    """Sample-by-sample computation of the grammar's variables over consecutive chunks of one run.

    The batch computation is "reset, then one chunk", so any chunking gives
    the same numbers (to rounding of the filter's state hand-over).

    Parameters
    ----------
    settings
        How the variables are computed.
    variables
        Variables to compute.
    thermometer
        The unit's thermometer (anything with ``temperature(freq_hz, warn=False)``);
        needed for the gradient ``g`` only.
    """

    def __init__(self, settings: FeatureSettings, variables: Iterable[str] = ("f", "df"),
                 thermometer: Any = None):
        self.settings = settings
        self.variables = tuple(variables)
        self.thermometer = thermometer
        unknown = [v for v in self.variables if not is_variable(v)]
        if unknown:
            raise InputError(f"unknown variable(s) {unknown}; known: {', '.join(VARIABLES)} "
                             "and a_NAME")
        self._check()
        self.reset()

    def _check(self) -> None:
        for v in self.variables:  # what each variable needs (its module's check)
            missing = _registered(v).check(self.settings, self.thermometer, v)
            if missing is not None:
                raise InputError(missing)

    def reset(self) -> None:
        """Forget the filter state (start of a new run)."""
        self._states: dict[str, RateFilterState] = {}
        self._memory: dict[str, Any] = {}  # the remembering variables' state (the play's)
        self.samples_seen = 0

    def _rate(self, key: str, level: np.ndarray, tau_s: float, time_s: np.ndarray,
              restart: np.ndarray | None) -> np.ndarray:
        rate, _, self._states[key] = causal_rate(level, tau_s, state=self._states.get(key),
                                                 time_s=time_s, restart=restart)
        return rate

    def transform(self, chunk: Recording, restart: np.ndarray | None = None
                ) -> dict[str, np.ndarray]:
        """Variables of the next chunk of the run, keyed by variable name.

        Each step of the rate filters uses its own Δt from ``chunk.time_s`` (a gap is
        bridged with the gap's Δt); ``restart`` (a boolean mask of the chunk's rows,
        e.g. the segment starts of ``--gaps split``) starts them at rest on those rows.
        """
        time_s = chunk.time_s
        # each variable's numpy reference (its module's compute), sharing levels and filters
        inputs = Inputs(chunk, self.settings, self.thermometer, _registered,
                        lambda key, level, tau: self._rate(key, level, tau, time_s, restart),
                        self._memory, restart)
        out = {v: inputs.value(v) for v in self.variables}
        self.samples_seen += len(chunk)
        return out


def aux_centre(settings: FeatureSettings, name: str) -> float:
    """Training mean of the extra channel ``name`` (0 before it is known). [column unit]"""
    return _aux_centre(settings, name)


def compute_variables(
    recording: Recording, settings: FeatureSettings, variables: Iterable[str] = ("f", "df"),
    thermometer: Any = None,
) -> dict[str, np.ndarray]:
    """Batch form of :class:`FeatureStream`: the variables of a whole run."""
    return FeatureStream(settings, variables, thermometer).transform(recording)


def linear_combination(
    terms: Sequence[Term],
    coefficients: Sequence[float],
    values: Mapping[str, np.ndarray],
    scales: Mapping[str, float],
    intercept: float = 0.0,
) -> np.ndarray:
    """intercept + sum_k c_k term_k(values / scales), without building the design matrix."""
    scaled = {v: values[v] / scales[v] for v in variables_for(terms)}
    n = next(iter(values.values())).shape[0]
    out = np.full(n, intercept, dtype=np.float64)
    cache: dict[tuple[str, int], np.ndarray] = {}
    for term, c in zip(terms, coefficients, strict=True):
        out += c * term.evaluate(scaled, cache)
    return out


def tangent_extension(
    terms: Sequence[Term],
    coefficients: Sequence[float],
    values: Mapping[str, np.ndarray],
    scales: Mapping[str, float],
    ranges: Mapping[str, tuple[float, float]],
    intercept: float = 0.0,
) -> np.ndarray:
    """The model inside the ranges, continued along its tangent plane outside them.

    Each variable is held at the edge of its range, the model evaluated there,
    and its first-order Taylor term added: B(c) + sum_v dB/dv(c) (v - c). Inside the
    ranges this is exactly :func:`linear_combination`; outside, a law linear in a
    variable is still exact while cubic terms no longer run away.
    """
    used = variables_for(terms)
    held = {v: (np.clip(values[v], *ranges[v]) if v in ranges else values[v]) for v in used}
    out = linear_combination(terms, coefficients, held, scales, intercept)
    outside = {v: values[v] - held[v] for v in used if v in ranges}
    if not any(np.any(d != 0.0) for d in outside.values()):
        return out
    scaled = {v: held[v] / scales[v] for v in used}
    cache: dict[tuple[str, int], np.ndarray] = {}
    for v, delta in outside.items():
        gradient = np.zeros_like(delta)
        for term, c in zip(terms, coefficients, strict=True):
            multiplier, rest = term.derivative(v)
            if multiplier:
                factor = c * multiplier / scales[v]
                gradient += factor if rest is None else factor * rest.evaluate(scaled, cache)
        out += gradient * delta
    return out


def variables_for(terms: Sequence[Term]) -> tuple[str, ...]:
    """Variables the terms use, in grammar order (a_NAME last, by name)."""
    return tuple(sorted({v for t in terms for v in t.variables}, key=variable_key))


def design_matrix(
    terms: Sequence[Term],
    values: Mapping[str, np.ndarray],
    scales: Mapping[str, float] | None = None,
) -> np.ndarray:
    """Columns of term values, on scaled variables when ``scales`` is given.

    Returns
    -------
    numpy.ndarray
        Shape (n_samples, n_terms), float64.
    """
    if scales:
        values = {v: values[v] / scales[v] for v in variables_for(terms)}
    cache: dict[tuple[str, int], np.ndarray] = {}
    columns = [np.asarray(t.evaluate(values, cache), dtype=np.float64) for t in terms]
    n = next(iter(values.values())).shape[0] if values else 0
    return np.column_stack(columns) if columns else np.empty((n, 0))
