"""Settings of the drift fit (stage 2b): Eq. (21)-(22) of [1] on window means.

:data:`DriftSettings` is generated: the common fields written here, and the options the
drift variables declare in :mod:`hrgtc.settings.drift_variables` (``D2Options``:
``--rate-tau2-s``), which imports only the standard library as this module does, so that
``hrgtc --help`` loads no numpy (docs/architecture.md, "Adding a drift variable").

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass
from typing import Any

from hrgtc.settings import setting
from hrgtc.settings.drift_variables import DECLARATIONS, Declaration

#: The nine candidate terms of Eq. (21) of [1].
EQ21_TERMS = ("f", "f^2", "f^3", "df", "df^2", "df^3", "f*df", "f^2*df", "f*df^2")
#: Default candidates when every training run logs ``housing_c``: the cubic in f of Eq. (21)
#: of [1] with the housing - resonator gradient g = housing_c - T(f) in place of df/dt (the
#: gradient is what makes the bias depend on the rate of change; measured, it carries over
#: to held-out warm-ups and cycles where the df/dt terms fitted on a cool-down do not:
#: bench/heldout_gradient.jsonl).
GRADIENT_TERMS = ("f", "f^2", "f^3", "g", "f*g", "f^2*g")
#: The warm-up left out of each run is this many of the longest filter time constant.
WARMUP_FACTOR = 5.0
#: A term enters the stepwise model below this p-value (MATLAB ``stepwisefit``'s default).
PENTER = 0.05
#: A term leaves the stepwise model above this p-value unless ``premove`` says otherwise
#: (``max(penter, PREMOVE_FLOOR)``, MATLAB ``stepwisefit``).
PREMOVE_FLOOR = 0.10
#: Term-selection methods of :func:`hrgtc.drift.fit`.
SELECTIONS = ("guarded", "stepwise", "cv")
#: Nuisance offsets of the drift fit (:mod:`hrgtc.drift.offsets`).
OFFSET_MODES = ("auto", "none", "run", "orientation", "run+orientation")
#: How the stepwise F-tests account for correlated window residuals.
AUTOCORRELATIONS = ("newey-west", "none")

_FIT = "Drift model"


def variable_options(
        declarations: tuple[Declaration, ...] = DECLARATIONS) -> list[tuple[str, Any, Any]]:
    """The options the drift variables declare (:mod:`hrgtc.settings.drift_variables`), in
    grammar order, as ``(field, type, dataclasses.Field)`` of
    :func:`dataclasses.make_dataclass` (the panel, when one names none, the drift model's).

    Raises
    ------
    RuntimeError
        A field of an options class is not a :func:`~hrgtc.settings.setting` with a help.
    """
    fields = []
    for declaration in declarations:
        if declaration.options is None:
            continue
        options = declaration.options
        for name, kind in typing.get_type_hints(options).items():
            declared = options.__dict__.get(name)
            if not isinstance(declared, dataclasses.Field) or "help" not in declared.metadata:
                raise RuntimeError(f"{options.__qualname__}.{name} (drift variable "
                                   f"{declaration.name}) is not a setting(...) with a help")
            meta = {**declared.metadata, "panel": declared.metadata["panel"] or _FIT}
            fields.append((name, kind, dataclasses.field(default=declared.default,
                                                         metadata=meta)))
    return fields


#: The variables of the term grammar, as ``--terms``'s help lists them (a_NAME with the
#: option that maps its channels).
_GRAMMAR = ", ".join(d.name + (" (--aux)" if d.name == "a_NAME" else "") for d in DECLARATIONS)


@dataclass(frozen=True)
class _Common:
    """The fields of :data:`DriftSettings` that are not a drift variable's (in this order,
    the variables' options after ``rate_tau_s``)."""

    terms: tuple[str, ...] | None = setting(
        None, f"Candidate drift terms, comma separated. Variables: {_GRAMMAR}.",
        default_text=f"{','.join(GRADIENT_TERMS)} (g the housing - resonator gradient) when "
        f"the runs log housing_c, else Eq. 21's {','.join(EQ21_TERMS)}", panel=_FIT)
    window_s: float = setting(10.0, "Averaging window of the fit.", unit="s", panel=_FIT)
    penter: float = setting(PENTER, "Stepwise p-value to enter.", panel=_FIT)
    premove: float | None = setting(
        None, "Stepwise p-value to remove.", default_text=f"max(--penter, {PREMOVE_FLOOR:g})",
        panel=_FIT)
    reference_c: float | None = setting(
        None, "Reference temperature of f.", unit="°C",
        default_text="the centre of the still training data, so a temperature offset does "
        "not change the model", panel=_FIT)
    rate_tau_s: float = setting(
        10.0, "Time constant of each stage of the causal df/dt filter.", unit="s", panel=_FIT)
    warmup_s: float | None = setting(
        None, "Start of each run left out while the df/dt filters settle.", unit="s",
        default_text=f"{WARMUP_FACTOR:g} × the longest filter time constant; 0 when the "
        "terms chosen use no rate (no filter to wait for)", panel=_FIT)
    select: str = setting(
        "guarded", "Term selection: guarded (F-tests, then terms that do not carry over to "
        "held-out runs, or to held-out time blocks of a single run, are dropped), stepwise "
        "(F-tests only) or cv (leave-one-run-out cross-validated bias stability; needs two "
        "training runs or more).", choices=SELECTIONS, panel=_FIT)
    offsets: str = setting(
        "auto", "Constant offsets that are nuisance parameters of the drift fit, not "
        "temperature terms: auto (one per orientation when the runs log accel_x/y/z or an "
        "orientation column, else none), none, run (one per training run: restarts), "
        "orientation, run+orientation.", choices=OFFSET_MODES, panel=_FIT)
    autocorrelation: str = setting(
        "newey-west", "Stepwise F-tests on correlated window means: divide each F by the "
        "long-run / plain variance ratio of the full candidate model's residuals "
        "(newey-west, bandwidth n^(1/3) windows: bias instability keeps 10 s means "
        "correlated, and plain F-tests admit terms that fit noise), or plain F-tests (none, "
        "MATLAB stepwisefit).", choices=AUTOCORRELATIONS, panel=_FIT)
    hierarchical: bool = setting(
        True, "Marginality: a term enters only after its lower-order parents (f before f^2, "
        "f and df before f*df) and leaves only after its children; off gives MATLAB's plain "
        "stepwisefit.", cli="--hierarchical/--no-hierarchical", panel=_FIT)


def _fields(variables: list[tuple[str, Any, Any]]) -> list[tuple[str, Any, Any]]:
    """:class:`_Common`'s fields with the variables' options after ``rate_tau_s``."""
    hints = typing.get_type_hints(_Common)
    common = [(f.name, hints[f.name], dataclasses.field(default=f.default, metadata=f.metadata))
              for f in dataclasses.fields(_Common)]
    split = [name for name, _, _ in common].index("rate_tau_s") + 1
    return [*common[:split], *variables, *common[split:]]


def _warmup(self: Any, tau2_s: float) -> float:
    """The warm-up left out of each run: ``warmup_s`` or its default, ``tau2_s`` the
    longest of the variables' own filter time constants (0: none). [s]"""
    if self.warmup_s is not None:
        return float(self.warmup_s)
    return WARMUP_FACTOR * max(self.rate_tau_s, tau2_s)


def _variable_values(self: Any) -> dict[str, Any]:
    """The values of the options the drift variables declare, by name, as
    :func:`hrgtc.drift.fit` takes them (``options=``)."""
    return {name: getattr(self, name) for name in VARIABLE_OPTIONS}


_VARIABLE_FIELDS = variable_options()
#: Names of the fields of :data:`DriftSettings` that the drift variables declare.
VARIABLE_OPTIONS = tuple(name for name, _, _ in _VARIABLE_FIELDS)

#: How the drift model is fitted: candidates, windows, stepwise thresholds, filters. A frozen
#: dataclass generated from the common fields and the options each drift variable declares
#: in :mod:`hrgtc.settings.drift_variables` (``--rate-tau2-s`` is ``d2``'s).
DriftSettings = dataclasses.make_dataclass(
    "DriftSettings", _fields(_VARIABLE_FIELDS), frozen=True,
    namespace={"__module__": __name__, "__qualname__": "DriftSettings",
               "warmup": _warmup, "variable_options": _variable_values,
               "__doc__": """How the drift model is fitted: candidates, windows, stepwise
    thresholds, filters.

    Every field is a parameter of :func:`hrgtc.drift.fit` and an option of ``hrgtc
    calibrate``; the model file's provenance records them. The options of the drift
    variables (``rate_tau2_s``, ``d2``'s) are declared in
    :mod:`hrgtc.settings.drift_variables` (:func:`variable_options`) and handed to the fit
    together (``variable_options()``).
    """})
