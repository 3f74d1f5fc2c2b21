"""The JSON Schema of the model file, and the checks a schema cannot express.

The schema is not written by hand: :data:`MODEL_SCHEMA` is generated from the typed
records of the file's parts (:class:`FileRecord`, :class:`AxisRecord` and the records
beside each result: ``ThermometerRecord``, ``DriftModelRecord``, ``ScaleFactorRecord``,
...; see :mod:`hrgtc.core.records`), the same definitions that write and read them.

A model file is trusted by nothing: :func:`check_document` validates it once, with
msgspec against the records :data:`MODEL_SCHEMA` is generated from (the tests prove
with ``jsonschema``, Draft 2020-12, that the published schema accepts and refuses the
same files), and then checks what a schema cannot say: every term is known and
parsable, the selected terms are among the candidates with one coefficient each, every
range is ordered, the user-unit coefficients agree with the scaled ones they are derived
from.

Numbers: the *parameters* (coefficients, ranges, scales, settings) must be finite
numbers; the *statistics* (standard errors, p-values, R², the stepwise record)
may be missing, written ``null`` (schema version 2) or, in files of version 1,
the non-standard ``NaN`` that Python's ``json`` used to write. Version 1 files
are read through :func:`parse_model_json`, which turns ``NaN`` and ``Infinity``
into the strings ``"NaN"`` / ``"Infinity"`` so that the schema names them where
they are not allowed.

Integrity: a file of version 2 carries ``parameters_sha256``, the SHA-256 of its
canonical JSON without provenance (:func:`parameters_sha256`); a file whose
content no longer matches it was changed after it was written (a flipped digit
in a coefficient or a range is otherwise a valid model with wrong numbers) and is
refused. A deliberate hand edit removes that line. The same hash names the model
in the mark of a compensated output.

One source of truth for coefficients: prediction uses ``scaled_coefficients``
(coefficients of the centred and scaled variables, what the fit produced); the
readable ``coefficients`` in user units are derived from them. On loading, the
file's ``coefficients`` must agree with the derived ones to rounding
(:data:`COEFFICIENT_RTOL`), else the file was edited by hand and is refused;
the derived values are the ones kept.
"""

from __future__ import annotations

import json
import re
import types
from collections.abc import Mapping
from fractions import Fraction
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import msgspec
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import InputError, ModelFileError
from hrgtc.drift.drift_model import DriftModelRecord
from hrgtc.drift.features import parse_terms
from hrgtc.drift.scale_factor import ScaleFactorRecord
from hrgtc.drift.training import TrainingStatisticsRecord
from hrgtc.thermometry.reference import TemperatureMapRecord
from hrgtc.thermometry.thermometer import ThermometerRecord
from hrgtc.update.lineage import LineageRecord

SCHEMA_NAME = "hrgtc.model"
#: 2: strict JSON (statistics that are not finite are written ``null``).
#: 3: several axes (``axes``) and scale factor (``scale_factor``); written only when used.
SCHEMA_VERSION = 3
#: Axis names of a multi-axis model (as the recording's per-axis column suffixes).
AXIS_PATTERN = r"^[A-Za-z][A-Za-z0-9]*$"
#: Relative agreement of ``coefficients`` with those derived from ``scaled_coefficients``.
COEFFICIENT_RTOL = 1e-9
#: Largest bias the intercept or any one term may give over the trained ranges: ten times
#: the largest rate a recording may hold (1000 °/s, ``recording.checks.RATE_MAX_DPH``).
#: No gyro has such a bias; a coefficient beyond it is a corrupt or hand-made file. [°/h]
BIAS_BOUND_DPH = 3.6e7
#: Largest scale-factor error any one term may give over the rate tables' range. [ppm]
SCALE_BOUND_PPM = 1e6

class AxisRecord(records.Record, kw_only=True):
    """What one axis holds: the parts of a single-axis model file (at its top level), or
    of one axis of a multi-axis file (under ``axes``)."""

    # scale_factor and training are written only when known: older files hash alike
    omit_when_default = ("scale_factor", "training")

    thermometer: ThermometerRecord
    drift: DriftModelRecord
    housing: DriftModelRecord | None = None
    plateaus: tuple[dict[str, Any], ...] = ()
    scale_factor: ScaleFactorRecord | None = None
    #: Optional: files written before it still load (the noise check is then skipped).
    training: TrainingStatisticsRecord | None = None


