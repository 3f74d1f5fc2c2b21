"""The model file: one JSON document holding everything a unit's compensation needs.

:class:`Model` is the model of a unit or instrument, one :class:`AxisModel` per axis
(a single-axis unit is the one-axis case); :func:`load_model` reads every model file,
:func:`save_model` writes one. This is the one module that tells one axis from many.

Thermometer (Eq. 18 form), feature settings (reference, causal df/dt filter,
scales), drift model (Eq. 22 form), the optional classical housing-thermistor
baseline, the unit's plateau table, and provenance (input files with SHA-256,
settings, package version, time). The schema is versioned: a file of a newer
schema, a foreign JSON document or a corrupt one gets a clear error.

Every file is validated on loading against the JSON Schema of
:mod:`hrgtc.model_schema` plus the checks a schema cannot express (finite
parameters, ordered ranges, known terms, coefficients that agree with the scaled
ones prediction uses). Files are written as strict JSON (schema version 2:
statistics that are not finite become ``null``); version 1 files, whose
statistics may hold a bare ``NaN``, still load when they are otherwise valid.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from datetime import UTC, datetime
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from hrgtc.core import records
from hrgtc.core.errors import HrgtcError, InputError, ModelFileError
from hrgtc.core.files import file_sha256, write_text_atomic
from hrgtc.drift import DriftModel
from hrgtc.drift.scale_factor import ScaleFactorModel
from hrgtc.drift.training import TrainingStatistics
from hrgtc.model_schema import (
    SCHEMA_NAME,
    SCHEMA_VERSION,
    AxisRecord,
    DuplicateKeyError,
    FileRecord,
    axis_records,
    check_document,
    file_document,
    parameters_sha256,
    parse_model_json,
    strict,
)
from hrgtc.thermometry import Thermometer
from hrgtc.update import Lineage, UpdateResult, UpdateSettings, update_model

__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "AxisModel", "Model", "axis_suffix",
           "load_model", "model_sha256", "model_text", "provenance", "save_model"]

#: Schema version of files with one axis and no scale factor (unchanged since version 2).
_PLAIN_VERSION = 2
#: The parts of an axis a one-axis :class:`Model` reads through (``model.thermometer``).
_PART_NAMES = ("thermometer", "drift", "housing", "plateaus", "scale_factor", "training")


@dataclass(frozen=True)
class AxisModel:
    """One axis's parts of a model: thermometer, drift model, baseline, scale factor.

    Not a model of its own: a :class:`Model` holds one per axis (a single-axis unit is
    ``Model.single(part)``, the axis ``""``).

    Attributes
    ----------
    thermometer
        f(T) and its inverse.
    drift
        Bias model in f and df/dt.
    housing
        Classical baseline: bias model in housing temperature (None when the
        training runs had no ``housing_c``).
    plateaus
        The axis's Table 1: one record per soak plateau (plain JSON).
    scale_factor
        Scale-factor error against frequency from rate-table runs (None: not
        calibrated; compensation then removes the bias only).
    training
        Statistics of the training data (rate noise and level, sample rate) that a
        recording is checked against for unit mistakes (None: an older model file).
    """

    thermometer: Thermometer
    drift: DriftModel
    housing: DriftModel | None = None
    plateaus: tuple[dict[str, Any], ...] = ()
    scale_factor: ScaleFactorModel | None = None
    training: TrainingStatistics | None = None

    def parts(self) -> dict[str, Any]:
        """The axis's parts of the model file (thermometer, drift, housing, ...), as
        :class:`hrgtc.model_schema.AxisRecord` writes them."""
        return records.dump(self, AxisRecord)

    @classmethod
    def from_record(cls, record: Any) -> AxisModel:
        """One axis from its parts as :func:`model_schema.check_document` converted them
        (the records of the parts' results: each part is built, not converted again)."""
        parts = records.built(record)
        return cls(**{name: parts[name] for name in _PART_NAMES})


def axis_suffix(axis: str) -> str:
    """Column suffix of an axis: ``"_x"`` for axis ``"x"``, ``""`` for a single-axis model."""
    return f"_{axis}" if axis else ""


def _one_axis(name: str) -> property:
    """A read-only property of a one-axis model: the only axis's part ``name``."""

    def read(self: Model) -> Any:
        return getattr(self._only(name), name)

    read.__doc__ = (f"The only axis's ``{name}`` (:class:`AxisModel`); a multi-axis model "
                    f"raises :class:`~hrgtc.core.errors.InputError`: pick one with "
                    f"``model.axes[name].{name}``.")
    return property(read)


@dataclass(frozen=True)
class Model:
    """A calibrated unit or instrument: one :class:`AxisModel` per axis, in one model file.

    A single-axis unit is the one-axis case: ``axes == {"": part}``
    (:meth:`single`), and its file is the single-axis model file (the parts at the
    top level). A multi-axis file (schema version 3) holds each axis's thermometer,
    drift model, housing baseline, plateaus and scale factor under ``axes``. For the
    one-axis case the parts read through: ``model.thermometer`` is
    ``model.axes[""].thermometer`` (on a multi-axis model they raise, naming the axes).

    Attributes
    ----------
    axes
        Axis name -> that axis's parts (names as the recording's column suffixes,
        ``""`` for a single-axis unit).
    unit
        Serial or name of the unit or instrument.
    provenance
        Inputs with SHA-256, settings, package version, creation time.
    temperature_map
        The count -> °C map of a raw temperature sensor fitted to a reference log
        (``calibrate --temp-ref``, :class:`hrgtc.thermometry.reference.TemperatureMap`
        as a dict), applied to the raw count at compensation; None without one.
    lineage
        An in-field update's parent, data and changes
        (:class:`~hrgtc.update.lineage.Lineage`, :meth:`update`); None for a calibrated
        model.
    """

    axes: dict[str, AxisModel]
    unit: str = "unknown"
    provenance: dict[str, Any] = field(default_factory=dict)
    temperature_map: dict[str, Any] | None = None
    lineage: Lineage | None = None

    def __post_init__(self) -> None:
        if not self.axes:
            raise ModelFileError("a model needs at least one axis")
        if "" in self.axes and len(self.axes) > 1:
            raise ModelFileError("the unnamed axis is the single-axis case; name every axis")

    @classmethod
    def single(cls, part: AxisModel, unit: str = "unknown",
               provenance: Mapping[str, Any] | None = None,
               temperature_map: Mapping[str, Any] | None = None) -> Model:
        """The one-axis model (axis ``""``) of ``part``."""
        return cls({"": part}, unit, dict(provenance or {}),
                   None if temperature_map is None else dict(temperature_map))

    @property
    def is_single_axis(self) -> bool:
        """True for the one-axis case (plain single-axis columns and file)."""
        return list(self.axes) == [""]

    @property
    def names(self) -> tuple[str, ...]:
        """Axis names in file order (``("",)`` for a single-axis model)."""
        return tuple(self.axes)

    def of_axis(self, name: str) -> Model:
        """The one-axis model of axis ``name`` (its parts as the axis ``""``; the unit,
        provenance and temperature map of this model)."""
        if name not in self.axes:
            raise InputError(f"the model of {self.unit!r} has no axis {name!r} (its axes: "
                             f"{', '.join(a or '-' for a in self.axes)})")
        return Model.single(self.axes[name], self.unit, self.provenance, self.temperature_map)

    def with_parts(self, **parts: Any) -> Model:
        """This one-axis model with parts of its axis replaced (``model.with_parts(drift=d)``,
        as :func:`dataclasses.replace` on the axis); a multi-axis model raises."""
        part = self._only()  # a multi-axis model raises
        (name,) = self.axes
        return replace(self, axes={name: replace(part, **parts)})

    @property
    def axis(self) -> AxisModel:
        """The only axis's parts; a multi-axis model raises, naming its axes."""
        return self._only()

    def _only(self, part: str = "") -> AxisModel:
        if len(self.axes) == 1:
            return next(iter(self.axes.values()))
        first = next(iter(self.axes))
        raise InputError(
            f"the model of {self.unit!r} has axes {', '.join(self.axes)}: pick one: "
            f"model.axes[{first!r}]{'.' + part if part else ''}")

    thermometer = _one_axis("thermometer")
    drift = _one_axis("drift")
    housing = _one_axis("housing")
    plateaus = _one_axis("plateaus")
    scale_factor = _one_axis("scale_factor")
    training = _one_axis("training")

    def to_dict(self) -> dict[str, Any]:
        """The model file's JSON document (:class:`~hrgtc.model_schema.FileRecord`): one
        axis's parts at the top level, or each axis's under ``axes``; the temperature map
        as it was read or fitted (keys a newer version wrote are kept)."""
        if self.is_single_axis:
            parts = self.axes[""].parts()
            version = SCHEMA_VERSION if "scale_factor" in parts else _PLAIN_VERSION
            return file_document(_head(self, version, single=True), parts,
                                 self.temperature_map)
        return file_document(_head(self, SCHEMA_VERSION), None, self.temperature_map)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "model",
                  non_standard: bool = False) -> Model:
        """Inverse of :meth:`to_dict`, with schema checks (:func:`model_schema.check_document`).

        ``non_standard``: the document's text held ``NaN``/``Infinity``.
        """
        if not isinstance(data, Mapping) or data.get("schema") != SCHEMA_NAME:
            found = data.get("schema") if isinstance(data, Mapping) else type(data).__name__
            raise ModelFileError(
                f"{source}: not an hrgtc model file (schema {found!r}, expected "
                f"{SCHEMA_NAME!r}); create one with 'hrgtc calibrate'"
            )
        version = data.get("schema_version")
        if not isinstance(version, int):
            raise ModelFileError(f"{source}: schema_version {version!r} is not an integer")
        if version > SCHEMA_VERSION:
            raise ModelFileError(
                f"{source}: model schema version {version} is newer than this hrgtc "
                f"understands ({SCHEMA_VERSION}); upgrade hrgtc"
            )
        checked = check_document(strict(dict(data)), source, non_standard)
        temperature_map = _temperature_map(data, checked, source)
        try:
            axes = {name: AxisModel.from_record(part)
                    for name, part in axis_records(checked).items()}
            lineage = None if checked.lineage is None else records.built(checked.lineage)
        except HrgtcError as exc:
            raise ModelFileError(f"{source}: model file is corrupt: {exc}") from exc
        return cls(axes, checked.unit, dict(checked.provenance), temperature_map, lineage)

    @property
    def sha256(self) -> str:
        """SHA-256 of the parameters as canonical JSON (see :func:`model_sha256`)."""
        return model_sha256(self)

    def update(self, recordings: Any, settings: UpdateSettings | None = None, *,
               still_s: Any = None, parent: str | os.PathLike[str] | None = None,
               read_options: Any = None) -> UpdateResult:
        """An in-field update from the still periods of new recordings (issue 29):
        :func:`hrgtc.update.update_model` with this model as the prior.

        ``parent``: the file this model was read from (its bytes go into the lineage, so
        that a rollback restores it byte for byte); None: the bytes :func:`save_model`
        writes of this model. The result's ``model`` is the updated model (None when the
        recordings changed nothing); refusals raise
        :class:`~hrgtc.update.UpdateRefused`. See docs/guide/update.md.
        """
        content = (Path(parent).read_bytes() if parent is not None
                   else model_text(self).encode("utf-8"))
        return update_model(self, recordings, settings, still_s=still_s, parent_bytes=content,
                            parent_path=str(parent or "<model>"), read_options=read_options)


