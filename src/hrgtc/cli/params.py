"""Command-line options generated from the settings dataclasses of :mod:`hrgtc.settings`.

A stage's options are not declared here one by one: :func:`settings_options` reads the
fields of its settings class (name, type, default, and the help, unit, option name and
choices in the field's metadata) and gives the command one option per field, so a
default is written once, in the dataclass, and ``--help``, the docs' option tables
(:mod:`hrgtc.cli.options_tables`) and the model file agree::

    @app.command()
    @settings_options(CalibrationSettings, "settings")
    def calibrate(drift: list[Path], settings: CalibrationSettings | None = None) -> None:
        ...

The settings modules import only the standard library, so generating the options at
start-up keeps ``hrgtc --help`` quick.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import types
import typing
from collections.abc import Callable, Sequence
from typing import Any

import typer

from hrgtc.settings import Setting, build, format_value, settings_of


def _is_terms(kind: Any) -> bool:
    """A tuple of strings (terms), given on the command line comma separated."""
    args = typing.get_args(kind) if isinstance(kind, types.UnionType) else (kind,)
    return any(typing.get_origin(a) is tuple for a in args)


def parameter_name(setting: Setting) -> str:
    """The Python name of a setting's option in a command's signature."""
    return setting.name


def _option_info(setting: Setting, **extra: Any) -> Any:
    """The ``typer.Option`` of one setting: its names, help, default and panel."""
    assert setting.option is not None
    default: Any = setting.default
    if setting.multiple:  # given once per item; not given: None, the field's ()
        default = None
    elif _is_terms(setting.type) and default is not None:
        default = format_value(default)
    show: bool | str = True
    if setting.default_text is not None:
        show = setting.default_text
    elif setting.default in (None, ()):
        show = False
    if setting.min is not None:  # click's IntRange/FloatRange: "0 is not in the range x>=1"
        extra.setdefault("min", setting.min)
    if setting.max is not None:
        extra.setdefault("max", setting.max)
    return typer.Option(default, *setting.option.split(), help=setting.full_help(),
                        show_default=show, metavar=setting.metavar,
                        rich_help_panel=setting.panel, **extra)


def option_parameter(setting: Setting) -> inspect.Parameter:
    """The keyword parameter (with its ``typer.Option``) of one setting."""
    annotation: Any = setting.type
    if setting.multiple:
        annotation = list[str] | None
    elif _is_terms(setting.type):
        annotation = str | None
    if setting.choices:  # typer checks a Literal's values and lists them
        annotation = typing.Literal[setting.choices]  # type: ignore[valid-type]
        if setting.default is None:
            annotation = typing.Optional[annotation]  # noqa: UP045 (a runtime type)
    return inspect.Parameter(parameter_name(setting), inspect.Parameter.KEYWORD_ONLY,
                             default=_option_info(setting), annotation=annotation)


def option(cls: type, name: str) -> Any:
    """The ``typer.Option`` of the field ``name`` of the settings class ``cls``, for a
    command that keeps its own parameter (``deviation: str = option(EvaluationSettings,
    "deviation")``): the default, help, unit and choices come from the field.

    A sequence field (a tuple) is given comma separated: the parameter is ``str`` and the
    command splits it (:func:`split_values`).
    """
    (setting,) = [s for s in settings_of(cls) if s.path == (name,)]
    if not setting.choices:
        return _option_info(setting)
    choices = setting.choices

    def check(value: Any) -> Any:
        if value is not None and value not in choices:
            raise typer.BadParameter(f"{value!r} is not one of {', '.join(choices)}")
        return value

    metavar = setting.metavar or "[" + "|".join(choices) + "]"
    return _option_info(dataclasses.replace(setting, metavar=metavar), callback=check)


def split_values(text: str, kind: type = float) -> tuple[Any, ...]:
    """A comma-separated option value as a tuple of ``kind`` (``"-20,0,20"``)."""
    try:
        return tuple(kind(v.strip()) for v in text.split(",") if v.strip())
    except ValueError:
        raise typer.BadParameter(f"{text!r} is not a comma-separated list of "
                                 f"{kind.__name__} values, e.g. -20,0,20") from None


def _value(setting: Setting, value: Any) -> Any:
    """A command-line value as the settings class takes it (terms, a repeated option: a
    tuple)."""
    if setting.multiple:
        return tuple(value or ())
    if _is_terms(setting.type) and isinstance(value, str):
        kind = float if "float" in str(setting.type) else str
        return split_values(value, kind)  # a bad number: a usage error naming the value
    return value


def option_settings(cls: type) -> list[Setting]:
    """The settings of ``cls`` that are command-line options, in their order."""
    return [s for s in settings_of(cls) if s.option is not None]


def _evaluated(parameter: inspect.Parameter, namespace: dict[str, Any]) -> inspect.Parameter:
    """``parameter`` with its annotation evaluated (left as text when it names a type only
    imported for type checking, such as the ``inputs`` another decorator replaces)."""
    if not isinstance(parameter.annotation, str):
        return parameter
    try:
        return parameter.replace(annotation=eval(parameter.annotation, namespace))
    except NameError:
        return parameter


def add_parameters(command: Callable[..., Any], target: str,
                   added: Sequence[inspect.Parameter],
                   make: Callable[[dict[str, Any]], Any]) -> Callable[..., Any]:
    """``command`` with the keyword parameters ``added`` in place of its ``target``.

    The command line shows the ``added`` options; the wrapper gathers their values,
    turns them into one object with ``make`` and passes it as ``target``.
    """
    signature = inspect.signature(command)
    namespace = getattr(command, "__globals__", {})
    own = [_evaluated(p, namespace) for name, p in signature.parameters.items()
           if name != target]
    names = [p.name for p in added]

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        values = {name: kwargs.pop(name) for name in names if name in kwargs}
        return command(*args, **{target: make(values)}, **kwargs)

    parameters = [p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in own] + list(added)
    wrapper.__signature__ = signature.replace(parameters=parameters)  # type: ignore[attr-defined]
    wrapper.__annotations__ = {p.name: p.annotation for p in parameters}
    del wrapper.__wrapped__  # Typer must see the new signature, not the wrapped one
    return wrapper


def settings_options(cls: type, target: str = "settings") -> Callable[[Any], Any]:
    """Give a command one option per field of the settings class ``cls``.

    The decorated function takes ``target: cls`` instead of the separate options.
    """
    settings = option_settings(cls)

    def make(values: dict[str, Any]) -> Any:
        return build(cls, {s.path: _value(s, values[parameter_name(s)]) for s in settings
                           if parameter_name(s) in values})

    def decorate(command: Callable[..., Any]) -> Callable[..., Any]:
        return add_parameters(command, target, [option_parameter(s) for s in settings], make)

    return decorate
