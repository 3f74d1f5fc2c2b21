"""The decision rule: limits per figure in ``spec.toml``, judged with guard bands (ILAC-G8).

A spec file names figures of the test report and their limits::

    [limits.bias_repeatability_dph]
    max = 0.5
    [limits.bias_temperature_sensitivity_dph_per_c]
    min = -0.2
    max = 0.2

Each limit is judged with the guard band w = U, the figure's expanded uncertainty
(ILAC-G8:09/2019, "simple acceptance" replaced by guarded acceptance and guarded
rejection):

- an upper limit L: **accept** if value + U⁺ ≤ L, **reject** if value − U⁻ > L,
  otherwise **indeterminate**;
- a lower limit L: **accept** if value − U⁻ ≥ L, **reject** if value + U⁺ < L, otherwise
  **indeterminate**;
- both: reject if either rejects, accept if both accept, otherwise indeterminate.

U⁻ and U⁺ are equal (k·u) but for the Allan figures, whose χ² intervals are not
symmetric. A figure that was not measured is **not measured**, never a fail; a figure
without a limit is **no limit**; a measured figure whose uncertainty is unknown cannot be
guarded and is **indeterminate**. The sums are formed in decimal from the numbers as
they print (their shortest round-trip text), so a value of 0.1 with U = 0.2 against a
limit of 0.3 is at the limit and accepted, as a spreadsheet says.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from hrgtc.core.errors import InputError

__all__ = ["ACCEPT", "INDETERMINATE", "NOT_MEASURED", "NO_LIMIT", "REJECT", "VERDICTS", "Limit",
           "decide", "load_spec"]

ACCEPT, REJECT, INDETERMINATE = "accept", "reject", "indeterminate"
NOT_MEASURED, NO_LIMIT = "not measured", "no limit"
#: Every verdict a figure can get.
VERDICTS = (ACCEPT, REJECT, INDETERMINATE, NOT_MEASURED, NO_LIMIT)


@dataclass(frozen=True)
class Limit:
    """The limits of one figure: a lower, an upper or both (None: no such limit)."""

    min: float | None = None
    max: float | None = None

    def text(self) -> str:
        """``≤ 0.5``, ``≥ -1`` or ``[-0.2, 0.2]``."""
        if self.min is not None and self.max is not None:
            return f"[{self.min:g}, {self.max:g}]"
        return f"≤ {self.max:g}" if self.max is not None else f"≥ {self.min:g}"


def _decimal(value: float) -> Decimal:
    return Decimal(repr(float(value)))


def decide(value: float | None, expanded: tuple[float, float] | None,
           limit: Limit | None) -> str:
    """The verdict of one figure (the module docstring says the rule).

    Parameters
    ----------
    value
        The figure; None: not measured.
    expanded
        (U⁻, U⁺), the expanded uncertainty below and above the value; None: unknown.
    limit
        Its limits; None: no limit.

    Examples
    --------
    >>> decide(0.4, (0.1, 0.1), Limit(max=0.5))
    'accept'
    >>> decide(0.45, (0.1, 0.1), Limit(max=0.5))
    'indeterminate'
    >>> decide(0.65, (0.1, 0.1), Limit(max=0.5))
    'reject'
    >>> decide(None, None, Limit(max=0.5))
    'not measured'
    """
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return NOT_MEASURED
    if limit is None:
        return NO_LIMIT
    if expanded is None or not all(math.isfinite(u) and u >= 0 for u in expanded):
        return INDETERMINATE
    v, below, above = _decimal(value), _decimal(expanded[0]), _decimal(expanded[1])
    verdicts = []
    if limit.max is not None:
        top = _decimal(limit.max)
        verdicts.append(ACCEPT if v + above <= top else REJECT if v - below > top
                        else INDETERMINATE)
    if limit.min is not None:
        bottom = _decimal(limit.min)
        verdicts.append(ACCEPT if v - below >= bottom else REJECT if v + above < bottom
                        else INDETERMINATE)
    if REJECT in verdicts:
        return REJECT
    return ACCEPT if all(v == ACCEPT for v in verdicts) else INDETERMINATE


def load_spec(path: str | Path, known: tuple[str, ...] | None = None) -> dict[str, Limit]:
    """The limits of a ``spec.toml`` by figure name.

    Parameters
    ----------
    path
        The spec file.
    known
        The figure names a limit may name (:data:`hrgtc.testreport.figures.FIGURES`);
        None: any.

    Raises
    ------
    InputError
        Not TOML, no ``[limits]``, an unknown figure, a limit that is not a finite number,
        or min above max.
    """
    where = str(path)
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except OSError as error:
        raise InputError(f"{where}: cannot read the spec ({error.strerror})") from None
    except tomllib.TOMLDecodeError as error:
        raise InputError(f"{where}: not a TOML spec ({error})") from None
    limits = data.get("limits")
    if not isinstance(limits, dict) or not limits:
        raise InputError(f"{where}: no [limits.<figure>] tables; e.g. "
                         "[limits.bias_repeatability_dph] max = 0.5")
    out = {}
    for name, table in limits.items():
        if known is not None and name not in known:
            raise InputError(f"{where}: [limits.{name}]: no such figure; the figures are "
                             f"{', '.join(known)}")
        if not isinstance(table, dict) or not table or set(table) - {"min", "max"}:
            raise InputError(f"{where}: [limits.{name}] takes min and/or max, got {table!r}")
        for key, value in table.items():
            if isinstance(value, bool) or not isinstance(value, int | float) \
                    or not math.isfinite(value):
                raise InputError(f"{where}: [limits.{name}] {key} = {value!r} must be a "
                                 "finite number")
        limit = Limit(table.get("min"), table.get("max"))
        if limit.min is not None and limit.max is not None and limit.min > limit.max:
            raise InputError(f"{where}: [limits.{name}] min {limit.min:g} > max {limit.max:g}")
        out[name] = limit
    return out
