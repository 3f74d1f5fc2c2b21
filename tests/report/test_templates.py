"""The report is data, then templates (issue 28, item 5): the templates show the page the
f-strings wrote (``legacy_report``), escape what they show, ship as package data, and jinja2
stays out of ``import hrgtc.report`` and ``hrgtc --help``."""

from __future__ import annotations

import ast
import dataclasses
import hashlib
import re
import subprocess
import sys
import tomllib
from html.parser import HTMLParser
from pathlib import Path

import pytest

import hrgtc.report
import hrgtc.report.figures as figures
from hrgtc.core.errors import InputError
from hrgtc.evaluation import evaluate
from hrgtc.pipeline.calibration import calibrate
from hrgtc.recording import ReadOptions
from hrgtc.report import build_report
from hrgtc.report.inputs import report_inputs
from hrgtc.report.kinds import KINDS
from hrgtc.report.render import render
from hrgtc.settings.compensation import ReportSettings

from legacy_report import legacy_html

REPORT = Path(hrgtc.report.__file__).parent
TEMPLATES = REPORT / "templates"
GOLDEN = Path(__file__).parents[1] / "data" / "golden-models"


class _Tokens(HTMLParser):
    """A page as its tags (with their attributes) and texts (entities decoded, blanks around
    them dropped): what a reader and a parser see, whatever the whitespace between tags."""

    def __init__(self, text: str) -> None:
        super().__init__(convert_charrefs=True)
        self.tokens: list[str] = []
        self.feed(re.sub(r"Report generated [^<]*?\.</p>", "Report generated (now).</p>", text))

    def handle_starttag(self, tag, attrs):
        self.tokens.append(f"<{tag} {attrs}>")

    def handle_endtag(self, tag):
        self.tokens.append(f"</{tag}>")

    def handle_data(self, data):
        if data.strip():
            self.tokens.append(data.strip())


def _same_page(inputs) -> str:
    """The page of ``inputs`` rendered by the templates, after checking it against the one the
    f-strings wrote: every tag, attribute (figure, link, id) and text the same."""
    new = render(KINDS["paper"].template, report=KINDS["paper"].data(inputs))
    old = legacy_html(inputs)
    new_tokens, old_tokens = _Tokens(new).tokens, _Tokens(old).tokens
    assert len(new_tokens) == len(old_tokens)
    for k, (a, b) in enumerate(zip(new_tokens, old_tokens, strict=True)):
        assert a == b, (k, a[:300], b[:300])
    return new


def _drawn(figure) -> str:
    """A stand-in for a figure's SVG: a digest of what its axes draw (lines, bars, texts), so
    that two pages can be compared without drawing every figure twice."""
    digest = hashlib.sha256()
    for ax in figure.axes:
        for line in ax.lines:
            digest.update(line.get_xydata().tobytes())
        for patch in ax.patches:
            digest.update(repr(patch.get_bbox().bounds).encode())
        for text in (ax.title, ax.xaxis.label, ax.yaxis.label, *ax.texts):
            digest.update(text.get_text().encode())
    return "data:image/svg+xml;base64," + digest.hexdigest()


@pytest.mark.parametrize("name", sorted(str(p.relative_to(GOLDEN))
                                         for p in GOLDEN.glob("v*/*.json")))
def test_each_golden_model_s_page_is_the_one_the_f_strings_wrote(name, monkeypatch):
    """Every released model file (one axis and three, resonator and temperature sensor, housing
    baseline, scale factor, temperature map), its soaks gone: the same page, ids included
    (the axes' ids were an ``id=`` rewrite of the finished HTML). The figures are compared by
    what they draw (:func:`_drawn`); the next test compares their SVG."""
    monkeypatch.setattr(figures, "svg_data_uri", _drawn)
    sensor = "sensor" in name  # read as the model's kind of thermometer
    options = ReadOptions(thermometer="sensor" if sensor else "resonator")
    inputs = report_inputs(GOLDEN / name, [], read_options=options)
    assert sensor == all(m.thermometer.source == "sensor"
                         for m in inputs.instrument.axes.values())
    page = _same_page(inputs)
    ids = re.findall(r' id="([^"]*)"', page)
    assert len(ids) == len(set(ids))  # each id once
    assert set(re.findall(r'href="#([^"]*)"', page)) <= set(ids)  # no dead link
    if not inputs.instrument.is_single_axis:
        assert {f"{axis}-runs" for axis in inputs.instrument.axes} <= set(ids)


