"""The typed parameters of every stage: frozen dataclasses, each default written once.

Each stage's tunable parameters are one frozen dataclass here, and each field carries
its default, its help text, its unit and its command-line option in the field's
metadata (:func:`setting`). From these fields

* the library takes its defaults (``recording.ReadOptions`` is
  :class:`~hrgtc.settings.reading.ReadSettings` with its methods;
  ``drift.fit`` and ``calibration.calibrate`` take
  :class:`~hrgtc.settings.drift.DriftSettings` and
  :class:`~hrgtc.settings.calibration.CalibrationSettings`);
* the command line generates its options (``hrgtc.cli.params``), so ``--help``
  shows the same default;
* the docs' option tables are generated (``python -m hrgtc.cli.params``), and a fresh
  model file records the same values in its provenance.

The modules import nothing but the standard library (no numpy), so that ``hrgtc
--help`` can build its options without loading the stages. Adding a parameter is one
field in one of these classes (docs/architecture.md, "Adding a parameter").

* :mod:`hrgtc.settings.reading` -- reading a user's files (``--gaps``, ``--spikes``, ...);
* :mod:`hrgtc.settings.drift` -- the drift fit (``--window-s``, ``--rate-tau-s``, ...);
* :mod:`hrgtc.settings.calibration` -- the calibration chain (thermometer order, plateau
  finder, soaks in the drift fit, scale-factor terms, cross-axis terms) and its drift fit;
* :mod:`hrgtc.settings.inputs` -- what calibration is given beside its recordings (``--aux``,
  the ``--temp-ref`` log, the ``--holdout-*`` end of the drift file);
* :mod:`hrgtc.settings.compensation` -- compensation chunks, the evaluation's deviation
  curve, the report's points;
* :mod:`hrgtc.settings.export` -- the firmware export (prefix, precision, format);
* :mod:`hrgtc.settings.fleet` -- the simulated fleet, its evaluation and the demo.
"""

from __future__ import annotations

import dataclasses
from typing import Any, TypedDict, Unpack

__all__ = ["Setting", "Shown", "build", "format_value", "setting", "settings_of", "to_dict"]


class Shown(TypedDict, total=False):
    """What the command line and docs say of a setting besides its help (see :func:`setting`)."""

    unit: str | None
    cli: str | None
    choices: tuple[str, ...] | None
    default_text: str | None
    metavar: str | None
    panel: str | None
    min: float | None
    max: float | None
    multiple: bool


#: What :func:`setting` assumes of what it is not told.
_SHOWN_DEFAULTS: Shown = {"unit": None, "cli": "", "choices": None, "default_text": None,
                          "metavar": None, "panel": None, "min": None, "max": None,
                          "multiple": False}


def setting(default: Any, help: str, **shown: Unpack[Shown]) -> Any:
    """A dataclass field with its default and what the command line and docs say of it.

    Parameters
    ----------
    default
        The default, written here once. A tuple for sequences (frozen dataclasses).
    help
        One sentence or two: what the parameter does (without the default or the unit:
        both are added where shown).
    unit
        Unit of the value (``"s"``, ``"°C"``), shown in brackets; None: no unit.
    cli
        The command-line option (``"--rate-tau-s"``); ``""``: ``--`` and the field's name
        with ``-`` for ``_``; None: the field is not an option.
    choices
        The values a text parameter takes (the option shows and checks them).
    default_text
        What the default means when it is None (``"6 × --rate-tau-s"``), shown in
        place of the value.
    metavar, panel
        The option's metavar and its ``--help`` panel.
    min, max
        The smallest and largest value a number takes (inclusive; None: unbounded): the
        option refuses a value outside, naming the range, and the docs list it.
    multiple
        A tuple field whose option is given once per item (``--aux a=x --aux b=y``), not
        comma separated; its default is ``()``.
    """
    unknown = set(shown) - set(_SHOWN_DEFAULTS)
    if unknown:
        raise TypeError(f"setting() got unknown keywords {sorted(unknown)}")
    meta = {"help": help, **_SHOWN_DEFAULTS, **shown}
    return dataclasses.field(default=default, metadata=meta)


