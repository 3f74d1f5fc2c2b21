"""The report as hrgtc wrote it before it was data, then templates (issue 28, item 5): the
f-string sections of ``hrgtc.report.html`` and the body of ``build_report`` at commit 8b58650,
kept to check that the templates show the same page (``tests/report/test_templates.py``).
Not maintained: it renders what the report showed then."""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Mapping, Sequence
from datetime import UTC, datetime
from html import escape
from pathlib import Path
from typing import Any

import numpy as np

import hrgtc.report.figures as figures
from hrgtc.core.summary import Summary
from hrgtc.evaluation import Evaluation
from hrgtc.evaluation.calibration_figures import (
    EQ18,
    PLATEAUS,
    SENSOR_THERMOMETER,
    TABLE1,
    TABLE2,
    calibration_summary,
    drift_heading,
    power_text,
    thermometer_tables,
)
from hrgtc.evaluation.glance_figures import GLANCE, glance_summary, instrument_glance_summary
from hrgtc.model import Model
from hrgtc.report.figures import SoakTrace
from hrgtc.report.inputs import ReportInputs, evaluate_runs, trace_soaks
from hrgtc.report.tables import INPUTS, SOAK_ERROR, provenance_summary, soak_error_summary
from hrgtc.thermometry import paper
from hrgtc.thermometry.plateaus import Plateau

__all__ = ["legacy_html"]

PathLike = str | os.PathLike[str]

REFERENCE = (
    "X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, “Temperature Drift Compensation for "
    "Hemispherical Resonator Gyro Based on Natural Frequency”, <i>Sensors</i> 12(5), "
    "6434–6446, 2012"
)
DOI = "10.3390/s120506434"
#: [1] without its title, as a sensor model's report cites it (the method is the paper's; the
#: resonator and natural frequency of its title are not the sensor's).
CITATION = "X. Wang et al., <i>Sensors</i> 12(5), 6434–6446, 2012"


def reference(sensor: bool) -> str:
    """[1] as the report cites it: in full, or without its title on a sensor model."""
    return CITATION if sensor else REFERENCE


# -- HTML pieces ----------------------------------------------------------------------------
_CSS = """
body{font:15px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,"DejaVu Sans",sans-serif;
color:#1d1d1f;background:#fff;margin:0 auto;max-width:1120px;padding:1.2em 2em 3em}
h1{font-size:1.7em;margin:.2em 0}h2{font-size:1.3em;margin-top:2em;border-bottom:2px solid #ddd;
padding-bottom:.2em}h3{font-size:1.08em;margin-top:1.6em}
figure{margin:1.2em 0;padding:.6em;border:1px solid #e4e4e4;border-radius:4px;background:#fcfcfc}
figure img{display:block;max-width:100%;height:auto;margin:0 auto}
figcaption{font-size:.9em;color:#444;margin-top:.5em}
table{border-collapse:collapse;margin:.8em 0;font-size:.9em}
caption{caption-side:top;text-align:left;font-weight:600;padding-bottom:.3em}
th,td{border:1px solid #d6d6d6;padding:.25em .6em;white-space:nowrap}
th{background:#f1f3f5;text-align:center;white-space:normal}.scroll{overflow-x:auto}
td.n{text-align:right;font-variant-numeric:tabular-nums}
code,.eq{font-family:ui-monospace,"DejaVu Sans Mono",Menlo,Consolas,monospace;font-size:.92em}
.eq{background:#f5f7fa;border-left:3px solid #8aa4c8;padding:.5em .8em;overflow-x:auto}
.note{background:#fff7e0;border-left:3px solid #e0b040;padding:.4em .8em}
.warning{background:#fdecea;border-left:3px solid #c0392b;padding:.4em .8em}
nav ol{columns:2;font-size:.92em}.muted{color:#666;font-size:.9em}
"""


def _number(value: Any, digits: int = 4, fixed: int | None = None, sign: bool = False) -> str:
    """A number for a table: ``fixed`` decimals or ``digits`` significant; "–" if missing."""
    if value is None or not math.isfinite(float(value)):
        return "–"
    plus = "+" if sign else ""
    if fixed is not None:
        return f"{float(value):{plus}.{fixed}f}"
    return f"{float(value):{plus}.{digits}g}"


