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
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from hrgtc.drift import DriftModel
from hrgtc.errors import HrgtcError, ModelFileError
from hrgtc.files import file_sha256, write_text_atomic
from hrgtc.model_schema import (
    SCHEMA_NAME,
    SCHEMA_VERSION,
    check_document,
    parameters_sha256,
    parse_model_json,
    strict,
)
from hrgtc.thermometry import Thermometer

__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "UnitModel", "load_model", "model_sha256",
           "provenance", "save_model"]


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
    """

    thermometer: Thermometer
    drift: DriftModel
    housing: DriftModel | None = None
    unit: str = "unknown"
    plateaus: tuple[dict[str, Any], ...] = ()
    provenance: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """The model file's JSON document."""
        return {
            "schema": SCHEMA_NAME,
            "schema_version": SCHEMA_VERSION,
            "unit": self.unit,
            "thermometer": self.thermometer.to_dict(),
            "drift": self.drift.to_dict(),
            "housing": None if self.housing is None else self.housing.to_dict(),
            "plateaus": list(self.plateaus),
            "provenance": dict(self.provenance),
        }

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
        data = check_document(strict(dict(data)), source, non_standard)
        try:
            housing = data.get("housing")
            return cls(
                thermometer=Thermometer.from_dict(data["thermometer"]),
                drift=DriftModel.from_dict(data["drift"]),
                housing=None if housing is None else DriftModel.from_dict(housing),
                unit=str(data.get("unit", "unknown")),
                plateaus=tuple(data.get("plateaus", ())),
                provenance=dict(data.get("provenance", {})),
            )
        except KeyError as exc:
            raise ModelFileError(f"{source}: model file is missing {exc}; it is corrupt") from exc
        except HrgtcError as exc:
            raise ModelFileError(f"{source}: model file is corrupt: {exc}") from exc

    @property
    def sha256(self) -> str:
        """SHA-256 of the model's canonical JSON (independent of file layout and provenance)."""
        return model_sha256(self)


def model_sha256(model: UnitModel) -> str:
    """SHA-256 of the model's parameters as canonical JSON (sorted keys, strict, no provenance).

    Written into the model file as ``parameters_sha256`` and into the mark of every
    output compensated with the model.
    """
    return parameters_sha256(model.to_dict())


def provenance(inputs: Mapping[str, list[str]], settings: Mapping[str, Any]) -> dict[str, Any]:
    """Provenance record: input files (role, path, SHA-256), settings, version, UTC time."""
    from hrgtc._meta import __version__

    files = []
    for role, paths in inputs.items():
        for path in paths:
            files.append({"role": role, "path": str(path), "sha256": file_sha256(path)})
    return {
        "inputs": files,
        "settings": dict(settings),
        "hrgtc_version": __version__,
        "created_utc": datetime.now(UTC).isoformat(timespec="seconds"),
    }


def save_model(model: UnitModel, path: str | os.PathLike[str], force: bool = False) -> Path:
    """Write the model file atomically as strict JSON (refuses to overwrite without ``force``).

    Raises
    ------
    ModelFileError
        The model does not pass the checks of loading (e.g. a coefficient that is
        not finite): such a file is never written.
    """
    document = strict(model.to_dict())
    document["parameters_sha256"] = parameters_sha256(document)
    check_document(document, str(path))
    text = json.dumps(document, indent=2, allow_nan=False)
    return write_text_atomic(path, text + "\n", force=force)


def load_model(path: str | os.PathLike[str]) -> UnitModel:
    """Read a model file written by :func:`save_model` (or ``hrgtc calibrate``).

    Raises
    ------
    ModelFileError
        Unreadable, not JSON, foreign, corrupt, or of a newer schema.
    """
    source = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ModelFileError(f"{source}: no such model file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{source}: cannot read model file: {exc}") from exc
    try:
        data, non_standard = parse_model_json(text)
    except json.JSONDecodeError as exc:
        raise ModelFileError(
            f"{source}: not a JSON document (line {exc.lineno}, column {exc.colno}: {exc.msg}); "
            "is it an hrgtc model file?"
        ) from exc
    except RecursionError:
        raise ModelFileError(f"{source}: not a model file (nested too deeply)") from None
    return UnitModel.from_dict(data, source=source, non_standard=non_standard)
