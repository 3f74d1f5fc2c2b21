"""The campaign manifest: which runs a test report reads, what each run is, and what a lab signs.

A manifest is a small TOML file the user writes (docs/guide/test-report.md)::

    title = "Acceptance test"            # optional
    [unit]
    serial = "SN-0042"
    firmware = "2.3.1"
    model = "unit.json"                  # optional: the compensation model (before/after)
    file_axis = "x"                      # optional: the axis of a multi-axis file
    [site]
    latitude_deg = 41.675                # Earth rate: 15.041 °/h (cos φ n + sin φ u)
    axis = "up"                          # or north/east/south/west/down, or [n, e, u]
    [conditions]                         # free text, shown as written
    ambient = "23 ± 2 °C"
    [[equipment]]
    item = "thermal chamber"
    id = "TC-07"
    certificate = "DAkkS D-K-12345 2026-03-01"
    [settings]                           # see :class:`CampaignSettings`
    turn_on_tolerance_dph = 0.5
    [[runs]]
    file = "turnon_day1.parquet"         # relative to the manifest's folder
    role = "turn-on"                     # turn-on, soak, sweep or rate-table
    day = "2026-11-02"
    [[runs]]
    file = "soak_-20C.parquet"
    role = "soak"
    settle_s = 14400                     # this run's own settling time (default: [settings])

The roles say what each run is, so nothing is guessed from a file's name or contents:
a turn-on is recorded from power-on at a constant temperature; a soak holds one
temperature; a sweep changes it (ramps, with or without holds); a rate-table run holds
known input rates (its ``input_rate_dph`` column). :func:`load_campaign` checks the file
once and names the key, the value and the fix of anything wrong.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from hrgtc.core.errors import InputError

__all__ = ["AXES_NEU", "EARTH_RATE_DPH", "ROLES", "Campaign", "CampaignSettings", "Equipment",
           "RunEntry", "earth_rate_component_dph", "load_campaign"]

#: Earth's rotation rate, WGS 84 (ω = 7.292115e-5 rad/s). [°/h]
EARTH_RATE_DPH = math.degrees(7.292115e-5) * 3600.0
#: The roles a run may have in a campaign.
ROLES = ("turn-on", "soak", "sweep", "rate-table")
#: Named orientations of the sensitive axis as (north, east, up) unit vectors.
AXES_NEU: dict[str, tuple[float, float, float]] = {
    "north": (1.0, 0.0, 0.0), "south": (-1.0, 0.0, 0.0), "east": (0.0, 1.0, 0.0),
    "west": (0.0, -1.0, 0.0), "up": (0.0, 0.0, 1.0), "down": (0.0, 0.0, -1.0)}


def earth_rate_component_dph(latitude_deg: float, axis_neu: tuple[float, float, float]) -> float:
    """The Earth rate seen by a level-mounted axis: Ω (cos φ n + sin φ u). [°/h]

    Parameters
    ----------
    latitude_deg
        Geodetic latitude φ of the test site. [°]
    axis_neu
        The sensitive axis as a unit vector (north, east, up).

    Examples
    --------
    >>> round(earth_rate_component_dph(90.0, (0.0, 0.0, 1.0)), 4)
    15.0411
    >>> round(earth_rate_component_dph(0.0, (0.0, 1.0, 0.0)), 12)
    0.0
    """
    phi = math.radians(latitude_deg)
    north, _, up = axis_neu
    return EARTH_RATE_DPH * (math.cos(phi) * north + math.sin(phi) * up)


@dataclass(frozen=True)
class CampaignSettings:
    """How the runs are measured (the manifest's ``[settings]``).

    Attributes
    ----------
    block_s
        Length of the block means every figure but the Allan deviation is computed from. [s]
    settle_s
        Time left out at the start of each turn-on and soak before its bias is measured
        (the warm-up, the chamber's settling); a run's own ``settle_s`` replaces it. [s]
    turn_on_tolerance_dph
        Band around the settled bias a turn-on must stay within (turn-on time); None: the
        turn-on time is not measured. [°/h]
    temperature_column
        The recorded temperature the sensitivities are per °C of (``housing_c``,
        ``temperature_c``, ``chamber_c``, ...). [°C]
    reference_c
        Temperature at which the scale-factor error is reported. [°C]
    plateau_tolerance_c
        A rate-table hold is at one temperature if its temperature spans at most twice
        this; the holds within twice this of each other make one plateau. [°C]
    coverage_k
        Coverage factor k of every expanded uncertainty U = k·u (2: about 95 % for a
        normal distribution); the χ² intervals of the Allan figures are taken at the
        coverage probability of k.
    """

    block_s: float = 60.0
    settle_s: float = 1800.0
    turn_on_tolerance_dph: float | None = None
    temperature_column: str = "housing_c"
    reference_c: float = 20.0
    plateau_tolerance_c: float = 1.0
    coverage_k: float = 2.0

    def __post_init__(self) -> None:
        for name in ("block_s", "coverage_k", "plateau_tolerance_c"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise InputError(f"[settings] {name} = {value!r}: must be a number > 0")
        for name in ("settle_s", "turn_on_tolerance_dph", "reference_c"):
            value = getattr(self, name)
            if value is not None and not (isinstance(value, int | float)
                                          and math.isfinite(value)):
                raise InputError(f"[settings] {name} = {value!r}: must be a finite number")
        if self.settle_s < 0:
            raise InputError(f"[settings] settle_s = {self.settle_s!r}: must be >= 0 s")


@dataclass(frozen=True)
class Equipment:
    """One item of test equipment or a probe, with its calibration certificate."""

    item: str
    id: str
    certificate: str = ""
    due: str = ""


@dataclass(frozen=True)
class RunEntry:
    """One run of the campaign: its file, its role, an optional day label and its own
    ``settle_s`` (None: the campaign's)."""

    path: Path
    role: str
    day: str = ""
    label: str = ""
    settle_s: float | None = None

    @property
    def name(self) -> str:
        """What the report calls the run: its label or its file name."""
        return self.label or self.path.name


@dataclass(frozen=True)
class Campaign:
    """A checked manifest (:func:`load_campaign`).

    Attributes
    ----------
    source
        The manifest file.
    title, serial, firmware, unit_type
        The report's title and the unit under test.
    model
        The compensation model file (before/after figures), or None.
    latitude_deg, axis_neu
        The test site's latitude and the sensitive axis (north, east, up). [°], [-]
    axis
        The axis of a multi-axis file to read (``x``), None for a single-axis file.
    conditions
        The test conditions, as written.
    equipment
        Test equipment and probes with their certificates.
    signatures
        The roles of the signature block (``["tested by", "approved by"]``).
    runs
        The runs, in the manifest's order.
    settings
        How the runs are measured.
    """

    source: Path
    serial: str
    firmware: str
    latitude_deg: float
    axis_neu: tuple[float, float, float]
    runs: tuple[RunEntry, ...]
    settings: CampaignSettings = field(default_factory=CampaignSettings)
    title: str = ""
    unit_type: str = ""
    model: Path | None = None
    axis: str | None = None
    conditions: tuple[tuple[str, str], ...] = ()
    equipment: tuple[Equipment, ...] = ()
    signatures: tuple[str, ...] = ("tested by", "reviewed by", "approved by")

    @property
    def earth_rate_dph(self) -> float:
        """The Earth-rate component on the sensitive axis, subtracted from every run. [°/h]"""
        return earth_rate_component_dph(self.latitude_deg, self.axis_neu)

    def of_role(self, role: str) -> tuple[RunEntry, ...]:
        """The runs of one role, in order."""
        return tuple(run for run in self.runs if run.role == role)


def _table(data: dict[str, Any], key: str, where: str) -> dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise InputError(f"{where}: [{key}] must be a table, got {value!r}")
    return value


def _text(table: dict[str, Any], key: str, where: str, required: bool = False) -> str:
    value = table.get(key, "")
    if required and value in ("", None):
        raise InputError(f"{where}: {key} is missing; the report names it (e.g. {key} = \"...\")")
    if not isinstance(value, str | int | float):
        raise InputError(f"{where}: {key} = {value!r} must be text")
    return str(value)


def _axis(site: dict[str, Any], where: str) -> tuple[float, float, float]:
    axis = site.get("axis")
    if isinstance(axis, str) and axis.lower() in AXES_NEU:
        return AXES_NEU[axis.lower()]
    if (isinstance(axis, list) and len(axis) == 3
            and all(isinstance(v, int | float) and math.isfinite(v) for v in axis)):
        norm = math.sqrt(sum(float(v) ** 2 for v in axis))
        if norm > 0:
            return (float(axis[0]) / norm, float(axis[1]) / norm, float(axis[2]) / norm)
    raise InputError(f"{where}: [site] axis = {axis!r}: give the sensitive axis as one of "
                     f"{', '.join(AXES_NEU)} or as [north, east, up], e.g. axis = \"up\"")


def _settings(data: dict[str, Any], where: str) -> CampaignSettings:
    table = _table(data, "settings", where)
    known = {f.name for f in fields(CampaignSettings)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise InputError(f"{where}: [settings] {unknown[0]!r} is not a setting; the settings "
                         f"are {', '.join(sorted(known))}")
    try:
        return CampaignSettings(**table)
    except InputError as error:
        raise InputError(f"{where}: {error}") from None


def _runs(data: dict[str, Any], folder: Path, where: str) -> tuple[RunEntry, ...]:
    runs = data.get("runs")
    if not isinstance(runs, list) or not runs:
        raise InputError(f"{where}: no [[runs]]; list each run with its file and role, e.g. "
                         "[[runs]] file = \"day1.parquet\" role = \"turn-on\"")
    entries = []
    for k, run in enumerate(runs):
        here = f"{where}: runs[{k}]"
        if not isinstance(run, dict):
            raise InputError(f"{here} must be a table with file and role")
        role = run.get("role")
        if role not in ROLES:
            raise InputError(f"{here}: role = {role!r}; the roles are {', '.join(ROLES)}")
        path = folder / _text(run, "file", here, required=True)
        if not path.is_file():
            raise InputError(f"{here}: file {str(path)!r} does not exist; paths are relative "
                             "to the manifest's folder")
        settle = run.get("settle_s")
        if settle is not None and not (isinstance(settle, int | float) and math.isfinite(settle)
                                       and settle >= 0):
            raise InputError(f"{here}: settle_s = {settle!r} must be a number of seconds >= 0")
        entries.append(RunEntry(path, role, _text(run, "day", here), _text(run, "label", here),
                                None if settle is None else float(settle)))
    return tuple(entries)


def load_campaign(path: str | Path) -> Campaign:
    """Read and check a campaign manifest (the module docstring shows one).

    Raises
    ------
    InputError
        The file is not TOML, or a key is missing or wrong (the message names it).
    """
    source = Path(path)
    where = str(source)
    try:
        data = tomllib.loads(source.read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(f"{where}: cannot read the manifest ({error.strerror})") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{where}: not a TOML manifest ({error})") from None
    unit = _table(data, "unit", where)
    site = _table(data, "site", where)
    latitude = site.get("latitude_deg")
    if not (isinstance(latitude, int | float) and -90.0 <= latitude <= 90.0):
        raise InputError(f"{where}: [site] latitude_deg = {latitude!r}: give the test site's "
                         "latitude in degrees (-90 to 90); the Earth rate is subtracted with it")
    model = unit.get("model")
    model_path = None if model in (None, "") else source.parent / str(model)
    if model_path is not None and not model_path.is_file():
        raise InputError(f"{where}: [unit] model = {model!r} does not exist (relative to the "
                         "manifest's folder)")
    equipment = []
    for k, item in enumerate(data.get("equipment", [])):
        here = f"{where}: equipment[{k}]"
        if not isinstance(item, dict):
            raise InputError(f"{here} must be a table with item, id and certificate")
        equipment.append(Equipment(_text(item, "item", here, True), _text(item, "id", here, True),
                                   _text(item, "certificate", here), _text(item, "due", here)))
    conditions = tuple((str(k), str(v)) for k, v in _table(data, "conditions", where).items())
    signatures = data.get("signatures", list(Campaign.signatures))
    if not (isinstance(signatures, list) and all(isinstance(s, str) for s in signatures)):
        raise InputError(f"{where}: signatures = {signatures!r} must be a list of roles, e.g. "
                         "[\"tested by\", \"approved by\"]")
    axis = unit.get("file_axis")
    return Campaign(
        source=source, serial=_text(unit, "serial", where + ": [unit]", True),
        firmware=_text(unit, "firmware", where + ": [unit]", True),
        latitude_deg=float(latitude), axis_neu=_axis(site, where),
        runs=_runs(data, source.parent, where), settings=_settings(data, where),
        title=_text(data, "title", where), unit_type=_text(unit, "type", where),
        model=model_path, axis=None if axis in (None, "") else str(axis),
        conditions=conditions, equipment=tuple(equipment), signatures=tuple(signatures))