def _head(model: Model, version: int, single: bool = False) -> dict[str, Any]:
    """The file's own fields (:class:`~hrgtc.model_schema.FileRecord`) of ``model``: a
    single-axis file has no ``axes`` (its parts sit at the top level); an instrument's
    axes are dumped by their record (:class:`~hrgtc.model_schema.AxisRecord`)."""
    source: Any = SimpleNamespace(unit=model.unit, provenance=model.provenance,
                                  lineage=model.lineage) if single else model
    return records.dump(source, FileRecord, schema=SCHEMA_NAME, schema_version=version,
                        temperature_map=None)


def _temperature_map(data: Mapping[str, Any], checked: Any,
                     source: str) -> dict[str, Any] | None:
    """The document's ``temperature_map`` as written (None without one), checked from its
    converted record (:func:`model_schema.check_document`), not converted again."""
    if checked.temperature_map is None:
        return None
    from hrgtc.thermometry.reference import TemperatureMap

    try:
        TemperatureMap.from_values(records.built(checked.temperature_map))
    except HrgtcError as exc:
        raise ModelFileError(f"{source}: {exc}") from None
    return dict(data["temperature_map"])


def model_sha256(model: Model) -> str:
    """SHA-256 of the model's parameters as canonical JSON (sorted keys, strict, no provenance).

    Written into the model file as ``parameters_sha256`` and into the mark of every
    output compensated with the model.
    """
    return parameters_sha256(model.to_dict())


