"""A report's data as HTML: the autoescaped Jinja2 templates of its kind.

Each report kind has its folder of templates, ``templates/<kind>/`` (its page is
``report.html.j2``), beside ``templates/common/`` (the style sheet and the macros of a table,
a figure and a note, which every kind may import). The templates are package data; jinja2 is
imported here, on the first report rendered, never by ``import hrgtc.report`` (the command
line starts without it). Every value is escaped unless a template says otherwise; numbers are
formatted in the templates with the filters below, so the data stays numbers.
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

__all__ = ["macros", "number", "render"]


def number(value: Any, digits: int = 4, fixed: int | None = None) -> str:
    """A number for the page: ``fixed`` decimals or ``digits`` significant; "–" if missing."""
    if value is None or not math.isfinite(float(value)):
        return "–"
    if fixed is not None:
        return f"{float(value):.{fixed}f}"
    return f"{float(value):.{digits}g}"


def pvalue(value: float | None) -> str:
    """A p-value, with underflow shown as a bound ("n/a" when there is none)."""
    if value is None or not math.isfinite(value):
        return "n/a"
    return "< 1e-300" if value == 0 else f"{value:.3g}"


def numeric(cell: Any) -> bool:
    """Whether a table cell reads as a number (right aligned): it starts with a digit, a sign,
    "–" (missing) or "<" (a bound), or is empty."""
    return str(cell)[:1] in "+-–<0123456789"


@cache
def _environment() -> Any:
    import jinja2

    environment = jinja2.Environment(
        loader=jinja2.PackageLoader("hrgtc.report", "templates"),
        autoescape=True, undefined=jinja2.StrictUndefined,
        trim_blocks=True, lstrip_blocks=True, keep_trailing_newline=True)
    environment.filters.update(fmt=format, number=number, pvalue=pvalue)
    environment.tests["numeric"] = numeric
    return environment


def render(template: str, **context: Any) -> str:
    """The template ``template`` (``"<kind>/report.html.j2"``, a path under ``templates/``)
    with ``context``; every value escaped unless the template marks it safe."""
    return _environment().get_template(template).render(**context)


def macros() -> Any:
    """The macros every kind shares (``templates/common/macros.html.j2``: ``table``,
    ``figure``, ``note``) as callables, e.g. ``macros().table(table)``, the HTML of a
    :class:`~hrgtc.report.tables.Table`."""
    return _environment().get_template("common/macros.html.j2").module
