"""A result's :class:`~hrgtc.core.summary.Summary` as rich tables, one per section.

The CLI's renderers print a result through its summary (figure, value, unit, interval:
``Summary.rows()``), the same cells the plain text and the HTML report show; see
docs/architecture.md ("One result contract").
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from rich.table import Table

if TYPE_CHECKING:
    from rich.console import Console

    from hrgtc.core.summary import Summary

__all__ = ["print_summary", "summary_tables"]

COLUMNS = ("figure", "value", "unit", "interval")


def summary_tables(summary: Summary) -> list[Table]:
    """One table per section of ``summary``, titled by its heading, a row per figure."""
    tables: dict[str, Table] = {}
    for heading, label, value, unit, interval in summary.rows():
        table = tables.get(heading)
        if table is None:
            table = tables[heading] = Table(title=heading, title_justify="left")
            for column in COLUMNS:
                table.add_column(column, justify="left" if column == "figure" else "right")
        table.add_row(label, value, unit, interval)
    return list(tables.values())


def print_summary(summary: Summary, console: Console, notes: bool = True) -> None:
    """Print the title, each section's table and (``notes``) the notes, without markup."""
    console.print(summary.title, markup=False, highlight=False)
    for table in summary_tables(summary):
        console.print(table)
    for note in summary.notes if notes else ():
        console.print(note, markup=False)
