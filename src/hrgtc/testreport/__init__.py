"""The test report of a campaign: IEEE-style figures judged against a spec.

Takes a campaign manifest (TOML: the unit, the site, the equipment and the runs with their
roles: turn-ons, soaks, sweeps, rate-table runs; ``manifest``) and optionally a
``spec.toml`` of limits (``spec``: the decision rule with ILAC-G8 guard bands) and gives a
:class:`TestReport` (``result``): turn-on time, warm-up drift, bias and its repeatability,
bias temperature and temperature-gradient sensitivities before and after compensation,
scale factor and its temperature sensitivity where a rate table was run, the Allan noise
terms, each with its clause, definition, uncertainty and coverage factor (``figures``,
``measures``), from each run read once (``series``). :mod:`hrgtc.report.test_report`
writes it as HTML, PDF and JSON (``hrgtc test-report``).
"""

from hrgtc.core import lazy_names

_NAMES = {
    "Campaign": "manifest", "load_campaign": "manifest", "earth_rate_component_dph": "manifest",
    "Limit": "spec", "decide": "spec", "load_spec": "spec",
    "FIGURES": "figures", "TestFigure": "figures",
    "TestReport": "result", "TestReportInputs": "result", "campaign_report": "result",
    "test_report": "result",
}

__getattr__, __dir__ = lazy_names(__name__, _NAMES, globals())

__all__ = ["FIGURES", "Campaign", "Limit", "TestFigure", "TestReport", "TestReportInputs",
           "campaign_report", "decide", "earth_rate_component_dph", "load_campaign", "load_spec",
           "test_report"]