class FileRecord(records.Record, kw_only=True):
    """The model file's own fields, beside one axis's parts (:class:`AxisRecord`) or ``axes``.

    A single-axis file holds its axis's parts at the place of ``axes``
    (:func:`file_document`); ``temperature_map`` is written as the map wrote it.
    """

    # absent unless used: a single-axis file, a file before it is hashed, no map
    omit_when_default = ("axes", "parameters_sha256", "temperature_map", "lineage")

    schema: Literal["hrgtc.model"]
    schema_version: Annotated[int, Meta(ge=1, le=SCHEMA_VERSION)]
    unit: str = "unknown"
    axes: Annotated[dict[Annotated[str, Meta(pattern=AXIS_PATTERN)], AxisRecord],
                    Meta(min_length=1)] = records.empty()
    provenance: dict[str, Any] = records.empty()
    parameters_sha256: Annotated[str, Meta(pattern="^[0-9a-f]{64}$")] = ""
    #: Optional: a raw temperature count's map to °C (calibrate --temp-ref).
    temperature_map: TemperatureMapRecord | None = None
    #: Optional: an in-field update's parent, data and changes (``hrgtc update``).
    lineage: LineageRecord | None = None


def file_document(head: Mapping[str, Any], parts: Mapping[str, Any] | None = None,
                  temperature_map: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """A model file's document: its :class:`FileRecord` fields (``records.dump``), with a
    single axis's parts (:class:`AxisRecord`) where ``axes`` would be, and the map last.

    The keys keep the order files have always had (``json.dumps`` writes them in order).
    """
    document: dict[str, Any] = {}
    for key, value in head.items():
        if key == "provenance" and parts is not None:
            document.update(parts)
        document[key] = value
    if temperature_map is not None:
        document["temperature_map"] = dict(temperature_map)
    return document


def _model_schema() -> dict[str, Any]:
    """The model file's JSON Schema, generated from :class:`FileRecord` and :class:`AxisRecord`
    (and the records of the parts: thermometer, drift model, scale factor, ...)."""
    _, definitions = records.schema_components([FileRecord, AxisRecord])
    top, axis = definitions.pop("FileRecord"), definitions["AxisRecord"]
    properties = {**top["properties"], **axis["properties"]}
    for name in ("axes", "provenance", "parameters_sha256"):  # absent, never a default
        properties[name].pop("default", None)
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": "https://hrgtc.invalid/schema/model.json",
        "title": "hrgtc model file",
        "description": top.get("description", ""),
        "type": "object",
        "required": top["required"],
        # one axis at the top level, or several under axes: never both
        "oneOf": [
            {"required": ["thermometer", "drift"], "not": {"required": ["axes"]}},
            {"required": ["axes"], "not": {"anyOf": [{"required": ["thermometer"]},
                                                      {"required": ["drift"]}]}},
        ],
        "properties": properties,
        "$defs": definitions,
    }


#: JSON Schema (Draft 2020-12) of the model file, versions 1 to 3, generated from the
#: records of its parts. A single-axis file holds one axis's parts at the top level; a
#: multi-axis file (version 3) holds them under ``axes``, one object per axis name.
MODEL_SCHEMA: dict[str, Any] = _model_schema()
#: Keys left out of :func:`parameters_sha256`.
UNHASHED = ("provenance", "parameters_sha256")


