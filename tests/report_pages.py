"""The paper report's page of one axis, rendered from its data (``hrgtc.report.paper``), for
the tests that check a section of the report against the figures it shows."""

from __future__ import annotations

from hrgtc.report.kinds import KINDS
from hrgtc.report.paper import PaperReport, axis_report
from hrgtc.report.render import render


def one_axis_page(model, evaluations=(), traces=()) -> str:
    """The page of ``model`` (a unit model) with these runs (evaluations with plotting
    blocks) and soak traces, as ``build_report`` renders it."""
    axis = axis_report("", "", model, evaluations, traces)
    report = PaperReport("test page", model.unit, None, "?", "?", "now", axis.sensor, None,
                         True, None, (axis,))
    return render(KINDS["paper"].template, report=report)