def _pvalue(value: float | None) -> str:
    """A p-value, with underflow shown as a bound."""
    if value is None or not math.isfinite(value):
        return "–"
    return "< 1e-300" if value == 0 else f"{value:.3g}"


def _table(headers: Sequence[str], rows: Iterable[Sequence[Any]], caption: str = "") -> str:
    """A table; cells are escaped text, numbers (from :func:`_number`) right aligned."""
    head = "".join(f"<th>{escape(h)}</th>" for h in headers)
    body = []
    for row in rows:
        cells = []
        for cell in row:
            raw = str(cell)
            numeric = raw[:1] in "+-–<0123456789"
            text = escape(raw)
            cells.append(f'<td class="n">{text}</td>' if numeric else f"<td>{text}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    cap = f"<caption>{escape(caption)}</caption>" if caption else ""
    return (f'<div class="scroll"><table>{cap}<thead><tr>{head}</tr></thead>'
            f"<tbody>{''.join(body)}</tbody></table></div>")


class _Page:
    """Numbers figures as they are added."""

    def __init__(self) -> None:
        self.parts: list[str] = []
        self.count = 0

    def add(self, *html: str) -> None:
        self.parts.extend(html)

    def figure(self, figure: Any, caption: str, alt: str) -> None:
        self.count += 1
        self.add(f'<figure><img src="{figures.svg_data_uri(figure)}" alt="{escape(alt)}">'
                 f"<figcaption><b>Figure {self.count}.</b> {caption}</figcaption></figure>")

    def note(self, text: str) -> None:
        self.add(f'<p class="note">{text}</p>')


# -- sections --------------------------------------------------------------------------------
#: The sections of one axis: link id, title, and its title on a sensor model (no frequency;
#: None: it has no such section, and no figure or equation of [1] is its).
_SECTIONS = (("settling", "Settling of the soaks (Fig. 3)", None),
             ("thermometer", "Frequency–temperature fit (Fig. 4, Table 1, Eq. 18)", None),
             ("temperature", "Temperature from frequency (Fig. 5, Table 2)", None),
             ("runs", "Runs: raw and compensated output (Fig. 6), Allan deviation",
              "Runs: raw and compensated output, Allan deviation"),
             ("model", "Drift model: stepwise regression (Eq. 21–22)",
              "Drift model: stepwise regression"))


def _header(page: _Page, model: Model, title: str, model_path: str | None,
            axis: str = "") -> None:
    """Title, provenance and the contents: the sections the axes have (a sensor model has
    no Figs. 3-5), linked to the first axis's (``axis``: its id prefix) when there are
    several."""
    prov = model.provenance
    sensor = model.thermometer.source == "sensor"
    page.add(f"<header><h1>{escape(title)}</h1>",
             f"<p>Unit <b>{escape(model.unit)}</b>. Model file "
             f"<code>{escape(model_path or '(in memory)')}</code>, written by hrgtc "
             f"{escape(str(prov.get('hrgtc_version', '?')))} on "
             f"{escape(str(prov.get('created_utc', '?')))}. Report generated "
             f"{datetime.now(UTC).isoformat(timespec='seconds')}.</p>",
             f'<p class="muted">{"Method" if sensor else "Method and figures"} after '
             f'[1] {reference(sensor)}, doi:<a href="https://doi.org/{DOI}">{DOI}</a>.</p>'
             "</header>")
    inputs = provenance_summary(prov)
    if inputs.sections:
        page.add(_grid_table(inputs, INPUTS, INPUTS))
    prefix = f"{axis}-" if axis else ""
    items = "".join(f'<li><a href="#{prefix}{key}">{escape(sensor_text if sensor else text)}'
                    + (f" (axis {escape(axis)})" if axis else "") + "</a></li>"
                    for key, text, sensor_text in _SECTIONS if sensor_text or not sensor)
    page.add(f"<nav><ol>{items}</ol></nav>")


def _summary(page: _Page, runs: Sequence[Evaluation], sensor: bool = False) -> None:
    """The result at a glance: 10 s bias stability of each run beside the paper's
    (:func:`~hrgtc.evaluation.glance_figures.glance_summary`; ``sensor``: a temperature
    sensor's model, not beside the paper's HRG)."""
    if runs:
        page.add(_grid_table(glance_summary(runs, paper_row=not sensor), GLANCE,
                             "At a glance: 10 s bias stability, raw and compensated"))


def _section_table(page: _Page, summary: Summary, heading: str, caption: str) -> None:
    """One section of a calibration's summary as a table (figure, value, unit, interval)."""
    rows = [row[1:] for row in summary.rows() if row[0] == heading]
    if rows:
        page.add(_table(("figure", "value", "unit", "interval"), rows, caption))


def _grid_table(summary: Summary, heading: str, caption: str,
                columns: Sequence[str] | None = None) -> str:
    """A section of table cells of ``summary`` (:meth:`Summary.grid`) as a table; a missing
    number shows as "–"."""
    headers, rows = summary.grid(heading, columns)
    return _table(headers, [["–" if c == "-" else c for c in row] for row in rows], caption)


def _match(plateaus: Sequence[Plateau], source: str) -> list[Plateau]:
    """Plateaus found in ``source``: the same file, else the same file name."""
    same = [p for p in plateaus if p.source and os.path.realpath(p.source)
            == os.path.realpath(source)]
    return same or [p for p in plateaus if p.source and Path(p.source).name == Path(source).name]


def _settling(page: _Page, plateaus: Sequence[Plateau], traces: Sequence[SoakTrace],
              missing: Sequence[str], tables: Summary) -> None:
    """Fig. 3 and the plateaus (``tables``: :func:`thermometer_tables` of the unit)."""
    page.add('<section id="settling"><h2>1. Settling of the soaks</h2>')
    if missing:
        page.note("Soak recordings not found: " + ", ".join(
            f"<code>{escape(m)}</code>" for m in missing)
            + ". Pass them with --soak (soaks= in Python).")
    caption = ("Resonator frequency during each chamber soak, {} means, mirrors <b>Fig. 3</b> "
               "of [1] (the paper's resonator settled after ~15,000 s). Red: settling-curve "
               "fit; dashed: its extrapolation; dotted: the settled frequency used for Table 1; "
               "shaded: the final stretch of the soak.")
    if traces:
        panels = [_match(plateaus, t.source) for t in traces]
        page.figure(figures.settling_figure(traces, panels),
                    caption.format(f"{traces[0].block_s:g} s"), "frequency of each soak vs time")
    elif any(p.fit is not None for p in plateaus):
        with_fit = [p for p in plateaus if p.fit is not None]
        page.figure(figures.settling_figure([None] * len(with_fit), [[p] for p in with_fit]),
                    "No soak recordings on disk: the settling-curve fits stored in the model, "
                    "mirrors <b>Fig. 3</b> of [1].", "stored settling fits of each soak")
    else:
        page.note("No soak recordings and no stored settling fits: the settling figure "
                  "cannot be drawn.")
    page.add(_grid_table(tables, PLATEAUS, "Plateaus of the unit (from the model file)"),
             "</section>")


def _table_rows(model: Model, plateaus: Sequence[Plateau]) -> list[dict[str, float]]:
    t = np.array([p.chamber_c for p in plateaus])
    f = np.array([p.settled_freq_hz for p in plateaus])
    estimate = model.thermometer.temperature(f, warn=False) if f.size else f
    return [{"chamber_c": a, "freq_hz": b, "temperature_c": c, "error_c": c - a}
            for a, b, c in zip(t, f, estimate, strict=True)]


def _thermometer(page: _Page, model: Model, plateaus: Sequence[Plateau],
                 table: Sequence[Mapping[str, float]], tables: Summary) -> None:
    """Fig. 4, Table 1, the thermometer's figures and Eq. 18 beside the paper's
    (``tables``: :func:`thermometer_tables` of the unit)."""
    th = model.thermometer
    page.add('<section id="thermometer"><h2>2. Frequency–temperature fit</h2>')
    if plateaus:
        page.figure(figures.thermometer_figure(
            th, [r["chamber_c"] for r in table], [r["freq_hz"] for r in table],
            [p.settled_freq_std_hz for p in plateaus]),
            "Left: the unit's plateau points (Table 1) and the fitted polynomial, mirrors "
            "<b>Fig. 4</b> of [1]. Right: residuals f − f<sub>fit</sub> in mHz (error bars: "
            "standard error of each settled frequency) and their equivalent in °C.",
            "frequency-temperature fit and residuals")
    page.add(_grid_table(tables, TABLE1, "The unit's Table 1"))
    summary = calibration_summary(model, table)
    _section_table(page, summary, "thermometer (Eq. 18)",
                   "Thermometer (Eq. 18): coefficients c0 (constant) to c3 (T³) ± 1σ, p-values, "
                   "fit")
    page.add(_grid_table(tables, EQ18, "Coefficients beside the paper's, highest power first"))
    high, powers = th.coefficients_high_first, range(th.order, -1, -1)
    terms = " ".join(f"{'−' if c < 0 else '+'} {abs(c):.7g}"
                     + (f"·{power_text('T', n)}" if n else "")
                     for n, c in zip(powers, high, strict=True))
    page.add(f'<p class="eq">f = {terms.lstrip("+ ")} &nbsp;[Hz, T in °C]</p>',
             f'<p class="muted">Eq. (18) form. Residual std {_number(1e3 * th.residual_std_hz, 3)} '
             f"mHz, R² {th.rsquared:.10f}, {th.n_points} points, calibrated "
             f"{th.temperature_range_c[0]:g} to {th.temperature_range_c[1]:g} °C. The paper's "
             "unit: f = 1.528e−5·T³ − 9.702e−4·T² + 0.3716·T + 4424.901.</p></section>")


def _temperature(page: _Page, table: Sequence[Mapping[str, float]],
                 traces: Sequence[SoakTrace], tables: Summary) -> None:
    """Fig. 5(a), Table 2 (``tables``: :func:`thermometer_tables` of the unit) and
    Fig. 5(b)."""
    page.add('<section id="temperature"><h2>3. Temperature from frequency</h2>')
    if table:
        page.figure(figures.temperature_error_figure(table),
                    "Temperature from frequency (inverse of Eq. 18) minus the chamber "
                    "temperature at each plateau, mirrors <b>Fig. 5(a)</b> of [1]; open circles: "
                    "the paper's unit (Table 2 of [1]).", "temperature error at each plateau")
    page.add(_grid_table(tables, TABLE2, "The unit's Table 2"))
    if traces:
        page.figure(figures.soak_temperature_figure(traces),
                    "Resonator temperature from frequency during each soak, mirrors "
                    "<b>Fig. 5(b)</b> of [1], beside the chamber and (simulated soaks) the true "
                    "resonator temperature.", "temperature from frequency during each soak")
        errors = soak_error_summary(traces)
        if errors.sections:
            page.add(_grid_table(errors, SOAK_ERROR, SOAK_ERROR))
    else:
        page.note("No soak recordings: the temperature-vs-time figure (Fig. 5(b)) needs them.")
    page.add("</section>")


def _recorded(run: Evaluation) -> str:
    """How long the run recorded: its samples' time; for a burst logger also its bursts
    and their spacing (the span is many times the recorded time)."""
    text = f"{run.duration_s / 3600:.3g} h recorded"
    burst = next(iter(run.burst_allan.values()), None)
    if burst is not None:
        text += f", in bursts of {burst.burst_s:.3g} s every {burst.period_s:.4g} s"
    return text


def _run(page: _Page, k: int, run: Evaluation, model: Model) -> None:
    page.add(f'<section id="run-{k}"><h3>4.{k} Run <code>{escape(run.name)}</code></h3>',
             f'<p class="muted">{escape(run.source)}: unit {escape(run.unit)}, {run.n_samples} '
             f"samples at {run.sample_rate_hz:g} Hz ({_recorded(run)}), input "
             f"rate {run.input_rate_dph:g} °/h.</p>")
    hrg = model.thermometer.source != "sensor"  # the paper's figures are an HRG's
    mirrors = (" mirrors <b>Fig. 6(a)</b> of [1];", " mirrors <b>Fig. 6(b)</b>;") if hrg else (
        "", "")
    page.figure(figures.run_figure(run, not hrg),
                f"(a) Gyro output minus the input rate with the drift model (red),{mirrors[0]} "
                f"(b) compensated output,{mirrors[1]} (c) temperatures. {run.block_s:g} s "
                f"means; red shading: samples outside the calibrated range.",
                f"raw and compensated output of {run.name}")
    summary = run.figures(sensor=not hrg, warnings=False)
    for line in run.range_warnings():  # where the reader looks, not only in the JSON
        page.add(f'<p class="warning"><b>Beyond the calibration.</b> '
                 f"{escape(line.removeprefix('warning: '))}</p>")
    captions = {"bias stability": f" with its {run.confidence:.3g} chi-squared interval, "
                "(blocks − 1) degrees of freedom" + (
                    " (paper [1], Section 4.2: 3.0143 → 0.5848 °/h on its cool-down)"
                    if hrg else ""),
                "Allan noise terms": " (IEEE Std 952-1997, Annex C)"}
    rows = summary.rows()
    for heading, _ in summary.sections:
        if heading.startswith("heating and cooling apart"):  # added after 8b58650: below
            continue
        if heading.startswith("Allan") and run.allan:
            _allan_figure(page, run)
        head, _, detail = heading.partition(" (")
        caption = (f"{head[:1].upper()}{head[1:]} of {run.name}"
                   + (f" ({detail}" if detail else "") + captions.get(head, ""))
        page.add(_table(("figure", "value", "unit", "interval"),
                        [row[1:] for row in rows if row[0] == heading], caption))
    if run.allan and not run.noise:
        _allan_figure(page, run)
    _heating_cooling(page, run, hrg)
    if model.housing is not None and "housing" not in run.bias_stability_dph:
        page.note("Housing baseline not applied: the run has no housing_c column.")
    for note in summary.notes:
        page.note(escape(note))
    page.add("</section>")


def _heating_cooling(page: _Page, run: Evaluation, hrg: bool) -> None:
    """Added after 8b58650 (issue 29, item 3), as an f-string reference of the template's
    table: a row per direction with a block, a sentence per direction without one."""
    split = run.directions
    if split is None:
        return
    what, block = "resonator temperature" if hrg else "temperature", f"{split.block_s:g} s"
    if split.reason is not None:
        page.note(escape(f"Heating and cooling apart: no {block} block ({split.reason})."))
        return
    truth = split.residual_rms_dph is not None
    rows = [[d, str(split.blocks[d]), _number(split.raw_dph[d]),
             _number(split.compensated_dph[d]), _number(split.improvement(d), 3)]
            + ([_number(split.residual_rms_dph[d])] if truth else [])
            for d in ("heating", "cooling") if split.blocks[d]]
    if rows:
        page.add(_table(["direction", f"{block} blocks", "raw (°/h)", "compensated (°/h)",
                         "improvement (×)"] + (["RMS model − true bias (°/h)"] if truth else []),
                        rows, f"Heating and cooling apart of {run.name}: {block} bias stability "
                        f"by the sign of the {what} rate, raw and compensated"))
    total = sum(split.blocks.values())
    for d, other in (("heating", "cooling"), ("cooling", "heating")):
        if not split.blocks[d]:
            page.note(escape(f"No {d} block: the run's {total} blocks of {block} outside the "
                             f"dead band of the {what} rate were all {other}."))


def _allan_figure(page: _Page, run: Evaluation) -> None:
    page.figure(figures.allan_figure(run),
                f"Deviation ({run.deviation}) of the output before and after compensation "
                f"(octave τ) with its {run.confidence:.3g} chi-squared interval where "
                "SP 1065 gives one; squares mark a flat bias-instability minimum.",
                f"Allan deviation of {run.name}")


def _excluded(d: Any) -> str:
    names = [c for c in d.candidates if c not in d.selected]
    if not names:
        return ""
    pairs = zip(names, d.stepwise.excluded_pvalues, strict=True)
    return " Not in the model (p-value if added): " + ", ".join(
        f"<code>{escape(n)}</code> {_pvalue(p) if math.isfinite(p) else 'n/a'}"
        for n, p in pairs) + "."


def _drift_model(page: _Page, model: Model) -> None:
    """The drift model: its candidates, steps and coefficients; on a resonator beside the
    paper's Eq. 21-22, on a temperature sensor in its own words."""
    d = model.drift
    sensor = model.thermometer.source == "sensor"
    page.add('<section id="model"><h2>5. Drift model: stepwise regression</h2>',
             f"<p>Candidates{'' if sensor else ' (Eq. 21 of [1] by default)'}: "
             f"<code>{escape(', '.join(d.candidates))}"
             f"</code>. Fitted on {d.n_windows} means of {d.window_s:g} s ({d.n_samples} "
             f"samples); p-to-enter {d.stepwise.penter:g}, p-to-remove {d.stepwise.premove:g}; "
             f"stopped: {escape(d.stepwise.stop_reason)}.{_excluded(d)}</p>")
    summary = calibration_summary(model)
    _section_table(page, summary, "stepwise steps", "Stepwise steps")
    _section_table(page, summary, drift_heading(sensor),
                   "The final model: coefficients ± 1σ, p-values, fit")
    kept = [n for n in d.selected if n in paper.EQ22_TERMS]
    if not sensor:
        page.add(f"<p>Terms also kept in Eq. 22 of [1]: {escape(', '.join(kept) or 'none')}.</p>")
    page.add(f'<p class="eq">{escape(d.equation(sensor))}</p>',
             f'<p class="muted">{"" if sensor else "Eq. (22) form. "}Residual std '
             f"{_number(d.residual_std_dph)} °/h on {d.window_s:g} s means, R² "
             f"{d.rsquared:.6f}.</p>")
    if d.variance_inflation > 1.0:
        page.note(f"F-tests and standard errors corrected for autocorrelated window residuals "
                  f"(Newey–West, {d.bandwidth_windows} windows): variance inflation "
                  f"{d.variance_inflation:.3g}.")
    if model.housing is not None:
        _section_table(page, summary, "housing-thermistor baseline",
                       "Classical baseline (housing thermistor)")
        page.add(f'<p class="eq">{escape(model.housing.equation())}</p>')
    page.add("</section>")


def _scale_factor(page: _Page, model: Model) -> None:
    """The scale-factor model: per-temperature k from the rate-table holds and k(f)."""
    sf = model.scale_factor
    if sf is None:
        return
    page.add('<section id="scale"><h2>6. Scale factor against frequency</h2>',
             f"<p>Rate-table holds grouped by temperature; in each group rate = b + (1 + k)·Ω "
             f"by least squares, then k(f) by stepwise regression over candidates "
             f"<code>{escape(', '.join(sf.candidates))}</code>. Compensation applies "
             f"rate_comp = (rate − bias(f, ḟ)) / (1 + k(f)·10⁻⁶).</p>")
    summary = sf.summary()
    shown = summary.figures()
    page.add(_grid_table(summary, "scale-factor temperature groups",
                         "Temperature groups of the rate-table holds",
                         ("mean frequency", "k", "std error", "model k", "holds")),
             f'<p class="eq">{escape(sf.equation())}</p>',
             f'<p class="muted">Residual {shown["scale_factor.residual_ppm"].number()} ppm '
             f"RMS over the groups; "
             f"|input| up to {shown['scale_factor.input_rate_max_dps'].number()} °/s.</p>"
             "</section>")


def legacy_html(inputs: ReportInputs) -> str:
    """The page ``build_report`` wrote from ``inputs`` before the templates (its body at
    8b58650, with the reading of the runs and soaks it shares with the new one)."""
    instrument = inputs.instrument
    first = next(iter(instrument.axes.values()))
    traced = {axis: m.thermometer for axis, m in instrument.axes.items()
              if m.thermometer.source != "sensor"}
    title = inputs.title
    page = _Page()
    _header(page, instrument.of_axis(next(iter(instrument.axes))), title
            or f"Temperature compensation report — unit {instrument.unit}", inputs.model_path,
            "" if instrument.is_single_axis else next(iter(instrument.axes)))
    evaluations = evaluate_runs(inputs, lambda rows: None)
    traces = trace_soaks(inputs, traced, lambda rows: None)
    sections: dict[str, list[str]] = {}
    for axis in instrument.axes:
        axis_page = _Page()
        axis_page.count = page.count
        _unit_sections(axis_page, instrument.of_axis(axis), evaluations[axis], traces.get(axis, []),
                       list(inputs.missing_soaks), instrument.temperature_map)
        page.count = axis_page.count
        sections[axis] = axis_page.parts
    if instrument.is_single_axis:
        _summary(page, evaluations[""], first.thermometer.source == "sensor")
        page.add(*sections[""])
    else:
        _instrument_summary(page, instrument, evaluations)
        for axis, parts in sections.items():
            html = "\n".join(parts).replace(' id="', f' id="{axis}-').replace(
                'href="#', f'href="#{axis}-')
            page.add(f'<section id="axis-{escape(axis)}"><h2 class="axis">Axis '
                     f"{escape(axis)}</h2>", html, "</section>")
    body = "\n".join(page.parts)
    title_text = title or f"Temperature compensation report — unit {instrument.unit}"
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{escape(title_text)}</title>"
            f"<style>{_CSS}</style></head><body>\n{body}\n<footer class=\"muted\"><p>[1] "
            f"{reference(first.thermometer.source == 'sensor')}. doi:{DOI}. Generated by "
            "hrgtc.</p></footer></body></html>\n")


