"""Every result's ``summary()`` returns a :class:`~hrgtc.core.summary.Summary` (issue 28,
item 3), on real objects built from the shared campaigns (``tests/summary_objects.py``).

Each summary's text is not empty and shows a figure that could be wrong: the paper-unit's
Eq. 18 coefficients and held-out bias stability, the Hald data's stepwise steps (Draper and
Smith's, as MATLAB's ``stepwisefit`` reports them), a prior's units; every renderer (text,
rich, HTML, JSON) takes every summary; a layout only names figures the summary has; and
every class that defines ``summary()`` in ``src/`` has an object here.
"""

from __future__ import annotations

import ast
import io
import json
import math
import re
from pathlib import Path

import pytest
from rich.console import Console

from hrgtc.cli.summary_tables import print_summary
from hrgtc.core.summary import Summary
from summary_objects import every_result

SRC = Path(__file__).resolve().parents[1] / "src" / "hrgtc"


@pytest.fixture(scope="module")
def results(paper_campaign, imu_campaign, tmp_path_factory):
    return every_result(paper_campaign, imu_campaign, tmp_path_factory.mktemp("summaries"))


def _summarised_classes() -> set[str]:
    """The classes of src/ with a ``summary`` method."""
    out = set()
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef) and any(
                    isinstance(m, ast.FunctionDef) and m.name == "summary" for m in node.body):
                out.add(node.name)
    return out


def test_every_class_with_a_summary_has_an_object_here(results):
    """A new ``summary()`` cannot escape this test: every class is built."""
    classes = {type(obj).__name__ for obj in results.values()}
    missing = _summarised_classes() - classes
    assert not missing, missing


def test_every_summary_is_a_summary_that_every_renderer_takes(results):
    for name, obj in results.items():
        summary = obj.summary()
        assert isinstance(summary, Summary), name
        text = summary.text()
        assert str(summary) == text, name
        assert text.strip(), name  # none is empty here
        figures = summary.figures()
        assert summary.referenced() <= set(figures), (name, summary.referenced() - set(figures))
        document = json.loads(json.dumps(summary.to_dict()))
        assert [f["name"] for s in document["sections"] for f in s["figures"]] == [
            f.name for _, fs in summary.sections for f in fs], name
        assert summary.html().startswith('<table class="summary">'), name
        out = io.StringIO()
        print_summary(summary, Console(file=out, width=5000))  # no line wrapped
        if summary.layout is not None:  # the CLI prints a summary with its own text as that
            assert text in out.getvalue(), name


def _number(text: str, pattern: str) -> float:
    match = re.search(pattern, text)
    assert match, (pattern, text)
    return float(match.group(1))


def test_the_texts_name_figures_that_could_be_wrong(results):
    """The figures of a text are its object's, to the printed digit."""
    thermometer = results["Thermometer"]
    text = thermometer.summary().text()
    # Eq. 18 of the paper-unit: f = c3 T^3 + ... c0 [Hz], each printed with 6 digits
    for k, c in enumerate(thermometer.coefficients):
        power = "" if k == 0 else ("·T" if k == 1 else f"·T^{k}")
        assert f"{c:+.6g}{power}" in text
    assert thermometer.coefficients[0] == pytest.approx(4425.0, abs=15.0)  # the resonator
    # the held-out warm-up's 10 s bias stability, raw and compensated (Section 4.2)
    evaluation = results["Evaluation"].summary()
    raw = evaluation["evaluation.bias_stability_dph.raw.10"]
    compensated = evaluation["evaluation.bias_stability_dph.compensated.10"]
    assert compensated.value < raw.value / 2  # compensation works on the held-out run
    assert raw.value == pytest.approx(results["Evaluation"].raw_10s)
    # Hald's cement data: stepwise adds x4, x1, removes x4 ... as MATLAB reports
    hald = results["StepwiseResult"].summary()
    assert [hald[f"history[{k}].term"].value for k in range(4)] == ["x4", "x1", "x2", "x4"]
    assert "removed x4" in re.sub(r"\s+", " ", hald.text())
    assert hald["result.nobs"].value == 13
    drift = results["DriftModel"]
    dtext = drift.summary().text()
    assert _number(dtext, r"residual std (\S+) °/h") == pytest.approx(
        drift.residual_std_dph, rel=1e-3)
    assert "B = " in dtext.splitlines()[-1]  # Eq. 22 form, last
    prior = results["ThermometerPrior"].summary()
    assert prior.text().startswith("prior of 8 units") and prior["n_units"].value == 8
    slow = results["SlowChannels"].summary()
    assert slow["channels[0].column"].value == "housing_c"
    assert slow["channels[0].filled"].value == 900
    assert "900 cells filled" in slow.text()
    spikes = results["RobustSpikeFilter"].summary()
    assert "row 700" in spikes.text() and spikes["first.row"].value == 700
    fleet = results["FleetRun"].summary()
    assert fleet.text().startswith("2 units in 12.5 s") and fleet["counts.failed"].value == 1
    curve = results["AllanResult"].summary()
    first = curve["deviation[0]"]
    assert f"{first.value:12.6g}" in curve.text().splitlines()[2]
    assert not math.isnan(first.value)


def test_the_instrument_summaries_are_tables(results):
    """``hrgtc evaluate``'s axes and scale-factor check, once hand-built rich tables, are
    the sections of the evaluation's summary (a grid: their cells by row and column)."""
    from hrgtc.evaluation.instrument_figures import SCALE_CHECKS, scale_check_figures

    calibration = results["Calibration"]
    check = calibration.scale_checks[0]
    summary = Summary("", ((SCALE_CHECKS, scale_check_figures(calibration.scale_checks)),))
    headers, rows = summary.grid(SCALE_CHECKS)
    assert headers == ["axis", "frequency [Hz]", "holds", "raw [ppm]", "compensated [ppm]"]
    assert rows[0] == [check.axis or "-", f"{check.freq_hz[0]:.4f}", str(check.holds[0]),
                       f"{check.raw_ppm[0]:+.2f}", f"{check.compensated_ppm[0]:+.2f}"]
    out = io.StringIO()
    print_summary(summary, Console(file=out, width=400))
    assert f"{check.compensated_ppm[0]:+.2f}" in out.getvalue()
    evaluated = results["RunEvaluation"]
    tables = evaluated.summary()
    assert [h for h, _ in tables.sections] == [f"{evaluated.model.unit}: 10 s bias stability "
                                               "per axis", SCALE_CHECKS]
    for k, row in enumerate(evaluated.axis_summary()):  # the rows of --json's summary
        assert tables[f"summary[{k}].compensated_10s_dph"].value == row["compensated_10s_dph"]
    demo = results["DemoResult"].summary()
    headers, rows = demo.grid("10 s bias stability, raw → compensated")
    assert rows[0][1:] == ["3.0143", "0.5848", "5.15"]  # Section 4.2 of [1], as printed
    assert rows[2][1] == f"{results['Evaluation'].raw_10s:.4f}"