@dataclasses.dataclass(frozen=True)
class Setting:
    """One parameter as shown to users: the field of a settings class, flattened.

    ``path`` is the chain of field names from the outer settings class (nested settings
    classes are flattened, ``("drift", "rate_tau_s")``).
    """

    path: tuple[str, ...]
    default: Any
    help: str
    unit: str | None
    option: str | None
    choices: tuple[str, ...] | None
    default_text: str | None
    metavar: str | None
    panel: str | None
    type: Any
    min: float | None = None
    max: float | None = None
    multiple: bool = False

    @property
    def name(self) -> str:
        """The field's own name (the last of ``path``)."""
        return self.path[-1]

    def shown_default(self) -> str:
        """The default as ``--help`` and the docs show it."""
        if self.default_text is not None:
            return self.default_text
        return format_value(None if self.default == () else self.default)

    def range_text(self) -> str | None:
        """The values a number takes (``"≥ 1"``, ``"0 to 1"``), None when unbounded."""
        if self.min is not None and self.max is not None:
            return f"{self.min:g} to {self.max:g}"
        if self.min is not None:
            return f"≥ {self.min:g}"
        if self.max is not None:
            return f"≤ {self.max:g}"
        return None

    def full_help(self) -> str:
        """The help with the unit in brackets before its last full stop (``Averaging window
        of the fit [s].``), without the default."""
        text = self.help
        if self.unit:
            text = (text[:-1] + f" [{self.unit}]." if text.endswith(".")
                    else f"{text} [{self.unit}]")
        return text


def format_value(value: Any) -> str:
    """A default as text: a tuple of terms comma separated, None as "none"."""
    if isinstance(value, tuple):
        return ",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value)
    if value is None:
        return "none"
    if isinstance(value, bool):
        return str(value).lower()
    return str(value)


def settings_of(cls: type, prefix: tuple[str, ...] = ()) -> list[Setting]:
    """Every parameter of a settings class, nested settings classes flattened, in order.

    Fields whose metadata has no ``help`` are not parameters (derived values).
    """
    import typing

    hints = typing.get_type_hints(cls)
    out: list[Setting] = []
    for field in dataclasses.fields(cls):
        kind = hints[field.name]
        if dataclasses.is_dataclass(kind):
            out.extend(settings_of(kind, (*prefix, field.name)))  # type: ignore[arg-type]
            continue
        meta = field.metadata
        if "help" not in meta:
            continue
        cli = meta["cli"]
        option = None if cli is None else (cli or "--" + field.name.replace("_", "-"))
        out.append(Setting((*prefix, field.name), field.default, meta["help"], meta["unit"],
                           option, meta["choices"], meta["default_text"], meta["metavar"],
                           meta["panel"], kind, meta.get("min"), meta.get("max"),
                           meta.get("multiple", False)))
    return out


def build(cls: type, values: dict[tuple[str, ...], Any]) -> Any:
    """An instance of ``cls`` from values by path (:attr:`Setting.path`), nested classes
    built from their own; fields not given keep their defaults."""
    import typing

    hints = typing.get_type_hints(cls)
    kwargs: dict[str, Any] = {}
    for field in dataclasses.fields(cls):
        kind = hints[field.name]
        if dataclasses.is_dataclass(kind):
            inner = {p[1:]: v for p, v in values.items() if p[0] == field.name}
            kwargs[field.name] = build(kind, inner)  # type: ignore[arg-type]
        elif (field.name,) in values:
            kwargs[field.name] = values[(field.name,)]
    return cls(**kwargs)


def to_dict(settings: Any) -> dict[str, Any]:
    """The settings as plain JSON types (tuples as lists), nested classes flattened into
    one mapping by field name, as a model file's provenance records them."""
    out: dict[str, Any] = {}
    for field in dataclasses.fields(settings):
        value = getattr(settings, field.name)
        if dataclasses.is_dataclass(value):
            out.update(to_dict(value))
        else:
            out[field.name] = list(value) if isinstance(value, tuple) else value
    return out
