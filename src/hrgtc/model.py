"""The model file: one JSON document holding everything a unit's compensation needs.

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
from typing import Any

from hrgtc.core import records
from hrgtc.core.errors import HrgtcError, ModelFileError
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
    axis_parts,
    check_document,
    file_document,
    parameters_sha256,
    parse_model_json,
    strict,
)
from hrgtc.thermometry import Thermometer

__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "InstrumentModel", "UnitModel", "axis_suffix",
           "load_instrument", "load_model", "model_sha256", "provenance", "save_instrument",
           "save_model"]

#: Schema version of files with one axis and no scale factor (unchanged since version 2).
_PLAIN_VERSION = 2


@dataclass(frozen=True)
class UnitModel:
    """A calibrated unit: thermometer, drift model and where they came from.

    Attributes
    ----------
    thermometer
        f(T) and its inverse.
    drift
        Bias model in f and df/dt.
    housing
        Classical baseline: bias model in housing temperature (None when the
        training runs had no ``housing_c``).
    unit
        Serial or name of the gyro.
    plateaus
        The unit's Table 1: one record per soak plateau (plain JSON).
    provenance
        Inputs with SHA-256, settings, package version, creation time.
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
    unit: str = "unknown"
    plateaus: tuple[dict[str, Any], ...] = ()
    provenance: dict[str, Any] = field(default_factory=dict)
    scale_factor: ScaleFactorModel | None = None
    training: TrainingStatistics | None = None

    def parts(self) -> dict[str, Any]:
        """The axis's parts of the model file (thermometer, drift, housing, ...), as
        :class:`hrgtc.model_schema.AxisRecord` writes them."""
        return records.dump(self, AxisRecord)

    def to_dict(self) -> dict[str, Any]:
        """The model file's JSON document: :class:`~hrgtc.model_schema.FileRecord`'s fields
        with the axis's parts (:class:`~hrgtc.model_schema.AxisRecord`) at the top level."""
        parts = self.parts()
        version = SCHEMA_VERSION if "scale_factor" in parts else _PLAIN_VERSION
        return file_document(_head(self, version), parts)

    @classmethod
    def from_parts(cls, data: Mapping[str, Any], unit: str,
                   provenance: Mapping[str, Any]) -> UnitModel:
        """One axis from its checked parts (see :func:`model_schema.check_document`)."""
        housing = data.get("housing")
        scale_factor = data.get("scale_factor")
        training = data.get("training")
        return cls(
            thermometer=Thermometer.from_dict(data["thermometer"]),
            drift=DriftModel.from_dict(data["drift"]),
            housing=None if housing is None else DriftModel.from_dict(housing),
            unit=unit,
            plateaus=tuple(data.get("plateaus", ())),
            provenance=dict(provenance),
            scale_factor=None if scale_factor is None else ScaleFactorModel.from_dict(scale_factor),
            training=None if training is None else TrainingStatistics.from_dict(training),
        )

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "model",
                  non_standard: bool = False) -> UnitModel:
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
        if "axes" in data:
            names = ", ".join(data["axes"]) if isinstance(data["axes"], Mapping) else "?"
            raise ModelFileError(
                f"{source}: a multi-axis model file (axes {names}); load it with "
                "hrgtc.model.load_instrument, or pick one axis with InstrumentModel.axes[name]"
            )
        data = check_document(strict(dict(data)), source, non_standard)
        head = _read_head(data, source)
        try:
            return cls.from_parts(data, head["unit"], head["provenance"])
        except KeyError as exc:
            raise ModelFileError(f"{source}: model file is missing {exc}; it is corrupt") from exc
        except HrgtcError as exc:
            raise ModelFileError(f"{source}: model file is corrupt: {exc}") from exc

    @property
    def sha256(self) -> str:
        """SHA-256 of the model's canonical JSON (independent of file layout and provenance)."""
        return model_sha256(self)