def parameters_sha256(document: Mapping[str, Any]) -> str:
    """SHA-256 of a model document's canonical JSON (sorted keys), provenance left out."""
    import hashlib

    content = {k: v for k, v in strict(dict(document)).items() if k not in UNHASHED}
    text = json.dumps(content, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def parse_model_json(text: str) -> tuple[Any, bool]:
    """Parse a model file's text; ``NaN``/``Infinity`` become strings the schema can name.

    Returns
    -------
    (document, non_standard)
        The parsed document, and whether the text held non-standard constants.
    """
    seen: list[str] = []

    def constant(name: str) -> str:
        seen.append(name)
        return name

    def unique(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
        document = dict(pairs)
        if len(document) < len(pairs):
            names = [k for k, _ in pairs]
            raise DuplicateKeyError(next(k for k in names if names.count(k) > 1))
        return document

    return json.loads(text, parse_constant=constant, object_pairs_hook=unique), bool(seen)


class DuplicateKeyError(ValueError):
    """A key written twice in one object of a model file: JSON readers disagree on which
    value counts (Python's keeps the last, others the first), so none is taken."""

    def __init__(self, key: str) -> None:
        super().__init__(key)
        self.key = key

    def describe(self, source: str, text: str) -> str:
        """The error's sentence for ``source``, with the line of the key's second use."""
        needle = json.dumps(self.key) + ":"
        first = text.find(needle)
        second = text.find(needle, first + 1) if first >= 0 else -1
        line = f" (again on line {text.count(chr(10), 0, second) + 1})" if second >= 0 else ""
        return (f"{source}: the key {self.key!r} is written twice in one object{line}: JSON "
                "readers disagree on which value counts (one keeps the first, another the "
                "last); delete one of them, or recreate the file with 'hrgtc calibrate'")


def _path(parts: Any) -> str:
    text = ""
    for part in parts:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(top level)"


def _fail(source: str, where: str, message: str) -> ModelFileError:
    return ModelFileError(f"{source}: model file is invalid at {where}: {message}; the file is "
                          "corrupt or was edited: recreate it with 'hrgtc calibrate'")


#: A single-axis file: the file's own fields and one axis's parts at the top level (the
#: records of :data:`MODEL_SCHEMA`'s first alternative; :class:`FileRecord` is the other).
_SINGLE_AXIS = msgspec.defstruct(
    "SingleAxisFileRecord",
    [(f.name, f.type, f.default if f.default_factory is msgspec.NODEFAULT
      else msgspec.field(default_factory=f.default_factory)) if not f.required
     else (f.name, f.type)
     for record in (FileRecord, AxisRecord) for f in msgspec.structs.fields(record)
     if f.name != "axes"],
    bases=(records.Record,), kw_only=True, module=__name__)


def check_schema(data: Any, source: str) -> Any:
    """Validate ``data`` against the records of :data:`MODEL_SCHEMA` (msgspec, one pass) and
    return it converted (a :class:`FileRecord`, or the single-axis file's record: each
    part the record of its result, which :func:`hrgtc.core.records.built` turns into the
    result); the first error names its place (``drift.settings.scales.f``).

    A missing section of a single-axis file (``thermometer``, ``drift``) is named as such,
    a file holding both ``axes`` and one axis's parts is refused (the schema's "one axis
    or several"), and a key the schema does not know is refused (:func:`unknown_key`).
    ``tests/test_model_schema_agreement.py`` proves that the published JSON Schema
    (checked with ``jsonschema``) accepts and refuses the same files.
    """
    if isinstance(data, dict) and data.get("schema") == "hrgtc.model":
        if "axes" not in data:
            for section in ("thermometer", "drift"):
                if section not in data:
                    raise _fail(source, "(top level)",
                                f"the required section {section!r} is missing (a single-axis "
                                "model holds 'thermometer' and 'drift', a multi-axis one "
                                "'axes')")
        else:
            both = [k for k in ("thermometer", "drift") if k in data]
            if both:
                raise _fail(source, "(top level)",
                            f"it holds 'axes' and also {both[0]!r}: a model holds one axis's "
                            "parts at the top level or several under 'axes', never both")
    record = FileRecord if isinstance(data, dict) and "axes" in data else _SINGLE_AXIS
    try:
        value = msgspec.convert(data, record, strict=True)
    except msgspec.ValidationError as exc:
        message, _, at = str(exc).partition(" - at `")
        where, value = _place(data, record, at.rstrip("`")) if at else ((), data)
        if value is None or isinstance(value, str | int | float):  # the value, as jsonschema
            message = f"{value!r} does not fit: {message}"
        raise _fail(source, _path(where), message) from None
    found = unknown_key(data, MODEL_SCHEMA, ())
    if found is not None:
        where, key, known = found
        raise _fail(source, _path(where) if where else "(top level)",
                    f"unknown key {key!r} (known here: {', '.join(known)}); a misspelt "
                    "key is ignored by hrgtc but not by the reader of the file")
    return value


def _place(data: Any, kind: Any, at: str) -> tuple[list[Any], Any]:
    """msgspec's place (``$.drift.settings.scales[...]``) with each ``[...]`` (a mapping's
    value, unnamed by msgspec) replaced by the key that does not fit
    (``drift.settings.scales.f``), and the value there."""
    parts: list[Any] = []
    for name, index, _ in re.findall(r"\.([^.\[]+)|\[(\d+)\]|(\[\.\.\.\])", at[1:]):
        kind = _member(kind, data)
        if name:
            fields = {f.name: f.type for f in msgspec.structs.fields(kind)} if isinstance(
                kind, type) and issubclass(kind, msgspec.Struct) else {}
            parts.append(name)
            data, kind = (data.get(name) if isinstance(data, dict) else None,
                          fields.get(name, Any))
        elif index:
            args = [a for a in get_args(kind) if a is not Ellipsis]
            item = args[min(int(index), len(args) - 1)] if args else Any
            parts.append(int(index))
            data = data[int(index)] if isinstance(data, list) and int(index) < len(data) else None
            kind = item
        else:  # a mapping's value: the first key whose value (or the key itself) fails
            key_type, value_type = (*get_args(kind), Any, Any)[:2]
            bad = next((k for k, v in (data.items() if isinstance(data, dict) else ())
                        if not _fits(v, value_type) or not _fits(k, key_type)), "[...]")
            parts.append(bad)
            data, kind = (data.get(bad) if isinstance(data, dict) else None), value_type
    return parts, data


def _member(kind: Any, value: Any) -> Any:
    """``kind`` without ``Annotated`` and, in a union, the member ``value`` is meant as."""
    while get_origin(kind) is Annotated:
        kind = get_args(kind)[0]
    args = get_args(kind)
    if get_origin(kind) in (Union, types.UnionType):
        wanted = dict if isinstance(value, dict) else list if isinstance(value, list) else None
        for member in args:
            plain = _member(member, value)
            if wanted is dict and (get_origin(plain) is dict or (
                    isinstance(plain, type) and issubclass(plain, msgspec.Struct))):
                return plain
            if wanted is list and get_origin(plain) in (list, tuple):
                return plain
        return Any
    return kind


def _fits(value: Any, kind: Any) -> bool:
    try:
        msgspec.convert(value, kind, strict=True)
    except msgspec.ValidationError:
        return False
    return True


#: Objects whose keys are free: the provenance (free-form) and the temperature map (keys
#: a newer version wrote are kept, ``thermometry.reference.TemperatureMapRecord``).
_OPEN_OBJECTS = ("provenance", "temperature_map")


def unknown_key(value: Any, schema: Mapping[str, Any], where: tuple[Any, ...]
                ) -> tuple[tuple[Any, ...], str, list[str]] | None:
    """The first key of ``value`` that its (already valid) schema does not know:
    ``(place, key, known keys)``, None when every key is known."""
    while "$ref" in schema:
        schema = MODEL_SCHEMA["$defs"][schema["$ref"].rsplit("/", 1)[1]]
    if "anyOf" in schema and value is not None:
        branches = [b for b in schema["anyOf"] if b.get("type") != "null"]
        schema = branches[0] if len(branches) == 1 else {}
    if isinstance(value, dict):
        properties = schema.get("properties")
        if properties is not None:
            for key, item in value.items():
                if key not in properties:
                    return where, key, list(properties)
                if key in _OPEN_OBJECTS and not where:
                    continue
                found = unknown_key(item, properties[key], (*where, key))
                if found is not None:
                    return found
        elif isinstance(schema.get("additionalProperties"), dict):
            for key, item in value.items():
                found = unknown_key(item, schema["additionalProperties"], (*where, key))
                if found is not None:
                    return found
    elif isinstance(value, list) and isinstance(schema.get("items"), dict):
        for i, item in enumerate(value):
            found = unknown_key(item, schema["items"], (*where, i))
            if found is not None:
                return found
    return None


def axis_parts(data: Mapping[str, Any]) -> dict[str, Any]:
    """Axis name -> the object holding that axis's parts (``""`` -> the document itself
    for a single-axis file)."""
    axes = data.get("axes")
    return {"": data} if axes is None else dict(axes)


#: ``value`` with every float that is not finite replaced by None (strict JSON).
strict = records.strict


def _agree(stored: float, derived: float, magnitude: float) -> bool:
    return abs(stored - derived) <= COEFFICIENT_RTOL * max(abs(magnitude), abs(derived)) + 1e-300


def _check_thermometer(therm: Mapping[str, Any], source: str, at: str = "") -> None:
    from hrgtc.thermometry.thermometer import _scaled_to_raw_matrix

    order = therm["order"]
    for name in ("coefficients", "scaled_coefficients", "standard_errors"):
        if len(therm[name]) != order + 1:
            raise _fail(source, f"{at}thermometer.{name}",
                        f"{len(therm[name])} values for a polynomial of order {order} "
                        f"(expected {order + 1})")
    low, high = therm["temperature_range_c"]
    if not low < high:
        raise _fail(source, f"{at}thermometer.temperature_range_c",
                    f"[{low!r}, {high!r}] is not an ordered range (low < high)")
    _check_thermometer_bounds(therm, source, at)
    matrix = _scaled_to_raw_matrix(order, therm["centre_c"], therm["scale_c"])
    scaled = [Fraction(v) for v in therm["scaled_coefficients"]]
    for i, row in enumerate(matrix):
        derived = float(sum(m * a for m, a in zip(row, scaled, strict=True)))
        magnitude = float(sum(abs(m * a) for m, a in zip(row, scaled, strict=True)))
        if not _agree(therm["coefficients"][i], derived, magnitude):
            raise _fail(source, f"{at}thermometer.coefficients[{i}]",
                        f"{therm['coefficients'][i]!r} disagrees with {derived!r} derived from "
                        "scaled_coefficients (the values used)")


def _check_thermometer_bounds(therm: Mapping[str, Any], source: str, at: str) -> None:
    """Refuse a thermometer whose F(T) over its calibrated range leaves what any HRG's
    frequency (a temperature sensor's reading) can be: an absurd coefficient."""
    import numpy as np

    from hrgtc.recording.checks import FREQ_SAMPLE_RANGE_HZ, TEMPERATURE_RANGE_C

    sensor = therm.get("source") == "sensor"
    low_t, high_t = therm["temperature_range_c"]
    u = (np.linspace(low_t, high_t, 33) - therm["centre_c"]) / therm["scale_c"]
    with np.errstate(all="ignore"):
        values = np.polynomial.polynomial.polyval(u, therm["scaled_coefficients"])
    low, high = TEMPERATURE_RANGE_C if sensor else FREQ_SAMPLE_RANGE_HZ
    worst = float(values[np.argmax(np.abs(values))]) if values.size else 0.0
    if not (np.all(np.isfinite(values)) and low <= values.min() and values.max() <= high):
        what = "a temperature sensor's reading" if sensor else "any HRG's resonator frequency"
        unit = "°C" if sensor else "Hz"
        raise _fail(source, f"{at}thermometer.scaled_coefficients",
                    f"F(T) over the calibrated {low_t:g} to {high_t:g} °C reaches {worst:.6g} "
                    f"{unit}, outside {what} ({low:g} to {high:g} {unit})")


def derived_coefficients(drift: Mapping[str, Any]) -> dict[str, float]:
    """User-unit coefficients from ``scaled_coefficients`` and the feature scales."""
    scales = drift["settings"].get("scales", {})
    terms = parse_terms(drift["selected"]) if drift["selected"] else ()
    return {t.name: float(c) / t.scale_factor(scales)
            for t, c in zip(terms, drift["scaled_coefficients"], strict=True)}


def _check_reference(drift: Mapping[str, Any], therm: Mapping[str, Any], where: str,
                     source: str) -> None:
    """f_ref must be the thermometer's frequency at the reference temperature."""
    import numpy as np

    settings = drift["settings"]
    u = (settings["reference_c"] - therm["centre_c"]) / therm["scale_c"]
    expected = float(np.polynomial.polynomial.polyval(u, therm["scaled_coefficients"]))
    if not _agree(settings["reference_freq_hz"], expected, expected * 1e-3):
        raise _fail(source, f"{where}.settings.reference_freq_hz",
                    f"{settings['reference_freq_hz']!r} Hz is not the thermometer's frequency "
                    f"{expected!r} Hz at the reference {settings['reference_c']!r} °C")


def _check_drift(drift: Mapping[str, Any], where: str, source: str) -> dict[str, float]:
    for name in ("candidates", "selected"):
        try:
            terms = parse_terms(drift[name]) if drift[name] else ()
        except InputError as exc:
            raise _fail(source, f"{where}.{name}", str(exc)) from None
        variables = {v for t in terms for v in t.variables}
        if name == "candidates":
            candidates = {t.name for t in terms}
        missing_scale = sorted(v for v in variables
                               if v not in drift["settings"].get("scales", {}))
        if name == "selected" and missing_scale:
            raise _fail(source, f"{where}.settings.scales",
                        f"no scale for variable(s) {missing_scale}")
    selected = [t.name for t in (parse_terms(drift["selected"]) if drift["selected"] else ())]
    unknown = [t for t in selected if t not in candidates]
    if unknown:
        raise _fail(source, f"{where}.selected", f"term(s) {unknown} are not among the candidates")
    if len(drift["scaled_coefficients"]) != len(selected):
        raise _fail(source, f"{where}.scaled_coefficients",
                    f"{len(drift['scaled_coefficients'])} values for {len(selected)} selected "
                    "term(s)")
    if set(drift["coefficients"]) != set(selected):
        raise _fail(source, f"{where}.coefficients",
                    f"terms {sorted(drift['coefficients'])} differ from the selected "
                    f"{sorted(selected)}")
    for variable in {v for t in parse_terms(selected) for v in t.variables} if selected else ():
        if variable not in drift["ranges"]:
            raise _fail(source, f"{where}.ranges", f"no training range for variable {variable!r}")
    for variable, (low, high) in drift["ranges"].items():
        if not low <= high:
            raise _fail(source, f"{where}.ranges.{variable}",
                        f"[{low!r}, {high!r}] is reversed (low > high)")
    _check_bounds(drift, where, source)
    derived = derived_coefficients(drift)
    for name, value in derived.items():
        if not _agree(drift["coefficients"][name], value, value):
            raise _fail(source, f"{where}.coefficients.{name}",
                        f"{drift['coefficients'][name]!r} disagrees with {value!r} derived from "
                        "scaled_coefficients (the values used)")
    return derived


def _check_bounds(drift: Mapping[str, Any], where: str, source: str) -> None:
    """Refuse an intercept or a term whose bias over the trained ranges no gyro can have.

    A term's largest magnitude over the box of the training ranges is |c| times the
    product of max(|low|, |high|)/scale to its powers (``scaled_coefficients`` act on
    the variables divided by their scales).
    """
    intercept = drift["intercept_dph"]
    if abs(intercept) > BIAS_BOUND_DPH:
        raise _fail(source, f"{where}.intercept_dph",
                    f"{intercept:.6g} °/h is beyond any gyro's bias (bound {BIAS_BOUND_DPH:.3g} "
                    "°/h = 10,000 °/s)")
    scales = drift["settings"].get("scales", {})
    ranges = drift["ranges"]
    terms = parse_terms(drift["selected"]) if drift["selected"] else ()
    for k, (term, c) in enumerate(zip(terms, drift["scaled_coefficients"], strict=True)):
        size = abs(float(c))
        for v, p in term.powers:
            low, high = ranges[v]
            size *= (max(abs(low), abs(high)) / scales[v]) ** p
        if not size <= BIAS_BOUND_DPH:  # also inf and NaN from an overflow
            raise _fail(source, f"{where}.scaled_coefficients[{k}]",
                        f"term {term.name} gives a bias of {size:.3g} °/h over its trained "
                        f"range, beyond any gyro's (bound {BIAS_BOUND_DPH:.3g} °/h = 10,000 "
                        "°/s)")


def _check_scale_bounds(sf: Mapping[str, Any], where: str, source: str) -> None:
    """Refuse a scale-factor model whose error over its range reaches 100 % (1e6 ppm)."""
    values = [("intercept_ppm", sf["intercept_ppm"])] + [
        (f"scaled_coefficients[{k}]", c) for k, c in enumerate(sf["scaled_coefficients"])]
    low, high = sf["freq_range_hz"]
    if not low <= high:
        raise _fail(source, f"{where}.freq_range_hz",
                    f"[{low!r}, {high!r}] is reversed (low > high)")
    reach = max(abs(low - sf["reference_hz"]), abs(high - sf["reference_hz"])) / sf["scale_hz"]
    terms = parse_terms(sf["selected"]) if sf.get("selected") else ()
    powers = [0] + [t.power_of("f") for t in terms]
    for (key, c), p in zip(values, powers, strict=False):
        size = abs(float(c)) * reach ** p
        if not size <= SCALE_BOUND_PPM:
            raise _fail(source, f"{where}.{key}",
                        f"{size:.3g} ppm of scale-factor error over the rate tables' range is "
                        f"beyond any gyro's (bound {SCALE_BOUND_PPM:.3g} ppm = 100 %)")


def check_document(data: Any, source: str, non_standard: bool = False) -> Any:
    """Validate a parsed model file; return it converted once (:func:`check_schema`), each
    axis's parts the records of their results (:func:`axis_records`), the drift models'
    coefficients the derived ones (:func:`hrgtc.core.records.built` gives the results).

    Parameters
    ----------
    data
        The parsed document (:func:`parse_model_json`).
    source
        The file, named in every message.
    non_standard
        The text held ``NaN`` or ``Infinity`` (allowed for statistics in version 1 only).

    Raises
    ------
    ModelFileError
        Names the place in the file (e.g. ``drift.ranges.f``), what is wrong and the fix.
    """
    version = data.get("schema_version") if isinstance(data, Mapping) else None
    if non_standard and isinstance(version, int) and version >= 2:
        raise ModelFileError(f"{source}: model file holds NaN or Infinity, which is not JSON "
                             f"(schema version {version} is strict JSON); it is corrupt or was "
                             "edited: recreate it with 'hrgtc calibrate'")
    value = check_schema(data, source)
    stored = data.get("parameters_sha256")
    if stored is not None and stored != parameters_sha256(data):
        raise ModelFileError(
            f"{source}: model file was changed after it was written (its content no longer "
            "matches its parameters_sha256): damaged or edited; recreate it with 'hrgtc "
            "calibrate' (after a deliberate edit, delete the parameters_sha256 line)")
    converted = axis_records(value)
    for axis, part in axis_parts(data).items():
        at = f"axes.{axis}." if axis else ""
        _check_thermometer(part["thermometer"], source, at)
        converted[axis].drift.coefficients = _check_drift(part["drift"], f"{at}drift", source)
        _check_reference(part["drift"], part["thermometer"], f"{at}drift", source)
        if part.get("housing") is not None:
            converted[axis].housing.coefficients = _check_drift(part["housing"],
                                                                 f"{at}housing", source)
        if part.get("scale_factor") is not None:
            _check_scale_bounds(part["scale_factor"], f"{at}scale_factor", source)
    return value


def axis_records(value: Any) -> dict[str, Any]:
    """Axis name -> the converted record holding its parts (``""`` -> the file's own
    for a single-axis file), of :func:`read_document`'s value."""
    return {"": value} if isinstance(value, _SINGLE_AXIS) else dict(value.axes)
