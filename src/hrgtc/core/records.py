"""Typed records: one declaration per result gives its JSON form, its checks and its JSON Schema.

The declaration is the result itself: a dataclass (or :class:`msgspec.Struct`) whose
fields carry their types and bounds (``Annotated[float, Meta(gt=0)]``, :data:`Positive`,
:data:`Count`, :data:`Statistic`, ``Array[Statistic]`` for a numpy array written as a
list, nested results). :func:`record_of` generates its *record*, the
:class:`msgspec.Struct` that names what the file holds (``<Result>Record``); fields that
are derived or runtime-only are left out by one declaration, the result's class attribute
``not_written`` (they need a default, or ``init=False``); what else a file's part needs
(a constant ``kind``, a tag, keys of another name, computed fields: :func:`derived`) is a
class attribute beside them (:class:`Dumped`). The mixin :class:`Written` gives a result
``to_dict``/``from_dict`` once (:class:`Dumped`: ``to_dict``). From the declaration:

* :func:`dump` writes a result as plain, strict JSON types: the fields are read off the
  result by name (numpy arrays and scalars by ``tolist``: the one numpy hook), NaN as
  ``null``;
* :func:`load` validates plain JSON types against the record (msgspec's messages name
  the place: ``Expected `int` >= 1 - at `$.order```) and builds the result, nested
  results too, arrays read-only, statistics as floats (``null`` -> NaN);
* :func:`json_schema` gives the JSON Schema (Draft 2020-12), which
  :mod:`hrgtc.model_schema` assembles into the model file's schema.

msgspec encodes and decodes dataclasses itself, honouring their ``Meta`` bounds; the
generated Struct is what lets a result hold numpy arrays and runtime state and keeps each
definition's name in the published schemas. A :class:`Record` written by hand remains
where a file's part is not one dataclass's fields (a document of several results);
:func:`dump` and :func:`load` take it in place of a result (``load`` then returns its
values as a dict).

Numbers: a parameter is a finite ``float`` (JSON has no NaN; a file that holds one is
refused where the record says ``float``); a :data:`Statistic` may also be ``null`` or,
in files of schema version 1, the strings ``"NaN"``/``"Infinity"``/``"-Infinity"``
(see :mod:`hrgtc.model_schema`). See docs/architecture.md ("One result contract").

msgspec is imported when this module is: import it from the modules that serialise,
never from the CLI's start-up path.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import math
import operator
import re
import types
import typing
from typing import Annotated, Any, ClassVar, Literal, TypeVar, get_args, get_origin

import msgspec
import numpy as np

from hrgtc.core.errors import InputError

__all__ = [
    "NOT_FINITE",
    "Array",
    "Count",
    "Dumped",
    "NonNegative",
    "Positive",
    "Range",
    "Record",
    "Statistic",
    "Written",
    "built",
    "derived",
    "dump",
    "empty",
    "json_schema",
    "load",
    "record_of",
    "schema_components",
    "statistic",
    "strict",
    "variant",
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
    #: Generated records (:func:`record_of`): field -> dtype of the :class:`Array` fields,
    #: the fields not passed to the result (constants, derived), old key -> field.
    arrays = {}  # type: dict[str, Any]
    unread = ()  # type: tuple[str, ...]
    renamed = {}  # type: dict[str, str]


def empty() -> Any:
    """The default of a mapping field: a new empty dict per record."""
    return msgspec.field(default_factory=dict)


class _Items:
    """The marker of an :class:`Array` field: what the file holds of each item."""

    __slots__ = ("item", "metas")

    def __init__(self, item: Any, metas: tuple[Any, ...]) -> None:
        self.item, self.metas = item, metas


class Array:
    """A numpy array field of a result, written as a list: ``Array[Statistic]``.

    ``Array[item, Meta(...)]`` is ``Annotated[np.ndarray, ...]`` (an ndarray to the code
    and to a type checker); in the file it is ``Annotated[list[item], Meta(...)]``
    (the Meta bounds the list: ``Meta(min_length=2)``). Read back as a read-only float64
    array (an ``int64`` one for ``Array[Count]``/``Array[int]``).
    """

    def __class_getitem__(cls, params: Any) -> Any:
        item, *metas = params if isinstance(params, tuple) else (params,)
        return Annotated[np.ndarray, _Items(item, tuple(metas))]


class Dumped:
    """Mixin of a result that is written, not read back: ``to_dict`` once (:func:`dump`).

    Class attributes a result may set (see :func:`record_of`):

    ``not_written``
        Fields that are derived or runtime-only: not in the file, not in the schema
        (they need a default, or ``init=False``, when the result is read back).
    ``omit_when_default``
        Fields written only when they differ from their default.
    ``forbid_unknown_fields``
        True: a key the record does not know is refused (a misspelt input), not ignored.
    ``constants``
        Fields of a fixed value, written first and checked on reading, not the result's:
        ``(("kind", "hrgtc.Thermometer"),)`` (a ``Literal`` in the record and schema).
    ``tag``
        ``(field, value)``: the record is a tagged struct, a member of a msgspec tagged
        union told by ``field`` (``("kind", "shell")``).
    ``record_order``
        The record's fields in file order, when it is not the declaration's (the
        constants, then the fields, then the :func:`derived` properties).
    ``renamed``
        ``(old key, field)`` pairs: a key older files wrote under another name.
    ``required``
        Fields a file must hold although the constructor has a default for them.
    ``file_names``
        ``(field, key)`` pairs: a field the file writes under another key.
    ``written_by``
        Its record when it cannot be generated beside it: a :class:`Record` of a module
        below the result's, where a document nests it (it is read back as the result).
    """

    __slots__ = ()
    not_written: ClassVar[tuple[str, ...]] = ()
    omit_when_default: ClassVar[tuple[str, ...]] = ()
    forbid_unknown_fields: ClassVar[bool] = False
    constants: ClassVar[tuple[tuple[str, str], ...]] = ()
    tag: ClassVar[tuple[str, str] | None] = None
    record_order: ClassVar[tuple[str, ...]] = ()
    renamed: ClassVar[tuple[tuple[str, str], ...]] = ()
    required: ClassVar[tuple[str, ...]] = ()
    file_names: ClassVar[tuple[tuple[str, str], ...]] = ()
    written_by: ClassVar[type[Record] | None] = None

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (lists, ``None`` for what is not finite): :func:`dump`."""
        return dump(self)


