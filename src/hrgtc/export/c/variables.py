"""C text of the drift-model variables beyond f, df, h and dh (issue 12).

:mod:`hrgtc.export.c.text` prints the firmware export; this module gives it the
pieces of the variables added to the term grammar after the paper's:

* ``d2``: the causal df/dt filter with its own time constant (``rate_tau2_s``) and its
  own state in the state struct (``f2_filter``), the same ``rate_update`` as the first
  filter so the rounding is hrgtc's;
* ``g``: ``housing_c`` minus the resonator temperature of the C thermometer inverse
  (``step()`` then takes ``housing_c``);
* ``a_NAME``: one more ``step()`` input ``aux_NAME`` per extra channel, minus its
  training mean.

Levels (f, h, g, a_NAME) are checked against their training ranges for ``in_range``,
rates (df, dh, d2) for ``rate_in_range``, as in :class:`hrgtc.compensate.Compensator`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from hrgtc.drift.features import is_aux
from hrgtc.drift.variables import variable
from hrgtc.export.c.plan import CPlan, variables_for_c
from hrgtc.export.c.types import DOUBLE, CType


def cname(variable: str) -> str:
    """Upper-case stem of a variable's constants (``F``, ``D2``; ``A_drive`` keeps its case)."""
    return f"A_{variable[2:]}" if is_aux(variable) else variable.upper()


def bias_params(plan: CPlan) -> list[tuple[str, str]]:
    """(variable, parameter of ``bias_dph()``) in the order of its signature."""
    out = [("f", "f_hz"), ("df", "df_hz_per_s")]
    if plan.housing:
        out += [("h", "h_c"), ("dh", "dh_c_per_s")]
    for v in variables_for_c(set(plan.computed)):  # d2, g, a_NAME: their modules name them
        code = variable(v).c_code
        out.append((v, v if code is None else code.parameter(v)))
    return out


def step_inputs(plan: CPlan) -> list[str]:
    """``step()``'s inputs after freq_hz and rate_dph: housing_c, then each extra channel."""
    return (["housing_c"] if plan.housing_input else []) + [f"aux_{n}" for n in plan.aux]


def levels(plan: CPlan) -> tuple[str, ...]:
    """Variables checked as levels (``in_range``); the rates are :data:`RATES`."""
    return ("f", "h", "g", *(f"a_{n}" for n in plan.aux))


RATES = ("df", "dh", "d2")


def extra_variables(plan: CPlan, settings: Any, _literal: Callable[[float, str], str],
                    _comment: Callable[[Any], str], ctype: CType = DOUBLE,
                    prefix: str = "hrgtc") -> dict[str, str]:
    """C pieces of the variables beyond f, df, h and dh (d2, g, the extra channels).

    Each variable's module in :mod:`hrgtc.drift.variables` writes its own pieces
    (``c_code``), in grammar order; ``_literal`` and ``_comment`` print a constant and a
    comment as :mod:`hrgtc.export.c.text` does.
    """
    out = dict.fromkeys(SLOTS, "")
    for v in variables_for_c(set(plan.computed)):
        code = variable(v).c_code
        if code is None:  # the extra channels: their C is written here
            continue
        for slot, text in code.pieces(ctype, DOUBLE, v, settings, prefix, _comment).items():
            out[slot] += text
    for name in plan.aux:
        centre = _literal(settings.aux_centres.get(name, 0.0), f"aux_centres[{name}]")
        out["constants"] += (f"/* training mean of aux_{name}, the logged column "
                             f"{_comment(settings.aux_columns.get(name, '?'))} */\n"
                             f"static const double AUX_CENTRE_{name} = {centre};\n")
        out["values"] += f"    const double a_{name}_value = aux_{name} - AUX_CENTRE_{name};\n"
        out["bias"] += f", a_{name}_value"
    return out


#: The slots of a variable's C pieces (:class:`hrgtc.drift.variables.spec.CCode`).
SLOTS = ("constants", "functions", "state", "reset", "start", "values", "rate", "gradient",
         "bias")
