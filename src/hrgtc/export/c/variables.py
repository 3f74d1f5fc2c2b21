"""C text of the drift-model variables beyond f, df, h and dh, gathered from their modules.

:mod:`hrgtc.export.c.source` prints the firmware export's skeleton, in double or float32
(f, df and the housing's h, dh); every other variable writes its own pieces in its module
of :mod:`hrgtc.drift.variables` (its ``c_code``: constants, state, filter steps, ``step()``
inputs, the argument of ``bias_dph()``, its README line), in both precisions, and this
module puts them together in grammar order:

* ``d2``: the causal df/dt filter with its own time constant (``rate_tau2_s``) and its
  own state in the state struct (``f2_filter``), the same ``rate_update`` as the first
  filter so the rounding is hrgtc's;
* ``g``: ``housing_c`` minus the resonator temperature of the C thermometer inverse
  (``step()`` then takes ``housing_c``);
* ``a_NAME``: one more ``step()`` input ``aux_NAME`` per extra channel, minus its
  training mean.

Levels (f, h, g, a_NAME) are checked against their training ranges for ``in_range``,
rates (df, dh, d2) for ``rate_in_range``, as in :class:`hrgtc.compensate.Compensator`
(the kinds the registry gives).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from hrgtc.drift.features import is_aux
from hrgtc.drift.variables import DRIFT_VARIABLES, variable
from hrgtc.export.c.plan import CPlan, variables_for_c
from hrgtc.export.c.types import DOUBLE, CType
from hrgtc.settings.export import ExportSettings


def cname(variable: str) -> str:
    """Upper-case stem of a variable's constants (``F``, ``D2``; ``A_drive`` keeps its case)."""
    return f"A_{variable[2:]}" if is_aux(variable) else variable.upper()


def bias_params(plan: CPlan) -> list[tuple[str, str]]:
    """(variable, parameter of ``bias_dph()``) in the order of its signature."""
    out = [("f", "f_hz"), ("df", "df_hz_per_s")]
    if plan.housing:
        out += [("h", "h_c"), ("dh", "dh_c_per_s")]
    for v in variables_for_c(set(plan.computed)):  # d2, g, a_NAME: their modules name them
        out.append((v, variable(v).c_code.parameter(v)))
    return out


def step_inputs(plan: CPlan) -> list[str]:
    """``step()``'s inputs after freq_hz and rate_dph: housing_c, then each extra channel."""
    out = ["housing_c"] if plan.housing_input else []
    for v in variables_for_c(set(plan.computed)):  # each variable's module names its inputs
        out += [i for i in variable(v).c_code.inputs(v) if i not in out]
    return out


def readme_lines(plan: CPlan, settings: Any) -> list[str]:
    """THE MODEL's lines of the variables beyond f, df, h and dh, from their modules."""
    return [variable(v).c_code.readme(v, settings) for v in variables_for_c(set(plan.computed))]


def levels(plan: CPlan) -> tuple[str, ...]:
    """Variables checked as levels (``in_range``); the rates are :data:`RATES`."""
    return tuple(v for v in plan.computed if variable(v).kind == "level")


#: The rates (checked for ``rate_in_range``), as the registry's kinds say.
RATES = tuple(v.name for v in DRIFT_VARIABLES if v.kind == "rate")


def extra_variables(plan: CPlan, settings: Any, _literal: Callable[[float, str], str],
                    _comment: Callable[[Any], str], ctype: CType = DOUBLE,
                    prefix: str = ExportSettings.prefix) -> dict[str, str]:
    """C pieces of the variables beyond f, df, h and dh (d2, g, the extra channels).

    Each variable's module in :mod:`hrgtc.drift.variables` writes its own pieces
    (``c_code``), in grammar order; ``_literal`` and ``_comment`` print a constant and a
    comment in the export's type, as :mod:`hrgtc.export.c.source` does.
    """
    out = dict.fromkeys(SLOTS, "")
    for v in variables_for_c(set(plan.computed)):
        code = variable(v).c_code
        for slot, text in code.pieces(ctype, DOUBLE, v, settings, prefix, _comment).items():
            out[slot] += text
    return out


#: The slots of a variable's C pieces (:class:`hrgtc.drift.variables.spec.CCode`).
SLOTS = ("constants", "functions", "state", "reset", "start", "values", "rate", "gradient",
         "bias")
