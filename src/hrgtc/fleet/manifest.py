"""A fleet on disk: which files belong to which unit, and in which role.

Two ways to say it:

* a **manifest**, CSV or YAML, one entry per file with ``unit, role, path``
  (role ``soak``, ``drift`` or ``validate``; a relative path is relative to the
  manifest's folder). CSV has a header line ``unit,role,path``; YAML is a list
  of mappings with those keys (or ``{files: [...]}``);
* the **convention**, without a manifest: ``ROOT/<unit>/soaks/*``,
  ``ROOT/<unit>/drift/*`` and ``ROOT/<unit>/validate/*`` with recording
  suffixes (``.parquet``, ``.csv``, ``.h5``, ...), what ``hrgtc fleet simulate``
  writes.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.recording.formats.registry import is_recording

__all__ = ["ROLES", "UnitFiles", "load_fleet", "read_manifest", "scan_root"]

PathLike = str | os.PathLike[str]
#: Roles of a unit's files and their folders under the convention.
ROLES = {"soak": "soaks", "drift": "drift", "validate": "validate"}


@dataclass(frozen=True)
class UnitFiles:
    """One unit's recordings by role (paths as strings, sorted within a role)."""

    unit: str
    soaks: tuple[str, ...] = ()
    drifts: tuple[str, ...] = ()
    validate: tuple[str, ...] = ()
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def paths(self) -> tuple[str, ...]:
        """Every file of the unit, soaks first."""
        return (*self.soaks, *self.drifts, *self.validate)

    def roles(self) -> dict[str, list[str]]:
        """``{"soak": [...], "drift": [...], "validate": [...]}`` (as model provenance)."""
        return {"soak": list(self.soaks), "drift": list(self.drifts),
                "validate": list(self.validate)}


def _unit_files(entries: Iterable[tuple[str, str, str]], source: str) -> list[UnitFiles]:
    by_unit: dict[str, dict[str, list[str]]] = {}
    for unit, role, path in entries:
        by_unit.setdefault(unit, {r: [] for r in ROLES})[role].append(path)
    return [UnitFiles(unit, tuple(sorted(r["soak"])), tuple(sorted(r["drift"])),
                      tuple(sorted(r["validate"])))
            for unit, r in sorted(by_unit.items())]


def _entry(record: Mapping[str, Any], where: str, base: Path) -> tuple[str, str, str]:
    missing = [k for k in ("unit", "role", "path") if not str(record.get(k) or "").strip()]
    if missing:
        raise InputError(f"{where}: missing {', '.join(missing)}; each entry needs unit, role "
                         "and path")
    role = str(record["role"]).strip().lower()
    if role not in ROLES:
        raise InputError(f"{where}: role {record['role']!r} is not one of "
                         f"{', '.join(ROLES)}")
    unit = str(record["unit"]).strip()
    if Path(unit).name != unit or unit in (".", ".."):
        raise InputError(f"{where}: unit name {unit!r} cannot name a model file; rename it")
    path = Path(str(record["path"]).strip())
    return unit, role, str(path if path.is_absolute() else base / path)


def read_manifest(path: PathLike) -> list[UnitFiles]:
    """The units of a manifest file (``.csv``, ``.yaml`` or ``.yml``).

    Raises
    ------
    InputError
        Unknown suffix, missing column or key, unknown role (the message gives the
        line or entry).
    """
    path = Path(path)
    base = path.parent
    suffix = path.suffix.lower()
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"{path}: no such manifest") from None
    if suffix == ".csv":
        reader = csv.DictReader(text.splitlines())
        header = [h.strip() for h in reader.fieldnames or []]
        if not {"unit", "role", "path"} <= set(header):
            raise InputError(f"{path}: the header must name unit, role and path, found {header}")
        entries = [
            _entry({k.strip(): v for k, v in row.items() if k}, f"{path} line {n}", base)
            for n, row in enumerate(reader, start=2) if any((v or "").strip()
                                                           for v in row.values())]
    elif suffix in (".yaml", ".yml"):
        import yaml

        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise InputError(f"{path}: not valid YAML: {exc}") from exc
        if isinstance(data, Mapping):
            data = data.get("files")
        if not isinstance(data, list):
            raise InputError(f"{path}: expected a list of {{unit, role, path}} entries")
        entries = []
        for n, record in enumerate(data, start=1):
            if not isinstance(record, Mapping):
                raise InputError(f"{path} entry {n}: expected a mapping with unit, role, path")
            entries.append(_entry(record, f"{path} entry {n}", base))
    else:
        raise InputError(f"{path}: a manifest is .csv or .yaml, not {suffix!r}")
    if not entries:
        raise InputError(f"{path}: the manifest lists no files")
    return _unit_files(entries, str(path))


def scan_root(root: PathLike) -> list[UnitFiles]:
    """The units under ``ROOT/<unit>/{soaks,drift,validate}/`` (the convention)."""
    root = Path(root)
    if not root.is_dir():
        raise InputError(f"{root}: no such fleet folder")
    entries = []
    for unit_dir in sorted(p for p in root.iterdir() if p.is_dir()):
        for role, folder in ROLES.items():
            for file in sorted((unit_dir / folder).glob("*")):
                if is_recording(file) and file.is_file():
                    entries.append((unit_dir.name, role, str(file)))
    if not entries:
        raise InputError(f"{root}: no unit folders with soaks/, drift/ or validate/ recordings; "
                         "lay them out as ROOT/<unit>/soaks/*.parquet or give a manifest")
    return _unit_files(entries, str(root))


def load_fleet(source: PathLike, units: Iterable[str] | None = None) -> list[UnitFiles]:
    """The fleet of a manifest file or a folder laid out by the convention.

    Parameters
    ----------
    source
        A manifest (``.csv``, ``.yaml``), a folder holding ``manifest.csv`` /
        ``manifest.yaml``, or a folder laid out as ``ROOT/<unit>/<role>/``.
    units
        Keep only these units (None: all).
    """
    source = Path(source)
    if source.is_dir():
        for name in ("manifest.csv", "manifest.yaml", "manifest.yml"):
            if (source / name).is_file():
                source = source / name
                break
    fleet = read_manifest(source) if source.is_file() else scan_root(source)
    if units is not None:
        wanted = set(units)
        unknown = sorted(wanted - {u.unit for u in fleet})
        if unknown:
            raise InputError(f"unit(s) {unknown} are not in the fleet {source}")
        fleet = [u for u in fleet if u.unit in wanted]
    return fleet
