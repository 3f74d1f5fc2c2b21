"""Typed records: one definition per result gives its JSON form, its checks and its JSON Schema.

A *record* is a :class:`msgspec.Struct` that names the fields a result writes to a file,
with their types and bounds (``Annotated[float, Meta(gt=0)]``). From that one definition:

* :func:`dump` writes a result as plain, strict JSON types (the result's ``to_dict``):
  the fields are read off the result by name, so the record and the result cannot
  disagree on a name without a test failing;
* :func:`load` validates plain JSON types against the record (msgspec's messages name
  the place: ``Expected `int` >= 1 - at `$.order```) and returns the field values, the
  statistics as floats (``null`` -> NaN), ready for the result's constructor (its
  ``from_dict``);
* :func:`json_schema` gives the JSON Schema (Draft 2020-12), which
  :mod:`hrgtc.model_schema` assembles into the model file's schema.

Numbers: a parameter is a finite ``float`` (JSON has no NaN; a file that holds one is
refused where the record says ``float``); a :data:`Statistic` may also be ``null`` or,
in files of schema version 1, the strings ``"NaN"``/``"Infinity"``/``"-Infinity"``
(see :mod:`hrgtc.model_schema`). See docs/architecture.md ("One result contract").

msgspec is imported when this module is: import it from the modules that serialise,
never from the CLI's start-up path.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal, TypeVar, get_args, get_origin

import msgspec

from hrgtc.core.errors import InputError

__all__ = [
    "NOT_FINITE",
    "Count",
    "NonNegative",
    "Positive",
    "Range",
    "Record",
    "Statistic",
    "dump",
    "empty",
    "json_schema",
    "load",
    "schema_components",
    "statistic",
]

#: A number that must be > 0.
Positive = Annotated[float, msgspec.Meta(gt=0)]
#: A number that must be >= 0.
NonNegative = Annotated[float, msgspec.Meta(ge=0)]
#: A count (>= 0).
Count = Annotated[int, msgspec.Meta(ge=0)]
#: An ordered pair of numbers (low, high); order is a check of the result, not of the type.
Range = tuple[float, float]
#: How files of schema version 1 spell a statistic that is not finite (see model_schema).
NOT_FINITE = ("NaN", "Infinity", "-Infinity")
#: A statistic (standard error, p-value, R², ...): a number, ``null`` when not finite, or
#: in files of schema version 1 one of :data:`NOT_FINITE`. Read as a float (NaN, ±inf).
Statistic = float | None | Literal["NaN", "Infinity", "-Infinity"]

R = TypeVar("R", bound="Record")


class Record(msgspec.Struct, kw_only=True):
    """Base of every record: keyword fields, unknown fields ignored (newer minor additions).

    Class attributes a record may set:

    ``omit_when_default``
        Fields written only when they differ from their default (so files written
        before the field existed hash alike).
    """

    omit_when_default = ()  # type: tuple[str, ...]


def empty() -> Any:
    """The default of a mapping field: a new empty dict per record."""
    return msgspec.field(default_factory=dict)


def dump(result: Any, record: type[Record], /, **given: Any) -> dict[str, Any]:
    """A result's record as strict JSON types (lists, ``None`` for what is not finite).

    Each field of ``record`` is read off ``result`` by name (a field the result lacks
    takes the record's default, e.g. the constant ``kind``); nested records likewise.
    ``given``: field values to use instead (a part that serialises itself).
    """
    try:
        value = msgspec.convert(_View(result, given), record, from_attributes=True)
    except msgspec.ValidationError as exc:
        raise InputError(f"{type(result).__name__} does not fit its record "
                         f"{record.__name__}: {exc}") from exc
    document = _strict(msgspec.to_builtins(value, enc_hook=_plain))
    _omit_defaults(document, record)
    return document


def _omit_defaults(document: Any, kind: Any) -> None:
    """Drop the fields of ``omit_when_default`` that hold their default, at every depth."""
    while get_origin(kind) is Annotated:
        kind = get_args(kind)[0]
    if isinstance(kind, type) and issubclass(kind, Record):
        if not isinstance(document, dict):
            return
        for field in msgspec.structs.fields(kind):
            if field.name not in document:
                continue
            if field.name in kind.omit_when_default and document[field.name] == _strict(
                    _default(field)):
                del document[field.name]
            else:
                _omit_defaults(document[field.name], field.type)
        return
    args = [a for a in get_args(kind) if a is not Ellipsis]
    if isinstance(document, dict) and get_origin(kind) is dict:
        for item in document.values():
            _omit_defaults(item, args[-1])
    elif isinstance(document, list) and args:
        for item in document:
            _omit_defaults(item, args[0])
    elif args:  # X | None: the record among the union's members
        for member in args:
            if isinstance(member, type) and issubclass(member, Record):
                _omit_defaults(document, member)


def _default(field: Any) -> Any:
    """A field's default (a new one of its factory's: ``records.empty()``)."""
    return field.default_factory() if field.default is msgspec.NODEFAULT else field.default


def _plain(value: Any) -> Any:
    """A numpy scalar or array in a free-form part as plain Python (``tolist``)."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"a record cannot hold {type(value).__name__} {value!r}")