class Written(Dumped):
    """Mixin of a result whose fields are its record: ``to_dict``/``from_dict`` once (the
    class attributes of :class:`Dumped`)."""

    __slots__ = ()

    @classmethod
    def from_dict(cls, data: Any) -> Any:
        """Inverse of :meth:`to_dict` (optional fields may be missing): :func:`load`."""
        return load(data, cls)


class _Derived(property):
    """A property written as a field of its result's record (:func:`derived`)."""

    default: Any = msgspec.NODEFAULT


def derived(fget: Any = None, *, default: Any = msgspec.NODEFAULT) -> Any:
    """A property of a result that its record writes (computed, not read back): its return
    annotation is the field's type, ``default`` the schema's default. ``@records.derived``
    or ``@records.derived(default=0)``."""
    def make(function: Any) -> _Derived:
        found = _Derived(function)
        found.default = default
        return found
    return make if fget is None else make(fget)


#: result class -> its record, and back (:func:`record_of`).
_RECORDS: dict[type, type[Record]] = {}
_RESULTS: dict[type, type] = {}


def record_of(result: type, name: str | None = None, doc: str | None = None) -> type[Record]:
    """The record of a result class, generated from its fields (cached).

    ``result`` is a dataclass (or a :class:`msgspec.Struct`) whose annotations are the
    declaration: ``Annotated[float, Meta(gt=0)]`` (:data:`Positive`), :data:`Statistic`,
    :class:`Array` for numpy arrays, nested results (``Annotated[Step, ScaleStepRecord]``
    nests a :func:`variant`). Its fields are the record's, in their order, with their
    defaults (a default that is not finite, NaN, is ``null`` as in the file); left out are
    those named in its ``not_written`` and those with ``init=False`` (derived). Its
    ``constants`` come first and its :func:`derived` properties last, unless its
    ``record_order`` says otherwise (the class attributes of :class:`Dumped`). The record
    is named ``<result>Record`` (the name of its definition in a JSON Schema; ``name``
    gives another, at the first call: ``BurstAllanRecord =
    records.record_of(BurstAllanResult, "BurstAllanRecord")`` beside the result, where
    another record nests it); its docstring (the JSON Schema's ``description``) names the
    result, or is ``doc``. A :class:`Record` subclass is its own record.
    """
    if isinstance(result, type) and issubclass(result, Record):
        return result
    found = _RECORDS.get(result)
    if found is not None:
        if (name is not None and found.__name__ != name) or (
                doc is not None and found.__doc__ != doc):
            raise TypeError(f"{result.__name__}'s record is {found.__name__} "
                            f"({found.__doc__!r}), not {name} ({doc!r})")
        return found
    given = getattr(result, "written_by", None)
    found = given if given is not None else variant(result, name or f"{result.__name__}Record",
                                                    doc)
    _RECORDS[result] = found
    _RESULTS.setdefault(found, result)
    return found


