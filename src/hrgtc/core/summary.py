"""A result's summary as data: each figure a value, a unit and an interval.

A result's ``summary()`` builds a :class:`Summary` (sections of :class:`Figure` s) before
any text; the renderers format that one structure: :meth:`Summary.text` (plain text, what
``summary()`` printed before), :meth:`Summary.rows` (the cells of a rich or HTML table:
section, figure, value, unit, interval), :meth:`Summary.grid` (a section whose figures are
the cells of a table, Table 1 or a list of temperature groups: its columns and rows) and
:meth:`Summary.html` (a table for the report). :meth:`Summary.to_dict` is the ``--json``
form. A summary whose text has its own shape (an aligned table, one line) carries a
``layout``: its lines as format strings over the figures' names (``"rms {rms_dph:.4g}"``),
so the text is rendered from the same figures the tables and the JSON show. ``str()`` of a
summary is its text. See docs/architecture.md ("One result contract"), after statsmodels'
``summary()``, which returns tables its renderers format.
"""

from __future__ import annotations

import html
import math
import string
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

__all__ = ["Figure", "Summary", "escape"]


def _number(value: float, digits: int, spec: str = "") -> str:
    if isinstance(value, bool) or not isinstance(value, float | int):
        return str(value)
    if isinstance(value, int) and not spec:
        return str(value)
    if math.isnan(value):
        return "-"
    return f"{value:{spec or f'.{digits}g'}}"


def escape(text: str) -> str:
    """``text`` as a literal of a :attr:`Summary.layout` line (its braces doubled)."""
    return text.replace("{", "{{").replace("}", "}}")


class _ByName(string.Formatter):
    """``{name:spec}`` with the whole field name a figure's name (dots and brackets
    included: ``{validation[0].rms_dph:.4g}``)."""

    def get_field(self, field_name: str, args: Sequence[Any],
                  kwargs: Any) -> tuple[Any, str]:
        return kwargs[field_name], field_name


_BY_NAME = _ByName()


def _renamed(line: str, prefix: str) -> str:
    """A layout line whose figure references are after ``prefix``."""
    out = []
    for literal, name, spec, conversion in _BY_NAME.parse(line):
        out.append(escape(literal))
        if name is not None:
            out.append("{" + prefix + name + (f"!{conversion}" if conversion else "")
                       + (f":{spec}" if spec else "") + "}")
    return "".join(out)