class _View:
    """``result``'s attributes as plain Python (numpy scalars and arrays by ``tolist``,
    nested results viewed alike), some replaced by ``given``."""

    def __init__(self, result: Any, given: dict[str, Any]) -> None:
        self._result, self._given = result, given

    def __getattr__(self, name: str) -> Any:
        if name in self._given:
            return _plain_value(self._given[name])
        return _plain_value(getattr(self._result, name))


def _plain_value(value: Any) -> Any:
    if isinstance(value, str | int | float | bool | None):
        return value.item() if hasattr(value, "item") else value
    if hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, dict):
        return {k: _plain_value(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain_value(v) for v in value]
    if hasattr(value, "__dataclass_fields__"):
        return _View(value, {})
    return value


def load(data: Any, record: type[Record], what: str) -> dict[str, Any]:
    """Validate ``data`` against ``record``; the field values, statistics as floats.

    Nested records come back as dicts of their values, lists as tuples, statistics
    as floats (``null`` -> NaN): what the results' constructors take.

    Raises
    ------
    InputError
        ``data`` does not fit, naming the place (``- at `$.settings.rate_tau_s```).
    """
    try:
        value = msgspec.convert(data, record, strict=False)
    except msgspec.ValidationError as exc:
        raise InputError(f"not a valid {what} record: {exc}") from exc
    return _values(value, record)


def _values(value: Any, kind: Any) -> Any:
    """``value`` (of the record type ``kind``) as constructor arguments."""
    while get_origin(kind) is Annotated:
        kind = get_args(kind)[0]
    if isinstance(value, Record):
        return {f.name: _values(getattr(value, f.name), f.type)
                for f in msgspec.structs.fields(type(value))}
    if kind == Statistic:
        return statistic(value)
    if value is None or kind is Any:  # free-form parts (a stepwise record) are kept as read
        return value
    origin, args = get_origin(kind), get_args(kind)
    if isinstance(value, dict):
        item = args[-1] if origin is dict else Any
        return {k: _values(v, item) for k, v in value.items()}
    if isinstance(value, tuple | list):
        if origin is tuple and args and args[-1] is not Ellipsis:
            return tuple(_values(v, a) for v, a in zip(value, args, strict=True))
        item = args[0] if args else Any
        return tuple(_values(v, item) for v in value)
    return value


def statistic(value: Any) -> float:
    """A statistic as a float: ``None`` and :data:`NOT_FINITE` become NaN / ±inf."""
    if value is None or value == "NaN":
        return math.nan
    if value == "Infinity":
        return math.inf
    if value == "-Infinity":
        return -math.inf
    return float(value)


def _strict(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _strict(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_strict(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def schema_components(records: list[type[Record]]) -> tuple[list[dict[str, Any]],
                                                            dict[str, Any]]:
    """The JSON Schemas of ``records`` and their shared definitions (``#/$defs/NAME``)."""
    return msgspec.json.schema_components(records, ref_template="#/$defs/{name}")


def json_schema(record: type[Record], title: str, schema_id: str) -> dict[str, Any]:
    """The JSON Schema (Draft 2020-12) of one record, with its definitions."""
    _, definitions = schema_components([record])
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": schema_id,
            **definitions[record.__name__], "title": title, "$defs": definitions}