def variant(result: type, name: str, doc: str | None = None, *,
            forbid_unknown_fields: bool | None = None, **types_: Any) -> type[Record]:
    """A record of ``result`` other than its own (:func:`record_of`): the same fields, some
    of another type (``term=FTerm``), reading back as ``result``. A field of another
    result nests it as ``Annotated[Step, ScaleStepRecord]``."""
    hints = {**typing.get_type_hints(result, include_extras=True), **types_}
    skip = set(getattr(result, "not_written", ()))
    required = set(getattr(result, "required", ()))
    names = dict(getattr(result, "file_names", ()))
    fields = {key: (key, Literal[value], value)  # type: ignore[valid-type]
              for key, value in getattr(result, "constants", ())}
    arrays: dict[str, Any] = {}
    for field, default, factory in _fields(result):
        if field in skip:
            continue
        dtype = _array_dtype(hints[field])
        if dtype is not None:
            arrays[field] = dtype
        if field in required:
            default, factory = msgspec.NODEFAULT, None
        fields[field] = _spec(field, _wire(hints[field]), default, factory, names.get(field))
    computed = _derived_fields(result)
    for field, (kind, default) in computed.items():
        fields[field] = _spec(field, _wire(kind), default, None, names.get(field))
    order = tuple(getattr(result, "record_order", ())) or tuple(fields)
    if sorted(order) != sorted(fields):
        raise TypeError(f"{result.__name__}.record_order {order} is not its fields {tuple(fields)}")
    tag = getattr(result, "tag", None)
    found = msgspec.defstruct(
        name, [fields[f] for f in order], bases=(Record,), kw_only=True,
        forbid_unknown_fields=getattr(result, "forbid_unknown_fields", False)
        if forbid_unknown_fields is None else forbid_unknown_fields,
        module=result.__module__, **({} if tag is None else {"tag_field": tag[0], "tag": tag[1]}),
        namespace={"__doc__": doc or f"The record of :class:`{result.__name__}` (its "
                                     "``to_dict``, ``from_dict``).",
                   "omit_when_default": tuple(getattr(result, "omit_when_default", ())),
                   "arrays": arrays,
                   "unread": (*dict(getattr(result, "constants", ())), *computed),
                   "renamed": dict(getattr(result, "renamed", ()))})
    _RESULTS[found] = result
    return found


def _spec(field: str, kind: Any, default: Any, factory: Any, name: str | None) -> tuple[Any, ...]:
    """A field of :func:`msgspec.defstruct`: its default as the file spells it (NaN as
    ``null``), its name in the file (``file_names``) when it is not the attribute's."""
    default = _file_default(default)
    if name is None and factory is None:
        return (field, kind) if default is msgspec.NODEFAULT else (field, kind, default)
    return (field, kind, msgspec.field(default=default, name=name,
                                       default_factory=factory or msgspec.NODEFAULT))


