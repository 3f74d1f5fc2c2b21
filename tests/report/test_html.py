"""Tests of hrgtc.report (the self-contained HTML report) and ``hrgtc report``."""

from __future__ import annotations

import base64
import dataclasses
import json
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from hrgtc import recording
from hrgtc.cli import app
from hrgtc.compensate import compensate
from hrgtc.core.errors import OutputExistsError
from hrgtc.model import save_model
from hrgtc.pipeline.calibration import calibrate
from hrgtc.report import build_report
from hrgtc.thermometry import paper

from campaign import SETPOINTS_C


class _Page(HTMLParser):
    """Images, section ids, figure captions and tables (by caption) of a report."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.images: list[str] = []
        self.ids: list[str] = []
        self.captions: list[str] = []
        self.tables: dict[str, list[list[str]]] = {}
        self._text: list[str] | None = None
        self._rows: list[list[str]] | None = None
        self._table_caption = ""
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if "id" in attrs:
            self.ids.append(attrs["id"])
        if tag == "img":
            self.images.append(attrs["src"])
        elif tag in ("figcaption", "caption", "td", "th"):
            self._text = []
        elif tag == "table":
            self._rows, self._table_caption = [], f"table {len(self.tables)}"
        elif tag == "tr" and self._rows is not None:
            self._rows.append([])

    def handle_data(self, data):
        if self._text is not None:
            self._text.append(data)

    def handle_endtag(self, tag):
        if tag in ("figcaption", "caption", "td", "th") and self._text is not None:
            text = "".join(self._text).strip()
            self._text = None
            if tag == "figcaption":
                self.captions.append(text)
            elif tag == "caption":
                self._table_caption = text
            elif tag == "td" and self._rows:
                self._rows[-1].append(text)
        elif tag == "table" and self._rows is not None:
            self.tables[self._table_caption] = [row for row in self._rows if row]
            self._rows = None

    def table(self, prefix: str) -> list[list[str]]:
        (match,) = [rows for caption, rows in self.tables.items() if caption.startswith(prefix)]
        return match


def _number(cell: str) -> float:
    return float(cell.replace("−", "-").split()[0])


@pytest.fixture(scope="module")
def unit(tmp_path_factory, paper_campaign):
    folder = tmp_path_factory.mktemp("report-unit")
    files = paper_campaign
    result = calibrate(files.soaks, [files.cooldown], [files.warmup])
    return files, result.model, save_model(result.model, folder / "unit.json")


@pytest.fixture(scope="module")
def report(unit, tmp_path_factory):
    files, _, model_path = unit
    output = tmp_path_factory.mktemp("report") / "report.html"
    calls = []
    build_report(model_path, [files.cooldown, files.warmup], output,
                 progress=lambda done, total: calls.append((done, total)))
    text = output.read_text(encoding="utf-8")
    return output, text, _Page(text), calls


def test_one_self_contained_document(report):
    _, text, page, calls = report
    assert text.startswith("<!DOCTYPE html>")
    assert text.count("<html") == 1 and text.count("</html>") == 1
    for external in ('src="http', "<link", "@import", "url(", "<script", "<iframe"):
        assert external not in text
    assert len(text) < 3e6
    for source in page.images:  # every figure is an embedded, well-formed SVG document
        assert source.startswith("data:image/svg+xml;base64,")
        svg = ET.fromstring(base64.b64decode(source.split(",", 1)[1]))
        assert svg.tag.endswith("svg")
        assert "http" not in "".join(svg.attrib.get(k, "") for k in svg.attrib if "href" in k)
    assert calls[-1][0] == calls[-1][1] > 0  # progress reached its total (all rows read)


def test_every_section_and_figure(report):
    _, text, page, _ = report
    for section in ("settling", "thermometer", "temperature", "runs", "run-1", "run-2", "model"):
        assert section in page.ids
    # Fig. 3, Fig. 4, Fig. 5(a), Fig. 5(b), then per run Fig. 6 and the Allan deviation.
    assert len(page.images) == len(page.captions) == 4 + 2 * 2
    for figure in ("Fig. 3", "Fig. 4", "Fig. 5(a)", "Fig. 5(b)", "Fig. 6(a)", "Fig. 6(b)"):
        assert any(figure in caption for caption in page.captions), figure
    assert "10.3390/s120506434" in text and "Sensors" in text
    assert "3.0143" in text and "0.5848" in text  # Section 4.2 of [1], beside the unit's numbers
    assert "Stepwise steps" in page.tables and "Newey" in text
    assert _dead_links(text, page) == []


def _dead_links(text: str, page: _Page) -> list[str]:
    """In-page links (href="#id") with no element of that id."""
    return [h for h in re.findall(r'href="#([^"]*)"', text) if h not in page.ids]


def test_a_sensor_instrument_s_contents_link_to_sections_it_has(tmp_path):
    """A three-axis MEMS gyro (the real cold test): no soaks, no frequency, sections per axis
    (x-runs, ...). The contents listed "Settling of the soaks", "Frequency–temperature fit"
    and "Temperature from frequency" and linked to #settling ... #model, none of which
    existed (issue 20, a new user's report)."""
    data = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
    read = ["--thermometer", "sensor", "--time-unit", "ms", "--rate-unit", "rad/s", "--gaps",
            "bridge", "--temp-scale", "0.00586994", "--temp-offset", "24.2787", "--col",
            "time_s=time (ms),rate_dph_x=gyrox rad/s,rate_dph_y=gyroy rad/s,"
            "rate_dph_z=gyroz rad/s,temperature_c=temp"]
    runner = CliRunner()
    done = runner.invoke(app, ["calibrate", "--drift", str(data), *read, "--rate-tau-s", "310",
                               "-o", str(tmp_path / "pan.json")])
    assert done.exit_code == 0, done.output
    done = runner.invoke(app, ["report", "--model", str(tmp_path / "pan.json"), str(data),
                               *read, "-o", str(tmp_path / "pan.html")])
    assert done.exit_code == 0, done.output
    text = (tmp_path / "pan.html").read_text(encoding="utf-8")
    page = _Page(text)
    assert _dead_links(text, page) == []
    assert "x-runs" in page.ids and "x-model" in page.ids
    for absent in ("Settling of the soaks", "Frequency–temperature fit",
                   "Temperature from frequency"):
        assert absent not in text


def test_tables_hold_the_units_plateaus(report):
    _, _, page, _ = report
    table1 = page.table("The unit's Table 1")
    assert [_number(row[0]) for row in table1] == list(SETPOINTS_C)
    # The simulator's default unit follows Table 1 of [1] through its cubic (DESIGN.md).
    truth = np.polyval(np.polyfit(paper.TABLE1_TEMPERATURE_C, paper.TABLE1_FREQUENCY_HZ, 3),
                       SETPOINTS_C)
    assert np.allclose([_number(row[1]) for row in table1], truth, atol=5e-3)
    table2 = page.table("The unit's Table 2")
    assert [_number(row[1]) for row in table2] == list(SETPOINTS_C)
    assert max(abs(_number(row[3])) for row in table2) < 0.02  # °C, as test_calibration
    plateaus = page.table("Plateaus of the unit")
    assert sorted(_number(row[0]) for row in plateaus) == sorted(SETPOINTS_C)
    provenance = page.table("Model inputs")
    assert [row[0] for row in provenance].count("soak") == len(SETPOINTS_C)
    assert all(row[3] == "unchanged" for row in provenance)


def test_bias_stability_table_against_numpy(unit, report):
    """10 s stabilities of the first run equal numpy's std of 10 s means, raw and compensated."""
    files, model, _ = unit
    _, _, page, _ = report
    run = recording.read(files.cooldown)
    compensated = compensate(model, run)
    m = round(10 * run.sample_rate_hz)
    settle = round(model.drift.settings.warmup_s * run.sample_rate_hz)  # the filter settling
    n = (len(run) - settle) // m

    def stability(rate):
        return np.std(rate[settle: settle + n * m].reshape(n, m).mean(axis=1), ddof=1)

    rows = {row[0]: row for row in page.table(f"Bias stability of {files.cooldown.name}")}
    raw10 = _number(rows["raw, τ = 10 s"][1])
    comp10 = _number(rows["compensated (frequency, Eq. 22), τ = 10 s"][1])
    assert raw10 == pytest.approx(stability(run.rate_dph), rel=1e-3)
    assert comp10 == pytest.approx(stability(compensated["rate_comp_dph"]), rel=1e-3)
    assert raw10 > 2 * comp10


def test_numbers_agree_with_hrgtc_evaluate(unit, report):
    """The report and ``hrgtc evaluate`` give one run the same figures."""
    from hrgtc.evaluation import evaluate

    files, model, _ = unit
    _, _, page, _ = report
    glance = {row[0]: row for row in page.table("At a glance")}
    for path in (files.cooldown, files.warmup):
        result = evaluate(model, path).axis.to_dict()
        row = glance[path.name]
        for column, key in ((1, "raw"), (2, "compensated"), (4, "housing")):
            assert _number(row[column]) == pytest.approx(
                result["bias_stability_dph"][key]["10"], rel=1e-3)
        # beyond the calibrated temperatures only (issue 21: the gradient g's share is its own)
        assert row[5] == f"{result['ranges']['temperature_fraction']:.1%}"
    assert glance["paper [1], Section 4.2 (its cool-down)"][1:3] == ["3.0143", "0.5848"]


def test_block_means_do_not_depend_on_chunking(unit):
    from hrgtc.evaluation import evaluate

    files, model, _ = unit
    trace = evaluate(model, files.cooldown, max_points=500,
                     read_options=recording.ReadOptions(chunk_rows=777)).axis
    run = recording.read(files.cooldown)
    rows = len(run) // 500  # 72 rows (36 s) per block: more than 10 s, 500 blocks
    assert trace.block_s == pytest.approx(rows / run.sample_rate_hz)
    expected = (run.rate_dph - run.metadata.input_rate_dph).reshape(-1, rows).mean(axis=1)
    np.testing.assert_allclose(trace.blocks["raw_dph"], expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(trace.blocks["resonator_c"],
                               run["resonator_c"].reshape(-1, rows).mean(axis=1), atol=1e-12)


def test_refuses_to_overwrite_without_force(unit, tmp_path):
    model = unit[1].with_parts(plateaus=())  # no figures: fast
    output = tmp_path / "report.html"
    output.write_text("keep me")
    with pytest.raises(OutputExistsError, match="--force"):
        build_report(model, [], output, soaks=[])
    assert output.read_text() == "keep me"
    build_report(model, [], output, soaks=[], force=True)
    assert output.read_text().startswith("<!DOCTYPE html>")
    assert not list(tmp_path.glob(".*.tmp"))  # written atomically, nothing left behind


def test_missing_soaks_are_said_and_stored_fits_drawn(unit, tmp_path):
    _, model, _ = unit
    inputs = [{**item, "path": str(tmp_path / "gone" / Path(item["path"]).name)}
              for item in model.provenance["inputs"]]
    moved = dataclasses.replace(model, provenance={**model.provenance, "inputs": inputs})
    output = build_report(moved, [], tmp_path / "report.html")
    text = output.read_text()
    page = _Page(text)
    assert "Soak recordings not found" in text and "soak_-20C.parquet" in text
    assert any("stored in the model" in caption for caption in page.captions)
    assert len(page.images) == 3  # stored settling fits, Fig. 4, Fig. 5(a); no Fig. 5(b)
    assert sorted(_number(row[0]) for row in page.table("Plateaus")) == sorted(SETPOINTS_C)
    assert all(row[3] == "missing" for row in page.table("Model inputs"))


def test_cli(unit, tmp_path):
    files, _, model_path = unit
    output = tmp_path / "cli.html"
    args = ["report", "--model", str(model_path), str(files.warmup), "-o", str(output),
            "--soak", str(files.soaks[0]), "--json"]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["report"] == str(output) and data["bytes"] == output.stat().st_size
    page = _Page(output.read_text())
    assert len(page.images) == 1 + 1 + 2 + 2  # one soak: Figs. 3, 4, 5(a), 5(b); one run
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 2 and "exists" in again.output
    bad = CliRunner().invoke(app, ["report", "--model", str(tmp_path / "none.json"),
                                   str(files.warmup), "-o", str(tmp_path / "x.html")])
    assert bad.exit_code == 2 and "no such model file" in bad.output


_CHECK = """<script>
window.addEventListener("load", async () => {
  const images = Array.from(document.images);
  await Promise.allSettled(images.map((image) => image.decode()));
  const loaded = images.filter((image) => image.complete && image.naturalWidth > 0).length;
  const marker = document.createElement("p");
  marker.id = "hrgtc-check";
  marker.textContent = `images=${images.length} loaded=${loaded}`;
  document.body.appendChild(marker);
});
</script>"""


def test_every_figure_loads_in_headless_chromium(report, tmp_path):
    """A real browser opens the report (``make test`` installs Debian's chromium)."""
    assert shutil.which("chromium"), "chromium is not installed: run 'make test' (it installs it)"
    _, text, page, _ = report
    probe = tmp_path / "probe.html"
    probe.write_text(text.replace("</body>", _CHECK + "</body>"), encoding="utf-8")
    command = [
        shutil.which("chromium"), "--headless", "--no-sandbox", "--disable-gpu",
        "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", f"--user-data-dir={tmp_path / 'ud'}",
        "--virtual-time-budget=10000", "--dump-dom", probe.as_uri(),
    ]
    dom = subprocess.run(command, capture_output=True, text=True, timeout=120, check=True).stdout
    found = re.search(r'id="hrgtc-check">images=(\d+) loaded=(\d+)<', dom)
    assert found, dom[-2000:]
    assert int(found.group(1)) == int(found.group(2)) == len(page.images) == 8


def test_intervals_and_noise_reasons_in_the_tables(unit, report):
    """Each bias stability carries its 1σ interval; a missing noise term shows its reason."""
    from hrgtc.evaluation import evaluate

    files, model, _ = unit
    _, _, page, _ = report
    result = evaluate(model, files.cooldown).axis
    row10 = next(row for row in page.table(f"Bias stability of {files.cooldown.name}")
                 if row[0] == "raw, τ = 10 s")
    low, high = result.stability_interval("raw", 10.0)
    bounds, inside = row10[3].split("] (")  # "[low, high] (68.3% CI, N blocks)"
    bounds = bounds.lstrip("[").split(", ")
    assert int(inside.rstrip(")").split(", N ")[1]) == result.bias_stability_blocks["raw"][10.0]
    assert float(bounds[0]) == pytest.approx(low, rel=1e-2)
    assert float(bounds[1]) == pytest.approx(high, rel=1e-2)
    noise = page.table(f"Allan noise terms of {files.cooldown.name}")
    cells = [row[1] for row in noise]  # each term's value, or the reason it is missing
    fields = {"arw": "arw_deg_per_rt_h", "bias_instability": "bias_instability_dph",
              "rrw": "rrw_dph_per_rt_h"}
    expected = [result.noise[k].text(t).split(" (")[0] if getattr(result.noise[k], fields[t])
                is not None else result.noise[k].text(t) for k in result.noise for t in fields]
    assert cells == expected
    assert any(cell.startswith("no ") for cell in cells) or all(
        n.rrw_reason is None for n in result.noise.values())
