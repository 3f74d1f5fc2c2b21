"""A result's :class:`~hrgtc.core.summary.Summary` as rich tables, one per section.

The CLI prints every result through its summary, here, and formats nothing itself: a
summary's sections as tables (figure, value, unit, interval: ``Summary.rows()``; a section
of table cells, Table 1, the scale factor's temperature groups or the axes of an
instrument, as that table: ``Summary.grid``), the same cells the plain text and the HTML
report show. A summary with its own text (``Summary.layout``: a model's coefficient table,
a file's description, a fleet run's line) is printed as that text, after a table for each
section the text does not show (a fleet run's failed units). See docs/architecture.md
("One result contract").
"""

from __future__ import annotations

from collections.abc import Collection
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

    from hrgtc.core.summary import Summary

__all__ = ["print_summary", "summary_tables"]

COLUMNS = ("figure", "value", "unit", "interval")


def summary_tables(summary: Summary, headings: Collection[str] | None = None) -> list[Table]:
    """One table per section of ``summary`` (``headings``: of those sections), titled by its
    heading, a row per figure (a section of table cells: its columns and rows,
    :meth:`Summary.grid`)."""
    from rich.table import Table  # rich is imported by a command, not by --help
    from rich.text import Text

    tables = []
    for heading, figures in summary.sections:
        if not figures or (headings is not None and heading not in headings):
            continue
        table = Table(title=Text(heading), title_justify="left")
        if summary.is_grid(heading):
            headers, rows = summary.grid(heading)
            for column in headers:  # Text: "[mHz]" is a unit, not rich markup
                table.add_column(Text(column), justify="right")
        else:
            for column in COLUMNS:
                table.add_column(column, justify="left" if column == "figure" else "right")
            rows = [[f.label, f.number(), f.unit, f.interval_text()] for f in figures]
        for row in rows:
            table.add_row(*(Text(cell) for cell in row))
        tables.append(table)
    return tables


def print_summary(summary: Summary, console: Console, notes: bool = True) -> None:
    """Print the title (if any), each section's table and (``notes``) the notes, without
    markup; a summary with a layout: a table of each section its text does not show, then
    the text (nothing when it is empty)."""
    if summary.layout is not None:
        shown = summary.referenced()
        for table in summary_tables(summary, [h for h, figures in summary.sections
                                              if not any(f.name in shown for f in figures)]):
            console.print(table)
        text = summary.text()
        if text:
            console.print(text, markup=False, highlight=False, emoji=False)
        return
    if summary.title:
        console.print(summary.title, markup=False, highlight=False, emoji=False)
    for table in summary_tables(summary):
        console.print(table)
    for note in summary.notes if notes else ():
        console.print(note, markup=False, emoji=False)