def provenance(inputs: Mapping[str, list[str]], settings: Mapping[str, Any],
               hashed: Mapping[str, str] | None = None) -> dict[str, Any]:
    """Provenance record: input files (role, path, SHA-256), settings, version, UTC time.

    ``hashed``: path -> SHA-256 of files hashed by the same command a moment ago (an
    instrument's record repeats its axes' inputs), not read again.
    """
    from hrgtc.core.meta import __version__

    files = []
    known = dict(hashed or {})
    for role, paths in inputs.items():
        for path in paths:
            digest = known.get(str(path)) or file_sha256(path)
            files.append({"role": role, "path": str(path), "sha256": digest})
    return {
        "inputs": files,
        "settings": dict(settings),
        "hrgtc_version": __version__,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def save_model(model: Model, path: str | os.PathLike[str], force: bool = False) -> Path:
    """Write the model file atomically as strict JSON (refuses to overwrite without ``force``):
    one file for every axis (a single-axis model writes the single-axis file).

    Raises
    ------
    ModelFileError
        The model does not pass the checks of loading (e.g. a coefficient that is
        not finite): such a file is never written.
    """
    return _save_document(model.to_dict(), path, force)


def _save_document(document: dict[str, Any], path: str | os.PathLike[str], force: bool) -> Path:
    return write_text_atomic(path, _document_text(document, str(path)), force=force)


def _document_text(document: dict[str, Any], source: str) -> str:
    document = strict(document)
    document["parameters_sha256"] = parameters_sha256(document)
    check_document(document, source)
    return json.dumps(document, indent=2, allow_nan=False) + "\n"


def model_text(model: Model) -> str:
    """The text :func:`save_model` writes of ``model`` (checked as on loading)."""
    return _document_text(model.to_dict(), "model")


def load_model(path: str | os.PathLike[str]) -> Model:
    """Read any model file written by :func:`save_model` (or ``hrgtc calibrate``): single-
    or multi-axis, of every schema version.

    Raises
    ------
    ModelFileError
        Unreadable, not JSON, foreign, corrupt or of a newer schema.
    """
    data, non_standard = _read_document(path)
    return Model.from_dict(data, source=str(path), non_standard=non_standard)


def _read_document(path: str | os.PathLike[str]) -> tuple[Any, bool]:
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelFileError(f"{source}: no such model file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{source}: cannot read model file: {exc}") from exc
    try:
        data, non_standard = parse_model_json(text)
    except DuplicateKeyError as exc:
        raise ModelFileError(exc.describe(source, text)) from None
    except json.JSONDecodeError as exc:
        raise ModelFileError(
            f"{source}: not a JSON document (line {exc.lineno}, column {exc.colno}: {exc.msg}); "
            "is it an hrgtc model file?"
        ) from exc
    except RecursionError:
        raise ModelFileError(f"{source}: not a model file (nested too deeply)") from None
    return data, non_standard
