"""The fleet report: one self-contained HTML file over the fleet table.

Per axis (the fleet table is long-form, a row per unit × axis; the x axes of a
fleet of instruments are one population, their y axes another): distributions of
the units' f at 20 °C, temperature coefficient of frequency, relative thermometer
coefficients (the basis of the population prior) and improvement of the 10 s bias
stability (Section 4.2 of [1]); outliers by a robust z-score, z = 0.6745 (x -
median) / MAD (Iglewicz and Hoaglin's modified z-score, flagged beyond 3.5), on
each relative coefficient and on the improvement, within the axis's population;
and the units that failed, with the error and its file, column and row. A fleet of
single-axis units is the one population of axis "".

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from datetime import UTC, datetime
from html import escape
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from hrgtc.core.files import refuse_existing, write_text_atomic
from hrgtc.report.figures import svg_data_uri

__all__ = ["OUTLIER_Z", "build_fleet_report", "by_axis", "outliers", "robust_z"]

#: Modified z-score beyond which a unit is flagged (Iglewicz and Hoaglin, 1993).
OUTLIER_Z = 3.5

_CSS = """body{font-family:system-ui,sans-serif;max-width:72em;margin:2em auto;padding:0 1em;
color:#222}h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.9em;margin:.8em 0}th,td{border:1px solid #d6d6d6;
padding:.2em .5em}th{background:#f1f3f5}td.n{text-align:right;font-variant-numeric:tabular-nums}
figure{margin:1em 0}img{max-width:100%}.bad{color:#b00020}.muted{color:#666;font-size:.9em}"""


def robust_z(values: Sequence[float | None]) -> np.ndarray:
    """Modified z-score 0.6745 (x - median) / MAD; NaN for missing values or MAD = 0."""
    x = np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    finite = x[np.isfinite(x)]
    if finite.size < 3:
        return np.full(x.shape, np.nan)
    median = np.median(finite)
    mad = np.median(np.abs(finite - median))
    if mad == 0:
        return np.full(x.shape, np.nan)
    return 0.6745 * (x - median) / mad


def _quantities(rows: Sequence[dict[str, Any]]) -> dict[str, list[float | None]]:
    order = max((len(r.get("relative_coefficients") or []) for r in rows), default=0)
    out: dict[str, list[float | None]] = {
        "f20_hz": [r.get("f20_hz") for r in rows],
        "tcf_ppm_per_c": [r.get("tcf_ppm_per_c") for r in rows],
    }
    for k in range(order):
        out[f"b{k + 1}"] = [(r.get("relative_coefficients") or [None] * order)[k] for r in rows]
    out["improvement_10s"] = [r.get("median_improvement_10s") for r in rows]
    return out


def by_axis(rows: Sequence[dict[str, Any]]) -> dict[str, list[dict[str, Any]]]:
    """The calibrated rows (status ok or skipped) of each axis, axes in order of appearance
    (a table written before the long form, without ``axis``: the one axis "")."""
    groups: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        if row.get("status") in ("ok", "skipped"):
            groups.setdefault(row.get("axis") or "", []).append(row)
    return groups


def outliers(rows: Sequence[dict[str, Any]], limit: float = OUTLIER_Z) -> list[dict[str, Any]]:
    """Units whose relative coefficients or improvement have |robust z| > ``limit`` among
    the units' same axis (``axis`` of each flag: "" for single-axis units)."""
    flagged = []
    for axis, done in by_axis(rows).items():
        for name, values in _quantities(done).items():
            if name in ("f20_hz", "tcf_ppm_per_c"):
                continue  # b1 carries the TCF; f20 spread is geometry, not a fault
            for row, value, z in zip(done, values, robust_z(values), strict=True):
                if math.isfinite(z) and abs(z) > limit:
                    flagged.append({"unit": row["unit"], "axis": axis, "quantity": name,
                                    "value": value, "z": float(z)})
    return flagged


def _histograms(quantities: dict[str, list[float | None]]) -> Figure:
    names = [n for n, v in quantities.items() if any(x is not None for x in v)]
    columns = 3
    rows = max(1, -(-len(names) // columns))
    figure = Figure(figsize=(10.0, 2.6 * rows), layout="constrained")
    labels = {"f20_hz": "f at 20 °C [Hz]", "tcf_ppm_per_c": "TCF at 20 °C [ppm/°C]",
              "improvement_10s": "improvement of 10 s bias stability [×]"}
    for k, name in enumerate(names):
        ax = figure.add_subplot(rows, columns, k + 1)
        values = np.array([v for v in quantities[name] if v is not None], dtype=float)
        ax.hist(values, bins=max(5, min(30, values.size // 2)), color="#1f5fa8")
        z = robust_z(quantities[name])
        bad = [v for v, zz in zip(quantities[name], z, strict=True)
               if v is not None and math.isfinite(zz) and abs(zz) > OUTLIER_Z]
        for v in bad:
            ax.axvline(v, color="#d62728", lw=1.0)
        ax.set_xlabel(labels.get(name, f"relative coefficient {name} [-]"), fontsize=8)
        ax.set_ylabel("units", fontsize=8)
        ax.tick_params(labelsize=7)
    return figure


def _cell(value: Any, digits: int = 5) -> str:
    if value is None:
        return "<td>–</td>"
    if isinstance(value, float):
        return f'<td class="n">{value:.{digits}g}</td>' if math.isfinite(value) else "<td>–</td>"
    if isinstance(value, int):
        return f'<td class="n">{value}</td>'
    return f"<td>{escape(str(value))}</td>"


def _html_table(headers: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    head = "".join(f"<th>{escape(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(_cell(c) for c in row) + "</tr>" for row in rows)
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _distributions(axis: str, done: Sequence[dict[str, Any]]) -> list[str]:
    """The summary table and histograms of one axis's population."""
    quantities = _quantities(done)
    summary = []
    for name, values in quantities.items():
        v = np.array([x for x in values if x is not None], dtype=float)
        if v.size:
            summary.append((name, float(np.median(v)), float(v.mean()),
                            float(v.std(ddof=1)) if v.size > 1 else None,
                            float(v.min()), float(v.max())))
    which = f", axis {axis}" if axis else ""
    uri = svg_data_uri(_histograms(quantities))
    return [f"<h2>Distributions{escape(which)}</h2>",
            _html_table(("quantity", "median", "mean", "std", "min", "max"), summary),
            f'<figure><img alt="distributions{escape(which)}" src="{uri}">'
            f"<figcaption>Distributions over the calibrated units{escape(which)}; red lines "
            f"mark outliers (|robust z| > {OUTLIER_Z}).</figcaption></figure>"]


def build_fleet_report(rows: Sequence[dict[str, Any]], output: str | os.PathLike[str], *,
                       title: str = "Fleet calibration report", force: bool = False) -> Path:
    """Write the fleet report (one self-contained HTML file) from the fleet table's rows
    (a row per unit × axis; each axis's distributions and outliers apart)."""
    target = Path(output)
    refuse_existing(target, force)
    groups = by_axis(rows)
    failed = [r for r in rows if r.get("status") == "failed"]
    units = {r["unit"] for r in rows}
    done = {r["unit"] for group in groups.values() for r in group}
    axes = f" of {len(groups)} axes ({', '.join(groups)})" if len(groups) > 1 else ""
    parts = [f"<h1>{escape(title)}</h1>",
             f'<p class="muted">hrgtc fleet report, {datetime.now(UTC):%Y-%m-%d %H:%M} UTC. '
             f"{len(units)} units{escape(axes)}: {len(done)} calibrated, "
             f'<span class="{"bad" if failed else ""}">'
             f"{len({r['unit'] for r in failed})} failed</span>.</p>"]
    for axis, group in groups.items():
        parts += _distributions(axis, group)
    flagged = outliers(rows)
    parts.append("<h2>Outliers</h2>")
    parts.append(_html_table(("unit", "axis", "quantity", "value", "robust z"),
                             [(f["unit"], f["axis"], f["quantity"], f["value"], f["z"])
                              for f in flagged])
                 if flagged else "<p>None: every unit within "
                 f"|robust z| ≤ {OUTLIER_Z} on its relative coefficients and improvement.</p>")
    parts.append("<h2>Failed units</h2>")
    parts.append(_html_table(("unit", "error", "file", "column", "row", "message"),
                             [(r["unit"], r.get("error_type"), r.get("error_file"),
                               r.get("error_column"), r.get("error_row"),
                               r.get("error_message")) for r in failed])
                 if failed else "<p>None.</p>")
    parts.append("<h2>Units</h2>")
    parts.append(_html_table(
        ("unit", "axis", "status", "f20 [Hz]", "TCF [ppm/°C]", "soaks", "max table error [°C]",
         "terms kept", "raw 10 s [°/h]", "compensated 10 s [°/h]", "improvement [×]"),
        [(r["unit"], r.get("axis"), r["status"], r.get("f20_hz"), r.get("tcf_ppm_per_c"),
          r.get("n_soaks"), r.get("table_max_error_c"), ", ".join(r.get("terms_kept") or []),
          _join(r.get("raw_10s_dph")), _join(r.get("compensated_10s_dph")),
          r.get("median_improvement_10s")) for r in rows]))
    html = (f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>'
            f"{escape(title)}</title><style>{_CSS}</style></head><body>"
            + "".join(parts) + "</body></html>\n")
    return write_text_atomic(target, html, force=force)


def _join(values: Sequence[float | None] | None) -> str:
    return ", ".join("–" if v is None else f"{v:.4g}" for v in values or [])