def axis_suffix(axis: str) -> str:
    """Column suffix of an axis: ``"_x"`` for axis ``"x"``, ``""`` for a single-axis model."""
    return f"_{axis}" if axis else ""


@dataclass(frozen=True)
class InstrumentModel:
    """A calibrated instrument: one :class:`UnitModel` per axis, in one model file.

    A single-axis model is the one-axis case: ``axes == {"": model}``, and its file is
    exactly a single-axis model file. A multi-axis file (schema version 3) holds each
    axis's thermometer, drift model, housing baseline, plateaus and scale factor under
    ``axes``.

    Attributes
    ----------
    axes
        Axis name -> that axis's model (names as the recording's column suffixes).
    unit
        Serial or name of the instrument.
    provenance
        Inputs with SHA-256, settings, package version, creation time.
    temperature_map
        The count -> °C map of a raw temperature sensor fitted to a reference log
        (``calibrate --temp-ref``, :class:`hrgtc.thermometry.reference.TemperatureMap`
        as a dict), applied to the raw count at compensation; None without one.
    """

    axes: dict[str, UnitModel]
    unit: str = "unknown"
    provenance: dict[str, Any] = field(default_factory=dict)
    temperature_map: dict[str, Any] | None = None

    def __post_init__(self) -> None:
        if not self.axes:
            raise ModelFileError("an instrument model needs at least one axis")
        if "" in self.axes and len(self.axes) > 1:
            raise ModelFileError("the unnamed axis is the single-axis case; name every axis")

    @classmethod
    def single(cls, model: UnitModel) -> InstrumentModel:
        """The one-axis instrument of a single-axis model."""
        return cls({"": model}, model.unit, dict(model.provenance))

    @property
    def is_single_axis(self) -> bool:
        """True for the one-axis case (plain single-axis columns and file)."""
        return list(self.axes) == [""]

    @property
    def names(self) -> tuple[str, ...]:
        """Axis names in file order (``("",)`` for a single-axis model)."""
        return tuple(self.axes)

    def to_dict(self) -> dict[str, Any]:
        """The model file's JSON document (:class:`~hrgtc.model_schema.FileRecord`): one
        axis's parts at the top level, or each axis's under ``axes``; the temperature map
        as it was read or fitted (keys a newer version wrote are kept)."""
        if self.is_single_axis:
            axis = replace(self.axes[""], unit=self.unit, provenance=self.provenance)
            parts = axis.parts()
            version = SCHEMA_VERSION if "scale_factor" in parts else _PLAIN_VERSION
            return file_document(_head(axis, version), parts, self.temperature_map)
        return file_document(_head(self, SCHEMA_VERSION), None, self.temperature_map)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "model",
                  non_standard: bool = False) -> InstrumentModel:
        """Inverse of :meth:`to_dict`, with the checks of :meth:`UnitModel.from_dict`."""
        temperature_map = _temperature_map(data, source)
        if not (isinstance(data, Mapping) and "axes" in data):
            single = cls.single(UnitModel.from_dict(data, source, non_standard))
            return single if temperature_map is None else replace(
                single, temperature_map=temperature_map)
        if data.get("schema") != SCHEMA_NAME:
            raise ModelFileError(f"{source}: not an hrgtc model file (schema "
                                 f"{data.get('schema')!r}, expected {SCHEMA_NAME!r})")
        version = data.get("schema_version")
        if isinstance(version, int) and version > SCHEMA_VERSION:
            raise ModelFileError(
                f"{source}: model schema version {version} is newer than this hrgtc "
                f"understands ({SCHEMA_VERSION}); upgrade hrgtc"
            )
        checked = check_document(strict(dict(data)), source, non_standard)
        head = _read_head(checked, source)
        unit, provenance = head["unit"], head["provenance"]
        try:
            axes = {name: UnitModel.from_parts(part, unit, provenance)
                    for name, part in axis_parts(checked).items()}
        except KeyError as exc:
            raise ModelFileError(f"{source}: model file is missing {exc}; it is corrupt") from exc
        except HrgtcError as exc:
            raise ModelFileError(f"{source}: model file is corrupt: {exc}") from exc
        return cls(axes, unit, provenance, temperature_map)

    @property
    def sha256(self) -> str:
        """SHA-256 of the parameters as canonical JSON (see :func:`model_sha256`)."""
        return parameters_sha256(self.to_dict())