def _file_default(default: Any) -> Any:
    if isinstance(default, float) and not math.isfinite(default):
        return None  # as the file spells it (a Statistic)
    return tuple(_file_default(d) for d in default) if isinstance(default, tuple) else default


def _derived_fields(result: type) -> dict[str, tuple[Any, Any]]:
    """``name -> (type, default)`` of the :func:`derived` properties of ``result``."""
    found: dict[str, tuple[Any, Any]] = {}
    for klass in reversed(result.__mro__):
        for key, value in vars(klass).items():
            if isinstance(value, _Derived):
                hint = typing.get_type_hints(value.fget, include_extras=True)["return"]
                found[key] = (hint, value.default)
    return found


def _fields(result: type) -> list[tuple[str, Any, Any]]:
    """``(name, default, default factory)`` of each field a result's constructor takes."""
    if dataclasses.is_dataclass(result):
        return [(f.name,
                 msgspec.NODEFAULT if f.default is dataclasses.MISSING else f.default,
                 None if f.default_factory is dataclasses.MISSING else f.default_factory)
                for f in dataclasses.fields(result) if f.init]
    if issubclass(result, msgspec.Struct):
        return [(f.name, f.default, None if f.default_factory is msgspec.NODEFAULT
                 else f.default_factory) for f in msgspec.structs.fields(result)]
    raise TypeError(f"{result.__name__} is neither a dataclass nor a msgspec Struct")


def _wire(kind: Any) -> Any:
    """The type a file holds for a field of type ``kind``: arrays as lists, nested
    results as their records."""
    origin, args = get_origin(kind), get_args(kind)
    if origin is Annotated:
        metas = kind.__metadata__
        given = [m for m in metas if isinstance(m, type) and issubclass(m, Record)]
        if given:  # Annotated[Step, ScaleStepRecord]: a variant (its record)
            return given[0]
        items = [m for m in metas if isinstance(m, _Items)]
        if items:
            listed = list[_wire(items[0].item)]  # type: ignore[misc]
            return Annotated[(listed, *items[0].metas)] if items[0].metas else listed
        inner = _wire(args[0])
        return kind if inner is args[0] else Annotated[(inner, *metas)]
    if isinstance(kind, type) and (dataclasses.is_dataclass(kind)
                                   or (issubclass(kind, msgspec.Struct)
                                       and not issubclass(kind, Record))):
        return record_of(kind)
    if not args or origin is Literal:
        return kind
    wired = tuple(a if a is Ellipsis else _wire(a) for a in args)
    if wired == args:
        return kind
    if origin in (typing.Union, types.UnionType):
        return functools.reduce(operator.or_, wired)
    return origin[wired]


def _array_dtype(kind: Any) -> Any:
    """The dtype a field of type ``kind`` is read back as, if it is an :class:`Array`."""
    for member in (kind, *get_args(kind)):  # Array[...] | None
        if get_origin(member) is Annotated:
            items = [m for m in member.__metadata__ if isinstance(m, _Items)]
            if items:
                item = items[0].item
                while get_origin(item) is Annotated:
                    item = get_args(item)[0]
                return np.int64 if item is int else np.float64
    return None


def dump(result: Any, record: type[Record] | None = None, /, **given: Any) -> dict[str, Any]:
    """A result's record as strict JSON types (lists, ``None`` for what is not finite).

    ``record``: the record to write (default: the result's own, :func:`record_of`).
    Each field of ``record`` is read off ``result`` by name (a field the result lacks
    takes the record's default, e.g. the constant ``kind``); nested results likewise.
    ``given``: field values to use instead (a part that serialises itself).
    """
    record = record_of(type(result)) if record is None else record
    try:
        value = msgspec.convert(_View(result, given), record, from_attributes=True)
    except msgspec.ValidationError as exc:
        raise InputError(f"{type(result).__name__} does not fit its record "
                         f"{record.__name__}: {exc}") from exc
    document = strict(msgspec.to_builtins(value, enc_hook=_plain))
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
            if field.encode_name not in document:
                continue
            if field.name in kind.omit_when_default and document[field.encode_name] == strict(
                    _default(field)):
                del document[field.encode_name]
            else:
                _omit_defaults(document[field.encode_name], field.type)
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
    if hasattr(value, "__dataclass_fields__"):  # a tagged result shows its tag (a union's)
        tag = value.tag if isinstance(value, Dumped) else None
        return _View(value, {} if tag is None else {tag[0]: tag[1]})
    return value