def _unit_sections(page: _Page, model: Model, evaluations: Sequence[Evaluation],
                   traces: Sequence[SoakTrace], missing: list[str],
                   temperature_map: dict[str, Any] | None = None) -> None:
    """One axis's sections: Figs. 3-5 and Tables 1-2 (a sensor thermometer: what it is and
    the map of its count, ``temperature_map``), its runs, drift and scale factor."""
    plateaus = [Plateau.from_dict(p) for p in model.plateaus]
    table = _table_rows(model, plateaus)
    sensor = model.thermometer.source == "sensor"
    if sensor:
        low, high = model.thermometer.temperature_range_c
        page.note(f"No frequency output: the gyro's temperature sensor is the thermometer "
                  f"(trained {low:.2f} to {high:.2f} °C); no soak settling, frequency fit or "
                  "temperature from frequency to show.")
        _section_table(page, calibration_summary(model, temperature_map=temperature_map),
                       SENSOR_THERMOMETER, "Thermometer: the gyro's temperature sensor"
                       + (", its count mapped to °C by the reference log" if temperature_map
                          else ", read directly"))
    else:
        tables = thermometer_tables(model.thermometer, plateaus)
        _settling(page, plateaus, traces, missing, tables)
        _thermometer(page, model, plateaus, table, tables)
        _temperature(page, table, traces, tables)
    page.add('<section id="runs"><h2>4. Runs: raw and compensated output</h2>')
    if not evaluations:
        page.note("No runs given.")
    for k, run in enumerate(evaluations, start=1):
        _run(page, k, run, model)
    page.add("</section>")
    _drift_model(page, model)
    _scale_factor(page, model)


def _instrument_summary(page: _Page, model: Model,
                        evaluations: dict[str, list[Evaluation]]) -> None:
    """The instrument at a glance: each axis's 10 s bias stability per run, scale factor."""
    page.add(f'<section id="instrument"><h2>Instrument {escape(model.unit)}: '
             f"{len(model.axes)} axes</h2>",
             _grid_table(instrument_glance_summary(model, evaluations), GLANCE,
                         "At a glance: 10 s bias stability per axis and run"),
             "<nav><ol>" + "".join(f'<li><a href="#axis-{escape(a)}">Axis {escape(a)}</a></li>'
                                   for a in model.axes) + "</ol></nav></section>")
