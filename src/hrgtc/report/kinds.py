"""The registry of report kinds: what a report shows is one data function and one folder of
templates.

A kind is one line of :data:`KINDS`: its name (``ReportSettings(kind=...)`` of
``build_report``), its data function (:class:`~hrgtc.report.inputs.ReportInputs` in, a
plain dataclass out: it reads the runs and soaks it shows and computes every figure, table
and plot) and, by its name, its templates,
``templates/<name>/report.html.j2`` (package data), which receive the data as ``report``.
Adding a kind is a module with its data function, a folder of templates and a line here.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.report.inputs import ReportInputs
from hrgtc.report.paper import paper_report
from hrgtc.testreport.result import TestReportInputs, campaign_report

__all__ = ["KINDS", "ReportKind", "kind"]


@dataclass(frozen=True)
class ReportKind:
    """A kind of report: its name (and template folder), its data function and what it is;
    ``takes``: what its data function reads (the model's :class:`ReportInputs`, or a test
    campaign's :class:`~hrgtc.testreport.result.TestReportInputs`)."""

    name: str
    data: Callable[[Any], Any]
    description: str
    takes: type = ReportInputs

    @property
    def template(self) -> str:
        """Its page: ``templates/<name>/report.html.j2``."""
        return f"{self.name}/report.html.j2"


#: The kinds, by name.
KINDS: dict[str, ReportKind] = {kind.name: kind for kind in (
    ReportKind("paper", paper_report,
               "the calibration's evidence laid out like [1]: Figs. 3-6, Tables 1-2, Eq. 18 and "
               "Eq. 22, each run's bias stability and Allan deviation"),
    ReportKind("test-report", campaign_report,
               "a test campaign's IEEE-style figures (turn-on, bias repeatability, temperature "
               "sensitivities, scale factor, Allan noise terms) judged against a spec",
               TestReportInputs),
)}


def kind(name: str) -> ReportKind:
    """The kind ``name``; an :class:`~hrgtc.core.errors.InputError` naming the kinds if none."""
    try:
        return KINDS[name]
    except KeyError:
        raise InputError(f"kind={name!r}: no such report kind; the kinds are "
                         f"{', '.join(KINDS)}") from None
