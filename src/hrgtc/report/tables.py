"""The report's own tables as summaries: the model's inputs and the soaks' temperature error.

What the report shows beside a calibration's figures: each input of the model file (its
provenance: role, file, the first 12 hex digits of its SHA-256 and whether the file on disk
still has it) and, for simulated soaks, how far the temperature from frequency is from the
true resonator temperature. Each is a :class:`~hrgtc.core.summary.Summary` of table cells
(:meth:`~hrgtc.core.summary.Summary.grid`), rendered like the other tables; see
docs/architecture.md ("One result contract").

A table as a report shows it is a :class:`Table` (caption, headers, rows of cells as text),
taken from a summary by :func:`grid_table` (a section of cells) or :func:`section_table` (a
section of figures: figure, value, unit, interval); the templates lay it out.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core.files import file_sha256
from hrgtc.core.summary import Figure, Summary

__all__ = ["INPUTS", "SOAK_ERROR", "Table", "grid_table", "provenance_summary", "section_table",
           "soak_error_summary"]

#: Headings of the sections.
INPUTS = "Model inputs (provenance)"
SOAK_ERROR = "Temperature from frequency minus the true resonator temperature (block means)"

#: What :func:`provenance_summary` says of a file on disk now.
MISSING, UNCHANGED, CHANGED = "missing", "unchanged", "CHANGED since calibration"


@dataclass(frozen=True)
class Table:
    """A table of the report: its caption, column headers and rows of cells (text)."""

    caption: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


#: The columns of a section of figures (:func:`section_table`).
FIGURE_COLUMNS = ("figure", "value", "unit", "interval")


def grid_table(summary: Summary, heading: str, caption: str,
               columns: Sequence[str] | None = None) -> Table:
    """A section of table cells of ``summary`` (:meth:`Summary.grid`); a missing number
    shows as "–"."""
    headers, rows = summary.grid(heading, columns)
    return Table(caption, tuple(headers),
                 tuple(tuple("–" if c == "-" else c for c in row) for row in rows))


def section_table(summary: Summary, heading: str, caption: str) -> Table | None:
    """One section of ``summary`` as a table (figure, value, unit, interval); None when the
    summary has no such figures."""
    rows = tuple(tuple(row[1:]) for row in summary.rows() if row[0] == heading)
    return Table(caption, FIGURE_COLUMNS, rows) if rows else None


def provenance_summary(provenance: Mapping[str, Any]) -> Summary:
    """Each input of a model file (``provenance["inputs"][k]``, the figure names' places in
    the model's ``provenance``): its role, file, the first 12 hex digits of its SHA-256 and
    whether the file on disk now is missing, unchanged or changed since the calibration."""
    cells: list[Figure] = []
    for k, item in enumerate(provenance.get("inputs", [])):
        path = Path(str(item.get("path", "")))
        digest = str(item.get("sha256", ""))
        state = MISSING if not path.is_file() else (
            UNCHANGED if file_sha256(path) == digest else CHANGED)
        key = f"inputs[{k}]"
        cells += [_cell(k, f"{key}.role", "role", str(item.get("role", "?"))),
                  _cell(k, f"{key}.path", "file", str(path)),
                  _cell(k, f"{key}.sha256_first12", "SHA-256 (first 12)", digest[:12]),
                  _cell(k, f"{key}.on_disk", "on disk now", state)]
    return Summary("the model's inputs", ((INPUTS, tuple(cells)),) if cells else ())


def soak_error_summary(traces: Sequence[Any]) -> Summary:
    """For each soak with the (simulator's) true resonator temperature: the rms and the
    largest |error| of the temperature from frequency over the soak and over its last hour
    (block means). ``traces``: :class:`~hrgtc.report.figures.SoakTrace` s."""
    cells: list[Figure] = []
    for k, trace in enumerate(t for t in traces if t.resonator_c is not None):
        error = np.asarray(trace.temperature_c - trace.resonator_c, dtype=np.float64)
        last = trace.time_s >= trace.time_s[-1] - 3600.0
        key = f"soaks[{k}]"
        cells += [_cell(k, f"{key}.name", "soak", trace.name),
                  _cell(k, f"{key}.rms_error_c", "rms error",
                        float(np.sqrt(np.nanmean(error**2))), "°C"),
                  _cell(k, f"{key}.max_abs_error_c", "max |error|",
                        float(np.nanmax(np.abs(error))), "°C"),
                  _cell(k, f"{key}.max_abs_error_last_hour_c", "max |error|, last hour",
                        float(np.nanmax(np.abs(error[last]))), "°C")]
    return Summary("the soaks' temperature from frequency against the truth",
                   ((SOAK_ERROR, tuple(cells)),) if cells else ())


def _cell(k: int, name: str, column: str, value: float | str, unit: str = "") -> Figure:
    """Row ``k``'s cell in ``column`` (numbers to 3 significant digits)."""
    return Figure(name, f"row {k + 1}, {column}", value, unit, digits=3, row=str(k),
                  column=column)
