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
from hrgtc.export.c.plan import CPlan


def cname(variable: str) -> str:
    """Upper-case stem of a variable's constants (``F``, ``D2``; ``A_drive`` keeps its case)."""
    return f"A_{variable[2:]}" if is_aux(variable) else variable.upper()


def bias_params(plan: CPlan) -> list[tuple[str, str]]:
    """(variable, parameter of ``bias_dph()``) in the order of its signature."""
    out = [("f", "f_hz"), ("df", "df_hz_per_s")]
    if plan.housing:
        out += [("h", "h_c"), ("dh", "dh_c_per_s")]
    if plan.rate2:
        out.append(("d2", "d2_hz_per_s"))
    if plan.gradient:
        out.append(("g", "g_c"))
    return out + [(f"a_{name}", f"a_{name}") for name in plan.aux]


def step_inputs(plan: CPlan) -> list[str]:
    """``step()``'s inputs after freq_hz and rate_dph: housing_c, then each extra channel."""
    return (["housing_c"] if plan.housing_input else []) + [f"aux_{n}" for n in plan.aux]


def levels(plan: CPlan) -> tuple[str, ...]:
    """Variables checked as levels (``in_range``); the rates are :data:`RATES`."""
    return ("f", "h", "g", *(f"a_{n}" for n in plan.aux))


RATES = ("df", "dh", "d2")


def extra_variables(plan: CPlan, settings: Any, _literal: Callable[[float, str], str],
                    _comment: Callable[[Any], str]) -> dict[str, str]:
    """C pieces of the second rate filter (d2), the gradient (g) and the extra channels.

    ``_literal`` and ``_comment`` print a constant and a comment as :mod:`hrgtc.export.c.text` does.
    """
    out = dict.fromkeys(("constants", "functions", "reset", "start", "values", "rate",
                         "gradient", "bias"), "")
    if plan.rate2:  # the same filter (rate_update), its own state and time constant
        out["constants"] += (
            "/* time constant of each stage of the second df/dt filter (d2) [s] */\n"
            f"static const double RATE2_TAU_S = {_literal(plan.tau2_s, 'rate_tau2_s')};\n")
        out["reset"] += "    rate_start(&state->f2_filter, 0.0);\n"
        out["start"] += "        rate_start(&state->f2_filter, f_value);\n"
        out["values"] += "    double d2_value = 0.0;\n"
        out["rate"] += ("        d2_value = rate_update(&state->f2_filter, f_value, dt_s, "
                        "RATE2_TAU_S);\n")
        out["bias"] += ", d2_value"
    if plan.gradient:
        out["values"] += "    double g_value;\n"
        out["gradient"] += "    g_value = housing_c - temperature;  /* NaN beyond the inverse */\n"
        out["bias"] += ", g_value"
    for name in plan.aux:
        centre = _literal(settings.aux_centres.get(name, 0.0), f"aux_centres[{name}]")
        out["constants"] += (f"/* training mean of aux_{name}, the logged column "
                             f"{_comment(settings.aux_columns.get(name, '?'))} */\n"
                             f"static const double AUX_CENTRE_{name} = {centre};\n")
        out["values"] += f"    const double a_{name}_value = aux_{name} - AUX_CENTRE_{name};\n"
        out["bias"] += f", a_{name}_value"
    return out
