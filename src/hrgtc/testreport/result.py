"""The test report's data: every figure of a campaign, judged, with what a lab signs.

:func:`test_report` reads the manifest's runs once each
(:func:`~hrgtc.testreport.series.read_series`), computes every figure of
:data:`~hrgtc.testreport.figures.FIGURES` (:mod:`~hrgtc.testreport.measures`), judges them
against the spec's limits (:func:`~hrgtc.testreport.spec.decide`) and returns a
:class:`TestReport`: the figures, the tables behind them, the unit, equipment and
conditions, the inputs' SHA-256 and the hrgtc version. It is the data of the
``test-report`` kind of :data:`hrgtc.report.kinds.KINDS`; ``summary()`` and ``to_dict()``
are its text and JSON.
"""

from __future__ import annotations

import dataclasses
import datetime as _dt
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.core.files import file_sha256
from hrgtc.core.summary import Summary
from hrgtc.evaluation.allan import AllanResult
from hrgtc.model import Model, load_model
from hrgtc.recording import ReadOptions, count_rows
from hrgtc.testreport.figures import FIGURES, TestFigure
from hrgtc.testreport.manifest import Campaign, load_campaign
from hrgtc.testreport.measures import (
    Plateau,
    SoakPoint,
    TurnOn,
    noise_figures,
    scale_factor_figures,
    temperature_figures,
    turn_on_figures,
    turn_ons,
)
from hrgtc.testreport.series import RunSeries, read_series
from hrgtc.testreport.spec import (
    ACCEPT,
    INDETERMINATE,
    NO_LIMIT,
    NOT_MEASURED,
    REJECT,
    Limit,
    load_spec,
)

__all__ = ["TestReport", "TestReportInputs", "campaign_report", "test_report"]

PathLike = str | os.PathLike[str]


@dataclass(frozen=True)
class TestReportInputs:
    """What a test report is made from: the checked manifest, the limits and the reading."""

    campaign: Campaign
    limits: Mapping[str, Limit] = field(default_factory=dict)
    spec_source: Path | None = None
    read_options: ReadOptions | None = None

    __test__ = False