def load(data: Any, kind: type[Any], what: str | None = None) -> Any:
    """Validate ``data`` against ``kind``'s record: the result, or a record's field values.

    ``kind`` is a result class (its record: :func:`record_of`): the result is built
    from the values, nested results too, :class:`Array` fields as numpy arrays. Or
    ``kind`` is a :class:`Record` (a part with no result class of its own): its field
    values as a dict. Lists come back as tuples and statistics as floats (``null`` ->
    NaN). ``what`` names the record in a message (default: ``kind``'s name, ``DriftModel``
    -> ``drift-model``).

    Raises
    ------
    InputError
        ``data`` does not fit, naming the place (``- at `$.settings.rate_tau_s```).
    """
    record = record_of(kind)
    if what is None:
        what = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", "-", kind.__name__).lower()
    if record.renamed and isinstance(data, dict):
        data = {record.renamed.get(k, k) if record.renamed.get(k, k) not in data else k: v
                for k, v in data.items()}
    try:
        value = msgspec.convert(data, record, strict=False)
    except msgspec.ValidationError as exc:
        raise InputError(f"not a valid {what} record: {exc}") from exc
    return built(value, what)


def built(value: Any, what: str | None = None) -> Any:
    """A converted record's value (``msgspec.convert(data, record)``, or a part of a
    document converted once) as its result: :func:`load` after the conversion. A result's
    own check that refuses the values (its ``__post_init__``) is an :class:`InputError`
    naming ``what`` (default: the record)."""
    try:
        return _values(value, type(value))
    except InputError:
        raise
    except (KeyError, TypeError, ValueError, IndexError) as exc:
        raise InputError(f"not a valid {what or type(value).__name__} record: "
                         f"{exc!r}") from exc


def _values(value: Any, kind: Any) -> Any:
    """``value`` (of the record type ``kind``) as constructor arguments; a generated
    record's value as its result."""
    while get_origin(kind) is Annotated:
        kind = get_args(kind)[0]
    if isinstance(value, Record):
        record = type(value)
        fields = {f.name: _values(getattr(value, f.name), f.type)
                  for f in msgspec.structs.fields(record)}
        result = _RESULTS.get(record)
        if result is None:
            return fields
        for name in record.unread:
            del fields[name]
        for name, dtype in getattr(record, "arrays", {}).items():
            if fields[name] is not None:
                fields[name] = np.array(fields[name], dtype=dtype)
                fields[name].setflags(write=False)  # a result read back is a value
        return result(**fields)
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


def strict(value: Any) -> Any:
    """``value`` with every float that is not finite replaced by None (strict JSON)."""
    if isinstance(value, dict):
        return {k: strict(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [strict(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def schema_components(records: list[type[Any]]) -> tuple[list[dict[str, Any]],
                                                         dict[str, Any]]:
    """The JSON Schemas of ``records`` (or results: their records) and their shared
    definitions (``#/$defs/NAME``)."""
    references, definitions = msgspec.json.schema_components(
        [record_of(r) for r in records], ref_template="#/$defs/{name}")
    return references, {name: _cleaned(d) for name, d in definitions.items()}


def _cleaned(definition: dict[str, Any]) -> dict[str, Any]:
    """``definition`` with its description dedented as :func:`inspect.cleandoc` does: msgspec
    0.23 dedents a docstring, 0.22 kept its indent; the published schema is the same for
    both."""
    if "description" not in definition:
        return definition
    return {**definition, "description": inspect.cleandoc(definition["description"])}


def json_schema(record: type[Any], title: str, schema_id: str) -> dict[str, Any]:
    """The JSON Schema (Draft 2020-12) of one record (or result: its record), with its
    definitions."""
    record = record_of(record)
    _, definitions = schema_components([record])
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "$id": schema_id,
            **definitions[record.__name__], "title": title, "$defs": definitions}