def _head(model: UnitModel | InstrumentModel, version: int) -> dict[str, Any]:
    """The file's own fields (:class:`~hrgtc.model_schema.FileRecord`) of ``model``: a
    :class:`UnitModel` has no ``axes``; an instrument's axes are dumped by their record
    (:class:`~hrgtc.model_schema.AxisRecord`)."""
    return records.dump(model, FileRecord, schema=SCHEMA_NAME, schema_version=version,
                        temperature_map=None)


def _read_head(checked: Mapping[str, Any], source: str) -> dict[str, Any]:
    """The file's own fields of a checked document, read by :class:`FileRecord` (each
    axis's parts are read by the records of the parts, :meth:`UnitModel.from_parts`)."""
    try:
        return records.load({k: checked[k] for k in ("schema", "schema_version", "unit",
                                                     "provenance") if k in checked},
                            FileRecord, "model file")
    except HrgtcError as exc:
        raise ModelFileError(f"{source}: {exc}") from None


def _temperature_map(data: Any, source: str) -> dict[str, Any] | None:
    """The document's ``temperature_map``, checked (None without one)."""
    if not isinstance(data, Mapping) or data.get("temperature_map") is None:
        return None
    from hrgtc.thermometry.reference import TemperatureMap

    raw = data["temperature_map"]
    if not isinstance(raw, Mapping):
        raise ModelFileError(f"{source}: temperature_map is {raw!r}, not an object")
    try:
        TemperatureMap.from_dict(raw)
    except HrgtcError as exc:
        raise ModelFileError(f"{source}: {exc}") from None
    return dict(raw)


def model_sha256(model: UnitModel) -> str:
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


def save_instrument(model: InstrumentModel, path: str | os.PathLike[str],
                    force: bool = False) -> Path:
    """Write an instrument's model file (one file, every axis); as :func:`save_model`."""
    return _save_document(model.to_dict(), path, force)


def save_model(model: UnitModel, path: str | os.PathLike[str], force: bool = False) -> Path:
    """Write the model file atomically as strict JSON (refuses to overwrite without ``force``).

    Raises
    ------
    ModelFileError
        The model does not pass the checks of loading (e.g. a coefficient that is
        not finite): such a file is never written.
    """
    return _save_document(model.to_dict(), path, force)


def _save_document(document: dict[str, Any], path: str | os.PathLike[str], force: bool) -> Path:
    document = strict(document)
    document["parameters_sha256"] = parameters_sha256(document)
    check_document(document, str(path))
    text = json.dumps(document, indent=2, allow_nan=False)
    return write_text_atomic(path, text + "\n", force=force)


def load_model(path: str | os.PathLike[str]) -> UnitModel:
    """Read a single-axis model file written by :func:`save_model` (or ``hrgtc calibrate``).

    Raises
    ------
    ModelFileError
        Unreadable, not JSON, foreign, corrupt, of a newer schema, or multi-axis
        (read those with :func:`load_instrument`).
    """
    data, non_standard = _read_document(path)
    return UnitModel.from_dict(data, source=str(path), non_standard=non_standard)


def load_instrument(path: str | os.PathLike[str]) -> InstrumentModel:
    """Read any model file, single- or multi-axis, as an :class:`InstrumentModel`.

    Raises
    ------
    ModelFileError
        As :func:`load_model`.
    """
    data, non_standard = _read_document(path)
    return InstrumentModel.from_dict(data, source=str(path), non_standard=non_standard)


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
