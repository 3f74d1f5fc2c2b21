"""Parse a :class:`~hrgtc.core.summary.Summary`'s renderings back and check every figure.

The plain text (``Summary.text()``), the CLI's rich tables (``print_summary``), the HTML
(``Summary.html()``) and a JSON document where a figure's name is a place: each must show
every figure with the same value (a table of cells, ``Summary.grid``, in its row and column).
"""

from __future__ import annotations

import math
import re
from html import unescape
from typing import Any

import pytest


def agrees(figure: Any, cell: str) -> bool:
    """``cell`` shows ``figure``'s value to the digits it is printed with."""
    if isinstance(figure.value, str):
        return cell.startswith(figure.value)
    token = cell.split()[0] if cell.split() else ""
    if isinstance(figure.value, float) and math.isnan(figure.value):
        return token == "-"
    spec = re.fullmatch(r"\+?\.(\d+)([fg%])", figure.spec)
    if spec and spec.group(2) == "f":
        return abs(float(token) - figure.value) <= 0.51 * 10.0 ** -int(spec.group(1))
    if spec and spec.group(2) == "%":
        return abs(float(token.rstrip("%")) / 100 - figure.value) <= 0.51 * 10.0 ** -(
            int(spec.group(1)) + 2)
    digits = int(spec.group(1)) if spec else figure.digits
    return float(token) == pytest.approx(float(figure.value), rel=10.0 ** (1 - digits))


def text_cells(summary: Any) -> dict[tuple[str, str], str]:
    """(section, label) -> what follows ``label: `` in ``summary.text()``."""
    labels = {(h, f.label) for h, figures in summary.sections for f in figures}
    out, heading = {}, ""
    for line in summary.text().splitlines():
        if line.startswith("  ") and ": " in line:
            label, _, rest = line.strip().partition(": ")
            while (heading, label) not in labels and ": " in rest:  # a label with ': '
                more, _, rest = rest.partition(": ")
                label = f"{label}: {more}"
            out[(heading, label)] = rest
        elif line.endswith(":") and not line.startswith(" "):
            heading = line[:-1]
    return out


def rich_tables(text: str) -> dict[str, tuple[list[str], list[list[str]]]]:
    """title -> (header, rows) of the rich tables printed (``width`` wide enough); a title
    is the lines since the table before, joined (rich wraps a title wider than its table)."""
    tables: dict[str, tuple[list[str], list[list[str]]]] = {}
    title, header, rows = "", [], []
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith("┃"):
            header = [c.strip() for c in stripped.split("┃")[1:-1]]
        elif stripped.startswith("│"):
            rows.append([c.strip() for c in stripped.split("│")[1:-1]])
        elif stripped.startswith("└"):
            tables[title] = (header, rows)
            title, header, rows = "", [], []
        elif stripped and stripped[0] not in "┏┡━─":
            title = f"{title} {stripped}" if title else stripped
    return tables


def html_tables(page: str) -> dict[str, tuple[list[str], list[list[str]]]]:
    """heading -> (header, rows) of ``Summary.html()``'s sections."""
    tables: dict[str, tuple[list[str], list[list[str]]]] = {}
    heading = ""
    for row in re.findall(r"<tr>(.*?)</tr>", page, flags=re.S):
        found = re.fullmatch(r'<th colspan="\d+">(.*)</th>', row)
        if found:
            heading = unescape(found.group(1))
            tables[heading] = ([], [])
            continue
        head = re.findall(r"<th>(.*?)</th>", row)
        if head:
            tables[heading] = ([unescape(h) for h in head], [])
        else:
            tables[heading][1].append([unescape(c) for c in re.findall(r"<td>(.*?)</td>", row)])
    return tables


def json_value(document: Any, name: str) -> Any:
    """The value at a figure's name in a JSON document, or KeyError/IndexError/TypeError."""
    node = document
    for token in re.findall(r"[^.\[\]]+|\[\d+\]", name):
        node = node[int(token[1:-1])] if token.startswith("[") else node[token]
    return node


def cell_of(summary: Any, heading: str, figure: Any,
            table: tuple[list[str], list[list[str]]]) -> str:
    """``figure``'s cell in a rendered table of the section ``heading``."""
    header, rows = table
    if summary.is_grid(heading):
        order = list(dict.fromkeys(f.row for f in dict(summary.sections)[heading]))
        return rows[order.index(figure.row)][header.index(figure.header())]
    (row,) = [r for r in rows if r[0] == figure.label]
    return row[1]


def check_renderings(summary: Any, rich_text: str, document: Any) -> int:
    """Every figure of ``summary`` agrees in the text, the rich tables, the HTML and (where
    its name is a place) ``document``; returns how many figures were places of it."""
    text = text_cells(summary)
    printed = rich_tables(rich_text)
    # a table's title, after what was printed before it (the summary's title, a wrap)
    rich = {h: next(table for title, table in printed.items()
                    if title == h or title.endswith(f" {h}"))
            for h, figures in summary.sections if figures}
    html = html_tables(summary.html())
    places = 0
    for heading, figures in summary.sections:
        if summary.is_grid(heading):
            headers, rows = summary.grid(heading)
            assert rich[heading] == (headers, rows), (heading, rich[heading], headers, rows)
            assert html[heading] == (headers, rows), heading
        for figure in figures:
            assert agrees(figure, text[(heading, figure.label)]), (figure, text)
            for table in (rich[heading], html[heading]):
                assert agrees(figure, cell_of(summary, heading, figure, table)), figure
            try:
                value = json_value(document, figure.name)
            except (KeyError, IndexError, TypeError):
                continue
            places += 1
            if isinstance(value, list) and figure.interval_kind == "range":  # a span
                assert value == pytest.approx(list(figure.interval), rel=1e-12), figure
            elif isinstance(value, list) and isinstance(figure.value, str):
                assert figure.value == (", ".join(value) or "(none)"), figure
            elif isinstance(value, str):  # a word or a file
                assert figure.value == value, figure
            elif value is None:
                assert isinstance(figure.value, str) or math.isnan(figure.value), figure
            else:
                assert value == pytest.approx(figure.value, rel=1e-12), figure
    return places