@pytest.fixture(scope="module")
def unit(paper_campaign):
    result = calibrate(paper_campaign.soaks, [paper_campaign.cooldown], [paper_campaign.warmup])
    return paper_campaign, result.model


def test_a_unit_s_page_with_runs_and_soaks_is_the_one_the_f_strings_wrote(unit):
    """Figs. 3-6 from the soaks and two runs, every table and caption: the same page."""
    files, model = unit
    runs = [evaluate(model, path, max_points=ReportSettings.max_points).axis
            for path in (files.cooldown, files.warmup)]
    page = _same_page(report_inputs(model, runs))
    assert page.count("<img ") == 4 + 2 * 2 and page.count("<table>") > 20


def test_what_the_page_shows_is_escaped(unit, tmp_path):
    """A recording, a title and a unit named with markup show as text (autoescaping on)."""
    files, model = unit
    evil = "<script>alert(1)<script>"
    run = tmp_path / f"{evil}.parquet"
    run.write_bytes(files.warmup.read_bytes())
    model = dataclasses.replace(model.with_parts(plateaus=()), unit=f"{evil}&")
    output = build_report(model, [run], tmp_path / "report.html",
                          ReportSettings(title=f"{evil} report"), soaks=[])
    text = output.read_text(encoding="utf-8")
    assert "<script" not in text
    assert "&lt;script&gt;alert(1)&lt;script&gt;.parquet" in text  # the run's name
    assert "<title>&lt;script&gt;alert(1)&lt;script&gt; report</title>" in text
    assert "&lt;script&gt;alert(1)&lt;script&gt;&amp;" in text  # the unit


def test_a_kind_is_a_data_function_and_a_folder_of_templates(tmp_path):
    folders = {p.name for p in TEMPLATES.iterdir() if p.is_dir()}
    assert folders == {*KINDS, "common"}
    for name, kind in KINDS.items():
        assert kind.name == name and (TEMPLATES / kind.template).is_file()
        assert callable(kind.data) and kind.description
    model = GOLDEN / "v2" / "unit-resonator-254ab6c.json"
    with pytest.raises(InputError, match=r"kind='ieee'.*the kinds are paper"):
        build_report(model, [], tmp_path / "r.html", ReportSettings(kind="ieee"), soaks=[])
    assert not (tmp_path / "r.html").exists()


def test_the_templates_are_package_data():
    """pyproject's package-data patterns name every file of templates/ (a wheel without
    them could not render a report)."""
    config = tomllib.loads((Path(__file__).parents[2] / "pyproject.toml").read_text())
    patterns = config["tool"]["setuptools"]["package-data"]["hrgtc.report"]
    shipped = {p for pattern in patterns for p in REPORT.glob(pattern)}
    files = {p for p in TEMPLATES.rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    assert files and shipped == files


def test_no_html_is_written_in_python():
    """No string or f-string of report/'s modules, docstrings aside, holds a tag: the
    templates write the page."""
    tag = re.compile(r"</?[a-z][a-z0-9]*[ >]")
    found = []
    for module in REPORT.glob("*.py"):
        tree = ast.parse(module.read_text(encoding="utf-8"))
        docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                      if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef)
                      and node.body and isinstance(node.body[0], ast.Expr)}
        found += [(module.name, node.value[:60]) for node in ast.walk(tree)
                  if isinstance(node, ast.Constant) and isinstance(node.value, str)
                  and id(node) not in docstrings and tag.search(node.value)]
    assert found == []
    assert tag.search('<p class="note">') and tag.search("</section>")  # it would see one


@pytest.mark.parametrize("code", [
    "import hrgtc.report",
    "import sys; from hrgtc.cli import main; sys.argv = ['hrgtc', '--help']\n"
    "try:\n    main()\nexcept SystemExit:\n    pass",
])
def test_jinja2_is_imported_only_to_render(code):
    """jinja2 is imported by the first report rendered, not by ``import hrgtc.report`` nor by
    ``hrgtc --help``."""
    probe = f"{code}\nimport sys\nprint('jinja2' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          check=True, timeout=120)
    assert done.stdout.strip().splitlines()[-1] == "False"


def test_rendering_imports_jinja2():
    """The check above can fail: rendering does import it."""
    probe = ("import sys\nfrom hrgtc.report.render import macros\nmacros()\n"
             "print('jinja2' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          check=True, timeout=120)
    assert done.stdout.strip() == "True"
