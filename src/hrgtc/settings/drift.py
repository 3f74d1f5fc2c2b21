"""Settings of the drift fit (stage 2b): Eq. (21)-(22) of [1] on window means.

:data:`DriftSettings` is generated: the common fields written here, and the options the
drift variables declare in their own modules (``hrgtc/drift/variables/d2.py``'s
``class Options``: ``--rate-tau2-s``). Those modules load numpy, so their declarations are
read from their text (:func:`variable_options`: the class statement run alone), which keeps
``hrgtc --help`` free of numpy (docs/architecture.md, "Adding a drift variable").

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import ast
import dataclasses
import os
import re
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from hrgtc.settings import setting

#: The nine candidate terms of Eq. (21) of [1].
EQ21_TERMS = ("f", "f^2", "f^3", "df", "df^2", "df^3", "f*df", "f^2*df", "f*df^2")
#: Default candidates when every training run logs ``housing_c``: the cubic in f of Eq. (21)
#: of [1] with the housing - resonator gradient g = housing_c - T(f) in place of df/dt (the
#: gradient is what makes the bias depend on the rate of change; measured, it carries over
#: to held-out warm-ups and cycles where the df/dt terms fitted on a cool-down do not:
#: bench/heldout_gradient.jsonl).
GRADIENT_TERMS = ("f", "f^2", "f^3", "g", "f*g", "f^2*g")
#: The second df/dt filter (``d2``) is this many times slower than the first by default.
TAU2_FACTOR = 6.0
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


#: The drift variables' modules (``hrgtc/drift/variables/``), read as text here.
VARIABLES_DIRECTORY = Path(__file__).resolve().parent.parent / "drift" / "variables"
#: Modules of that package that are not variables.
NOT_VARIABLES = frozenset({"registry", "spec"})


def variable_modules(directory: Path | str = VARIABLES_DIRECTORY) -> list[str]:
    """Names of the drift variables' modules in ``directory``, sorted (the registry's scan
    too): every ``NAME.py`` but ``_*``, ``registry`` and ``spec``."""
    names = (name[:-3] for name in os.listdir(directory) if name.endswith(".py"))
    return sorted(n for n in names if n not in NOT_VARIABLES and not n.startswith("_"))


@dataclass(frozen=True)
class Declared:
    """What this module reads of one drift variable's module, from its text.

    Attributes
    ----------
    name, order
        The literal ``name=`` and ``order=`` of its ``VARIABLE``.
    options
        Its ``class Options``, as ``(field, type, dataclasses.Field)`` (the panel, when it
        names none, the drift model's).
    """

    name: str
    order: int
    options: tuple[tuple[str, Any, Any], ...]


def _identity(path: Path, text: str) -> tuple[str, int]:
    """The literal ``name=`` and ``order=`` of the module's ``VARIABLE = DriftVariable(...)``
    (only the text from that statement on is parsed)."""
    start = text.find("\nVARIABLE = ")
    found: dict[str, Any] = {}
    if start >= 0:
        node = ast.parse(text[start + 1:], str(path)).body[0]
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call):
            found = {k.arg: ast.literal_eval(k.value) for k in node.value.keywords
                     if k.arg in ("name", "order")}
    if not (isinstance(found.get("name"), str) and isinstance(found.get("order"), int)):
        raise RuntimeError(f"{path}: a drift variable's module has a top-level VARIABLE = "
                           "DriftVariable(...) with a literal name= and order=")
    return found["name"], found["order"]


def _options(path: Path, text: str) -> tuple[tuple[str, Any, Any], ...]:
    """The ``Options`` class of one variable's module, run alone.

    Only the class statement runs, with :func:`~hrgtc.settings.setting` and the module's
    top-level constants whose values are literals (``TAU2_FACTOR = 6.0``); the module
    itself is not imported (it loads numpy).
    """
    start = text.find("\nclass Options")
    if start < 0:
        return ()
    # the text up to the class's end (the next line at the margin) holds what it may use
    end = re.search(r"\n(?=[^\s#])", text[text.index("\n", start + 1):])
    head = text if end is None else text[:text.index("\n", start + 1) + end.start()]
    try:
        tree = ast.parse(head, str(path))
    except SyntaxError:  # a line at the margin inside the class (a string): all of it
        tree = ast.parse(text, str(path))
    namespace: dict[str, Any] = {"setting": setting}
    declaration = None
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and node.name == "Options":
            declaration = node
        elif (isinstance(node, ast.Assign) and len(node.targets) == 1
              and isinstance(node.targets[0], ast.Name)):
            try:
                namespace[node.targets[0].id] = ast.literal_eval(node.value)
            except ValueError:  # not a literal: not available to the declaration
                pass
    if declaration is None:
        raise RuntimeError(f"{path}: a drift variable's options are one top-level "
                           "class Options")
    try:
        # dont_inherit: the annotations are evaluated here, in the declaration's namespace
        exec(compile(ast.Module([declaration], []), str(path), "exec", dont_inherit=True),
             namespace)
    except NameError as exc:
        raise RuntimeError(
            f"{path}: its Options declaration uses {exc.name!r}, which is not a literal "
            "constant of the module; hrgtc.settings.drift reads the declaration without "
            "importing the module, so it may use only setting(...), builtins and "
            "top-level constants such as NAME = 6.0") from None
    options = namespace["Options"]
    fields = []
    for name, kind in options.__annotations__.items():
        declared = options.__dict__.get(name)
        if not isinstance(declared, dataclasses.Field) or "help" not in declared.metadata:
            raise RuntimeError(f"{path}: Options.{name} is not a setting(...) with a help")
        meta = {**declared.metadata, "panel": declared.metadata["panel"] or _FIT}
        fields.append((name, kind, dataclasses.field(default=declared.default, metadata=meta)))
    return tuple(fields)


def declared_variables(directory: Path | str = VARIABLES_DIRECTORY) -> list[Declared]:
    """The drift variables as their modules' text declares them, in grammar order.

    Read without importing the modules (they load numpy), so that ``hrgtc --help`` stays
    quick; ``tests/drift/test_variable_settings.py`` checks that the imported modules
    declare the same.
    """
    found = []
    for module in variable_modules(directory):
        path = Path(directory) / f"{module}.py"
        text = path.read_text(encoding="utf-8")
        found.append(Declared(*_identity(path, text), _options(path, text)))
    return sorted(found, key=lambda d: d.order)


def variable_options(directory: Path | str = VARIABLES_DIRECTORY) -> list[tuple[str, Any, Any]]:
    """The options the drift variables declare (each module's ``Options``), in grammar
    order, as ``(field, type, dataclasses.Field)`` of :func:`dataclasses.make_dataclass`."""
    return [entry for d in declared_variables(directory) for entry in d.options]


_DECLARED = declared_variables()
#: The variables of the term grammar, as ``--terms``'s help lists them (a_NAME with the
#: option that maps its channels).
_GRAMMAR = ", ".join(d.name + (" (--aux)" if d.name == "a_NAME" else "") for d in _DECLARED)


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


_VARIABLE_FIELDS = [entry for d in _DECLARED for entry in d.options]
#: Names of the fields of :data:`DriftSettings` that the drift variables declare.
VARIABLE_OPTIONS = tuple(name for name, _, _ in _VARIABLE_FIELDS)

#: How the drift model is fitted: candidates, windows, stepwise thresholds, filters. A frozen
#: dataclass generated from the common fields and the options each drift variable declares
#: in its module (``Options``: ``--rate-tau2-s`` is ``d2``'s).
DriftSettings = dataclasses.make_dataclass(
    "DriftSettings", _fields(_VARIABLE_FIELDS), frozen=True,
    namespace={"__module__": __name__, "__qualname__": "DriftSettings",
               "warmup": _warmup, "variable_options": _variable_values,
               "__doc__": """How the drift model is fitted: candidates, windows, stepwise
    thresholds, filters.

    Every field is a parameter of :func:`hrgtc.drift.fit` and an option of ``hrgtc
    calibrate``; the model file's provenance records them. The options of the drift
    variables (``rate_tau2_s``, ``d2``'s) are declared in their modules
    (:func:`variable_options`) and handed to the fit together (``variable_options()``).
    """})
