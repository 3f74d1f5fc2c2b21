"""C expressions shared by the export's text modules: array initialisers, drift terms and
comment text.

:mod:`hrgtc.export.c.text` (the header), :mod:`hrgtc.export.c.source` (the ``.c``
file) and :mod:`hrgtc.export.c.scale` (the scale-factor pieces that ``source`` inserts)
print these; they live here so that ``scale`` does not import ``source`` back (no import
circle).
"""

from __future__ import annotations

import re
from typing import Any

from hrgtc.drift.features import Term
from hrgtc.export.c.types import DOUBLE, CType

__all__ = ["array", "comment", "factor", "term_expression"]


def comment(text: Any) -> str:
    """Text safe inside a C block comment: ASCII only, no ``*/``, one line."""
    ascii_text = str(text).encode("ascii", "backslashreplace").decode("ascii")
    ascii_text = re.sub(r"[\x00-\x1f\x7f]", " ", ascii_text)
    return ascii_text.replace("*/", "* /").replace("/*", "/ *")


def array(values: Any, name: str, t: CType = DOUBLE) -> str:
    """A C array initialiser ``{...}`` of ``values``, three literals a line."""
    items = [t.literal(v, f"{name}[{k}]") for k, v in enumerate(values)]
    lines = ["    " + ", ".join(items[k : k + 3]) + "," for k in range(0, len(items), 3)]
    return "{\n" + "\n".join(lines) + "\n}"


def factor(variable: str, power: int, t: CType = DOUBLE) -> str:
    """C expression of ``x_variable ** power``, rounded as NumPy rounds it."""
    x = f"x_{variable}"
    if power == 1:
        return x
    if power == 2:
        return f"({x} * {x})"  # numpy squares by multiplication
    # numpy calls the C library's pow for other powers
    return f"{t.call('pow')}({x}, {t.literal(power, 'power')})"


def term_expression(term: Term, t: CType = DOUBLE) -> str:
    """C expression of a drift term, the product of its factors."""
    return " * ".join(factor(v, p, t) for v, p in term.powers)