@dataclass(frozen=True)
class Figure:
    """One figure of a result.

    Attributes
    ----------
    name
        Machine key, stable across versions (``"drift.coefficients.f"``).
    label
        What a reader sees (``"k of f"``).
    value
        The number (NaN: not available), or a count or a word.
    unit
        Its unit (``"°/h"``, ``"Hz"``, ``""`` for a pure number).
    interval
        (low, high) around the value, or None.
    interval_kind
        What the interval is: ``"±1σ"`` (value ± one standard error), ``"68.3 % CI"``,
        ``"range"`` (the span of the data), ...
    digits
        Significant digits of the text forms.
    spec
        A format spec of the value's text instead of ``digits`` significant digits
        (``"+.4f"``: the printed decimals of a table, ``".1%"``: a share).
    row, column
        The figure's place in a table (:meth:`Summary.grid`): which row (a key, not shown)
        and which column (its header; the unit is added in brackets). Empty: not a cell.
    definition
        One sentence saying what the figure is (``"1σ of the 10 s means of the compensated
        rate"``); the JSON and the HTML title of its label. Empty: the label says it.
    """

    name: str
    label: str
    value: float | int | str
    unit: str = ""
    interval: tuple[float, float] | None = None
    interval_kind: str = ""
    digits: int = 6
    spec: str = ""
    row: str = ""
    column: str = ""
    definition: str = ""

    @classmethod
    def with_error(cls, name: str, label: str, value: float, error: float, unit: str = "",
                   digits: int = 6, definition: str = "") -> Figure:
        """A value ± one standard error (no interval when the error is not finite)."""
        interval = (value - error, value + error) if math.isfinite(error) else None
        return cls(name, label, value, unit, interval, "±1σ" if interval else "", digits,
                   definition=definition)

    def number(self) -> str:
        """The value as a table shows it (``spec`` or ``digits``; NaN: ``"-"``)."""
        return _number(self.value, self.digits, self.spec)

    def header(self) -> str:
        """The column header of a table cell: ``column [unit]``."""
        return f"{self.column} [{self.unit}]" if self.unit else self.column

    def value_text(self) -> str:
        """The value with its unit (``"3.21 °/h"``)."""
        text = self.number()
        return f"{text} {self.unit}" if self.unit and text != "-" else text

    def interval_text(self) -> str:
        """The interval as ``± e`` for a symmetric ±1σ, else ``[low, high] (kind)``."""
        if self.interval is None:
            return ""
        low, high = self.interval
        if self.interval_kind == "±1σ" and isinstance(self.value, float | int):
            return f"± {_number((high - low) / 2.0, 3)}"
        text = f"[{_number(low, self.digits)}, {_number(high, self.digits)}]"
        return f"{text} ({self.interval_kind})" if self.interval_kind else text

    def text(self) -> str:
        """``label: value unit ± e``."""
        interval = self.interval_text()
        return f"{self.label}: {self.value_text()}" + (f" {interval}" if interval else "")

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (NaN -> None); ``spec``, ``row``, ``column`` and ``definition``
        only when set (a figure that is no table cell keeps the keys it always had)."""
        def clean(v: Any) -> Any:
            return None if isinstance(v, float) and not math.isfinite(v) else v

        out = {"name": self.name, "label": self.label, "value": clean(self.value),
               "unit": self.unit,
               "interval": None if self.interval is None else [clean(v) for v in self.interval],
               "interval_kind": self.interval_kind}
        out.update({key: value for key, value in (("spec", self.spec), ("row", self.row),
                                                  ("column", self.column),
                                                  ("definition", self.definition)) if value})
        return out


@dataclass(frozen=True)
class Summary:
    """A result's figures in titled sections.

    Attributes
    ----------
    title
        What the result is (``"calibration of SN-001"``).
    sections
        (heading, figures) in reading order.
    notes
        Lines the figures cannot say (warnings, why a figure is missing).
    layout
        The lines of :meth:`text`, each a format string over the figures' names
        (``"rms {residual.rms_dph:.4g} °/h"``; a literal brace doubled, :func:`escape`),
        for a result whose text has its own shape; None: the title, then each section's
        figures one per line, then the notes.
    """

    title: str
    sections: tuple[tuple[str, tuple[Figure, ...]], ...] = ()
    notes: tuple[str, ...] = field(default=())
    layout: tuple[str, ...] | None = None

    def __str__(self) -> str:
        return self.text()

    def renamed(self, prefix: str) -> Summary:
        """The same summary with every figure's name (and the layout's references to it)
        after ``prefix`` (``"axes.x."``), to be part of a larger one."""
        sections = tuple((h, tuple(replace(f, name=prefix + f.name) for f in fs))
                         for h, fs in self.sections)
        layout = None if self.layout is None else tuple(_renamed(line, prefix)
                                                        for line in self.layout)
        return Summary(self.title, sections, self.notes, layout)

    def referenced(self) -> set[str]:
        """The names of the figures the layout shows (all of them without a layout)."""
        if self.layout is None:
            return set(self.figures())
        return {name for line in self.layout for _, name, _, _ in _BY_NAME.parse(line)
                if name is not None}

    def lines(self, indent: str = "") -> tuple[str, ...]:
        """The layout's lines (the generic text's, escaped, without one), each after
        ``indent``: the part this summary is of a larger one's layout."""
        lines = self.layout if self.layout is not None else tuple(
            escape(line) for line in self.text().splitlines())
        return tuple(escape(indent) + line for line in lines)

    def figures(self) -> dict[str, Figure]:
        """Every figure by its name."""
        return {f.name: f for _, figures in self.sections for f in figures}

    def __getitem__(self, name: str) -> Figure:
        return self.figures()[name]

    def rows(self) -> list[tuple[str, str, str, str, str]]:
        """Table cells, one row per figure: (section, label, value, unit, interval)."""
        return [(heading, f.label, f.number(), f.unit, f.interval_text())
                for heading, figures in self.sections for f in figures]

    def is_grid(self, heading: str) -> bool:
        """Whether the section ``heading`` is a table of cells (every figure has a column)."""
        figures = dict(self.sections)[heading]
        return bool(figures) and all(f.column for f in figures)

    def grid(self, heading: str, columns: Sequence[str] | None = None,
             ) -> tuple[list[str], list[list[str]]]:
        """The section ``heading`` as a table: its column headers (``column [unit]``, in
        order of appearance) and one list of cells per row (``Figure.row``, in order; a
        cell a row lacks is ``""``). The cells are :meth:`Figure.number` s. ``columns``:
        only these columns (``Figure.column``), in this order."""
        figures = dict(self.sections)[heading]
        if columns is not None:
            figures = tuple(sorted((f for f in figures if f.column in columns),
                                   key=lambda f: list(columns).index(f.column)))
        headers = list(dict.fromkeys(f.header() for f in figures))
        rows: dict[str, list[str]] = {}
        for f in figures:
            rows.setdefault(f.row, [""] * len(headers))[headers.index(f.header())] = f.number()
        return headers, list(rows.values())

    def text(self) -> str:
        """Plain text: the :attr:`layout` rendered with the figures' values, or the title,
        then each section's figures one per line, then the notes."""
        if self.layout is not None:
            values = {f.name: f.value for _, figures in self.sections for f in figures}
            return "\n".join(_BY_NAME.vformat(line, (), values) for line in self.layout)
        lines = [self.title]
        for heading, figures in self.sections:
            lines.append(f"{heading}:")
            lines.extend(f"  {f.text()}" for f in figures)
        lines.extend(self.notes)
        return "\n".join(lines)

    def html(self) -> str:
        """An HTML table (escaped), one row per figure, a header row per section."""
        out = [f"<table class=\"summary\"><caption>{html.escape(self.title)}</caption>"]
        for heading, figures in self.sections:
            if self.is_grid(heading):
                out.append(self._html_grid(heading))
                continue
            out.append(f"<tr><th colspan=\"4\">{html.escape(heading)}</th></tr>")
            for f in figures:
                title = f" title=\"{html.escape(f.definition)}\"" if f.definition else ""
                cells = (f.number(), f.unit, f.interval_text())
                out.append(f"<tr><td{title}>{html.escape(f.label)}</td>"
                           + "".join(f"<td>{html.escape(c)}</td>" for c in cells) + "</tr>")
        out.append("</table>")
        out.extend(f"<p>{html.escape(n)}</p>" for n in self.notes)
        return "\n".join(out)

    def _html_grid(self, heading: str) -> str:
        headers, rows = self.grid(heading)
        return "\n".join([
            f"<tr><th colspan=\"{len(headers)}\">{html.escape(heading)}</th></tr>",
            "<tr>" + "".join(f"<th>{html.escape(h)}</th>" for h in headers) + "</tr>",
            *("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in row) + "</tr>"
              for row in rows)])

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types: title, sections with their figures, notes."""
        return {"title": self.title,
                "sections": [{"heading": h, "figures": [f.to_dict() for f in figures]}
                             for h, figures in self.sections],
                "notes": list(self.notes)}
