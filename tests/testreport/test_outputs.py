"""The test report's files: the HTML opened in headless Chromium, the PDF it prints, the JSON
of every figure, and the command line."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import pytest
from typer.testing import CliRunner

from hrgtc.cli import app
from hrgtc.core.errors import InputError, OutputExistsError
from hrgtc.report import build_report
from hrgtc.report.test_report import write_test_report
from hrgtc.settings.compensation import ReportSettings
from hrgtc.testreport import FIGURES

SPEC = """[limits.bias_repeatability_dph]
max = 5.0
[limits.bias_temperature_sensitivity_dph_per_c]
min = -0.05
max = 0.05
[limits.scale_factor_error_ppm]
max = 100
"""

_CHECK = """<script>
window.addEventListener("load", async () => {
  const images = Array.from(document.images);
  await Promise.allSettled(images.map((image) => image.decode()));
  const loaded = images.filter((image) => image.complete && image.naturalWidth > 0).length;
  const rows = document.querySelectorAll("tr[id^='figure-']").length;
  const verdict = document.getElementById("verdict").textContent;
  const title = document.querySelector("h1").textContent;
  const marker = document.createElement("p");
  marker.id = "hrgtc-check";
  marker.textContent = `images=${images.length} loaded=${loaded} rows=${rows} ` +
    `verdict=${verdict} title=${title}`;
  document.body.appendChild(marker);
});
</script>"""


@pytest.fixture(scope="module")
def written(campaign, tmp_path_factory):
    folder = tmp_path_factory.mktemp("outputs")
    spec = folder / "spec.toml"
    spec.write_text(SPEC, encoding="utf-8")
    return write_test_report(campaign.manifest, folder / "report.html", spec=spec), spec


def test_the_page_opens_in_headless_chromium(written, tmp_path):
    """A real browser parses the page: both figures load, a row per figure, the verdict, the
    title's markup shown as text (escaped: the manifest's title is "Acceptance test
    <simulated>")."""
    assert shutil.which("chromium"), "chromium is not installed: run 'make test' (it installs it)"
    files, _ = written
    probe = tmp_path / "probe.html"
    probe.write_text(files.html.read_text(encoding="utf-8").replace("</body>", _CHECK + "</body>"),
                     encoding="utf-8")
    command = [
        shutil.which("chromium"), "--headless", "--no-sandbox", "--disable-gpu",
        "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", f"--user-data-dir={tmp_path / 'ud'}",
        "--virtual-time-budget=10000", "--dump-dom", probe.as_uri(),
    ]
    dom = subprocess.run(command, capture_output=True, text=True, timeout=120, check=True).stdout
    found = re.search(r'id="hrgtc-check">images=(\d+) loaded=(\d+) rows=(\d+) '
                      r'verdict=([a-z ]+) title=([^<]*)<', dom)
    assert found, dom[-2000:]
    assert int(found.group(1)) == int(found.group(2)) == 2  # bias against T, Allan deviation
    assert int(found.group(3)) == len(FIGURES)
    assert found.group(4) == files.report.verdict
    assert found.group(5) == "Acceptance test &lt;simulated&gt;"  # text, not a tag


def test_the_pdf_is_printed(written):
    files, _ = written
    assert files.pdf is not None and files.pdf.read_bytes()[:5] == b"%PDF-"
    assert files.pdf.stat().st_size > 10_000


def test_the_json_holds_every_figure_with_its_uncertainty_and_verdict(written):
    files, _ = written
    data = json.loads(files.json.read_text(encoding="utf-8"))
    figures = {f["name"]: f for f in data["figures"]}
    assert set(figures) == set(FIGURES)
    for figure in figures.values():
        assert figure["clause"] and figure["definition"] and figure["verdict"]
        if figure["value"] is not None and figure["expanded_uncertainty"] is not None:
            assert figure["coverage_factor"] == 2.0
    repeatability = figures["bias_repeatability_dph"]
    assert repeatability["expanded_uncertainty"][1] == pytest.approx(
        2.0 * repeatability["standard_uncertainty"])
    assert repeatability["verdict"] == "accept"  # 0.8 ± 0.6 °/h against 5
    assert figures["bias_temperature_sensitivity_dph_per_c"]["verdict"] == "reject"  # 0.2 vs 0.05
    assert figures["scale_factor_error_ppm"]["verdict"] == "not measured"
    assert data["verdict"] == "reject"
    hashes = {i["what"]: i["sha256"] for i in data["inputs"]}
    assert {"manifest", "spec", "model"} <= set(hashes)
    assert sum(i["what"].startswith("run") for i in data["inputs"]) == 10
    assert all(re.fullmatch(r"[0-9a-f]{64}", h) for h in hashes.values())
    assert data["serial"] == "SN-0042" and data["equipment"][0]["certificate"]
    assert data["hrgtc_version"]


def test_outputs_are_never_overwritten_without_force(written):
    files, _ = written
    before = files.html.read_bytes()
    with pytest.raises(OutputExistsError):
        write_test_report(files.report.campaign, files.html, pdf=False)
    assert files.html.read_bytes() == before


def test_no_browser_is_an_error_naming_the_fix(campaign, tmp_path, monkeypatch):
    """Checked before any run is read; nothing written."""
    import hrgtc.report.test_report as module

    monkeypatch.setattr(module, "BROWSERS", ("no-such-browser-hrgtc",))
    with pytest.raises(InputError, match="--no-pdf"):
        write_test_report(campaign.manifest, tmp_path / "r.html")
    assert not any(tmp_path.iterdir())


def test_build_report_refuses_the_test_report_kind(campaign, tmp_path):
    with pytest.raises(InputError, match="hrgtc test-report"):
        build_report(campaign.folder / "model.json", [], tmp_path / "r.html",
                     ReportSettings(kind="test-report"), soaks=[])


def test_the_command_writes_the_files_and_its_json(campaign, tmp_path):
    output = tmp_path / "report.html"
    result = CliRunner().invoke(app, ["test-report", str(campaign.manifest), "-o", str(output),
                                      "--no-pdf", "--json"])
    assert result.exit_code == 0, result.output
    data = json.loads(result.stdout)
    assert data["html"] == str(output) and data["pdf"] is None
    assert json.loads(output.with_suffix(".json").read_text(encoding="utf-8"))["figures"] \
        == data["figures"]
    again = CliRunner().invoke(app, ["test-report", str(campaign.manifest), "-o", str(output),
                                     "--no-pdf"])
    assert again.exit_code == 2 and "--force" in again.output
