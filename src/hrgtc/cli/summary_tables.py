"""A result's :class:`~hrgtc.core.summary.Summary` as rich tables, one per section.

The CLI's renderers print a result through its summary (figure, value, unit, interval:
``Summary.rows()``; a section of table cells, Table 1 or the scale factor's temperature
groups, as that table: ``Summary.grid``), the same cells the plain text and the HTML report
show; see
docs/architecture.md ("One result contract").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

    from hrgtc.core.summary import Summary

__all__ = ["print_summary", "summary_tables"]

COLUMNS = ("figure", "value", "unit", "interval")


def summary_tables(summary: Summary) -> list[Table]:
    """One table per section of ``summary``, titled by its heading, a row per figure (a
    section of table cells: its columns and rows, :meth:`Summary.grid`)."""
    from rich.table import Table  # rich is imported by a command, not by --help
    from rich.text import Text

    tables = []
    for heading, figures in summary.sections:
        if not figures:
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
    """Print the title, each section's table and (``notes``) the notes, without markup."""
    console.print(summary.title, markup=False, highlight=False)
    for table in summary_tables(summary):
        console.print(table)
    for note in summary.notes if notes else ():
        console.print(note, markup=False)