@dataclass(frozen=True, eq=False)
class TestReport:
    """A campaign's figures, judged, and what the report says of the test.

    Attributes
    ----------
    campaign
        The manifest.
    figures
        Every figure of :data:`FIGURES`, measured or not, with its verdict.
    turn_ons, soaks, plateaus
        The rows behind the figures: each turn-on, each soak's settled point, each
        rate-table plateau.
    allan, allan_run
        The Allan deviations (raw, compensated) and the run they are of.
    earth_rate_dph
        The Earth-rate component subtracted. [°/h]
    inputs
        (what, file, SHA-256) of the manifest, the spec, the model and every run.
    hrgtc_version, created_utc
        What made the report, and when.
    notes
        What the figures cannot say.
    """

    campaign: Campaign
    figures: tuple[TestFigure, ...]
    turn_ons: tuple[TurnOn, ...]
    soaks: tuple[SoakPoint, ...]
    plateaus: tuple[Plateau, ...]
    allan: dict[str, AllanResult]
    allan_run: str
    earth_rate_dph: float
    inputs: tuple[tuple[str, str, str], ...]
    hrgtc_version: str
    created_utc: str
    notes: tuple[str, ...] = ()

    __test__ = False

    def figure(self, name: str) -> TestFigure:
        """The figure ``name``."""
        return next(f for f in self.figures if f.name == name)

    @property
    def verdict(self) -> str:
        """The test's verdict over the figures with a limit: reject if one is rejected, else
        indeterminate if one is, else "not measured" if one was not measured, else accept;
        "no limit" when no figure has one."""
        found = [f.verdict for f in self.figures if f.limit is not None]
        if not found:
            return NO_LIMIT
        return next((v for v in (REJECT, INDETERMINATE, NOT_MEASURED) if v in found), ACCEPT)

    def sections(self) -> list[tuple[str, list[TestFigure]]]:
        """The figures by section (turn-on, temperature, scale factor, noise)."""
        order: dict[str, list[TestFigure]] = {}
        for figure in self.figures:
            order.setdefault(figure.info.section, []).append(figure)
        return list(order.items())

    def summary(self) -> Summary:
        """Every figure with its expanded-uncertainty interval, by section; the notes say
        the verdicts and what was not measured."""
        sections = tuple((heading, tuple(f.summary_figure() for f in figures))
                         for heading, figures in self.sections())
        notes = [f"{f.info.label}: {f.verdict}" + (f" ({f.reason})" if f.reason else "")
                 for f in self.figures if f.verdict != NO_LIMIT or f.reason]
        return Summary(f"test report of {self.campaign.serial}: {self.verdict}", sections,
                       tuple([*notes, *self.notes]))

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types: the unit, the inputs and their hashes, every figure."""
        c = self.campaign
        return {
            "title": c.title, "serial": c.serial, "firmware": c.firmware, "type": c.unit_type,
            "verdict": self.verdict, "hrgtc_version": self.hrgtc_version,
            "created_utc": self.created_utc,
            "site": {"latitude_deg": c.latitude_deg, "axis_neu": list(c.axis_neu),
                     "earth_rate_dph": self.earth_rate_dph},
            "conditions": dict(c.conditions),
            "equipment": [{"item": e.item, "id": e.id, "certificate": e.certificate,
                           "due": e.due} for e in c.equipment],
            "inputs": [{"what": w, "file": p, "sha256": h} for w, p, h in self.inputs],
            "settings": {k: getattr(c.settings, k) for k in c.settings.__dataclass_fields__},
            "figures": [f.to_dict() for f in self.figures],
            "turn_ons": [{"run": t.name, "day": t.day, "bias_dph": t.bias_dph,
                          "bias_se_dph": t.bias_se_dph, "compensated_dph": t.compensated_dph,
                          "turn_on_time_s": t.turn_on_time_s,
                          "warm_up_drift_dph": (t.warm_up_drift_dph if math.isfinite(
                              t.warm_up_drift_dph) else None)} for t in self.turn_ons],
            "soaks": [{"run": p.name, "temperature_c": p.temperature_c, "bias_dph": p.bias_dph,
                       "compensated_dph": p.compensated_dph} for p in self.soaks],
            "plateaus": [{"temperature_c": p.temperature_c, "k_ppm": p.k_ppm,
                          "k_se_ppm": None if not math.isfinite(p.k_se_ppm) else p.k_se_ppm,
                          "holds": p.holds} for p in self.plateaus],
            "allan_run": self.allan_run,
            "allan": {key: _allan_dict(curve) for key, curve in self.allan.items()},
            "notes": list(self.notes)}


def _allan_dict(curve: AllanResult) -> dict[str, Any]:
    def listed(values: Any) -> list[float] | None:
        return None if values is None else [float(v) for v in values]

    return {"taus_s": listed(curve.taus_s), "deviation_dph": listed(curve.deviation),
            "lower_dph": listed(curve.lower), "upper_dph": listed(curve.upper),
            "confidence": curve.confidence}


def _allan_entry(campaign: Campaign) -> str | None:
    """The run whose Allan deviation the report shows: the longest turn-on, else soak."""
    for role in ("turn-on", "soak"):
        runs = campaign.of_role(role)
        if runs:
            return str(max(runs, key=lambda r: count_rows(r.path)).path)
    return None


def _campaign_model(campaign: Campaign) -> Model | None:
    """The manifest's model; of an instrument, the axis the manifest's ``file_axis`` reads
    (its runs are read as that axis's single-axis view)."""
    if campaign.model is None:
        return None
    model = load_model(campaign.model)
    if campaign.axis is None or "" in model.axes:
        return model
    if campaign.axis not in model.axes:
        raise InputError(f"{campaign.source}: [unit] file_axis = {campaign.axis!r}, but the "
                         f"model {campaign.model.name} has axes {', '.join(model.axes)}: "
                         "name one of them, or the model of that axis")
    return model.of_axis(campaign.axis)


def campaign_report(inputs: TestReportInputs) -> TestReport:
    """The data function of the ``test-report`` kind: read every run once, compute and
    judge every figure."""
    from hrgtc.core.meta import __version__
    from hrgtc.thermometry.reference import options_with_map

    campaign = inputs.campaign
    settings = campaign.settings
    model = _campaign_model(campaign)
    # the column mapping, units, ...; a raw count read through the model's map to °C
    options = options_with_map(inputs.read_options or ReadOptions(),
                               None if model is None else model.temperature_map)
    if campaign.axis is not None:  # the manifest's file_axis
        options = dataclasses.replace(options, axis=campaign.axis)
    allan_path = _allan_entry(campaign)
    earth = campaign.earth_rate_dph
    series: dict[str, list[RunSeries]] = {}
    notes = []
    for entry in campaign.runs:
        found = read_series(entry, earth_rate_dph=earth, block_s=settings.block_s,
                            temperature_column=settings.temperature_column, model=model,
                            read_options=options, keep_samples=str(entry.path) == allan_path)
        series.setdefault(entry.role, []).append(found)
        if found.n_moving:
            notes.append(f"{entry.name}: {found.n_moving} of {found.n_samples} samples not at "
                         "rest (handling; the motion detector of calibrate) left out of its "
                         "block means; --motion keep uses them")
        if entry.role != "rate-table" and abs(found.metadata_input_rate_dph - earth) > 1e-3 \
                and found.metadata_input_rate_dph != 0.0:
            notes.append(f"{entry.name}: its metadata state an input rate of "
                         f"{found.metadata_input_rate_dph:.6g} °/h; the report subtracts the "
                         f"manifest's Earth rate, {earth:.6g} °/h")
    compensated = model is not None
    found_turn_ons = turn_ons(series.get("turn-on", []), settings)
    temperature, soaks = temperature_figures(series.get("soak", []), series.get("sweep", []),
                                             settings, compensated)
    scale, plateaus = scale_factor_figures(series.get("rate-table", []), settings)
    allan_series = next((s for runs in series.values() for s in runs
                         if s.samples_dph is not None), None)
    noise, curves = noise_figures(allan_series, settings)
    figures = {f.name: f for f in [*turn_on_figures(found_turn_ons, settings, compensated),
                                   *temperature, *scale, *noise]}
    ordered = tuple(figures[name].judged(inputs.limits.get(name)) for name in FIGURES
                    if name in figures)
    hashed = [("manifest", str(campaign.source), file_sha256(campaign.source))]
    if inputs.spec_source is not None:
        hashed.append(("spec", str(inputs.spec_source), file_sha256(inputs.spec_source)))
    if campaign.model is not None:
        hashed.append(("model", str(campaign.model), file_sha256(campaign.model)))
    hashed += [(f"run ({s.entry.role})", str(s.entry.path), s.sha256)
               for runs in series.values() for s in runs]
    if not compensated:
        notes.append("no model in the manifest: the figures after compensation are not shown")
    return TestReport(
        campaign, ordered, tuple(found_turn_ons), tuple(soaks), tuple(plateaus), curves,
        "" if allan_series is None else allan_series.entry.name, earth, tuple(hashed),
        __version__, _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"), tuple(notes))


def test_report(manifest: Campaign | PathLike, spec: PathLike | None = None, *,
                read_options: ReadOptions | None = None) -> TestReport:
    """The test report's data from a campaign manifest and, optionally, a spec.

    Parameters
    ----------
    manifest
        The campaign manifest (:func:`~hrgtc.testreport.manifest.load_campaign`) or its file.
    spec
        ``spec.toml``: the limits of the decision rule; None: no figure is judged.
    read_options
        How to read the runs (default: the manifest's ``file_axis`` only).

    Raises
    ------
    InputError
        A manifest or spec that is wrong (the message names the key), a run that cannot
        give what its role needs (too short, no temperature column, no ``input_rate_dph``).
    """
    campaign = manifest if isinstance(manifest, Campaign) else load_campaign(manifest)
    limits = {} if spec is None else load_spec(spec, tuple(FIGURES))
    return campaign_report(TestReportInputs(campaign, limits,
                                            None if spec is None else Path(spec), read_options))


test_report.__test__ = False  # type: ignore[attr-defined]
