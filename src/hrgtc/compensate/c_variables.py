"""C text of the drift-model variables beyond f, df, h and dh (issue 12).

:mod:`hrgtc.compensate.c_text` prints the firmware export; this module gives it the
pieces of the variables added to the term grammar after the paper's:

* ``d2``: the causal df/dt filter with its own time constant (``rate_tau2_s``) and its
  own state in the state struct (``f2_y1``, ``f2_y2``), the same separate statements as
  the first filter so the rounding is NumPy's;
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

from hrgtc.compensate.c_plan import CPlan
from hrgtc.drift.features import is_aux


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

    ``_literal`` and ``_comment`` print a constant and a comment as :mod:`c_text` does.
    """
    out = dict.fromkeys(("constants", "functions", "reset", "start", "values", "rate", "bias"),
                        "")
    if plan.rate2:
        out["constants"] += (
            f"static const double RATE2_ALPHA = {_literal(plan.alpha2, 'alpha2')};\n"
            f"static const double RATE2_BETA = {_literal(plan.beta2, 'beta2')};\n"
            f"static const double RATE2_GAIN = {_literal(plan.gain2, 'gain2')};\n")
        out["functions"] = """
/* The second df/dt filter (variable d2, time constant rate_tau2_s): rate_update's steps. */
static double rate2_update(double *y1, double *y2, double x)
{
    double a = RATE2_ALPHA * x;
    double b = RATE2_BETA * *y1;
    *y1 = a + b;
    a = RATE2_ALPHA * *y1;
    b = RATE2_BETA * *y2;
    *y2 = a + b;
    a = *y1 - *y2;
    return a * RATE2_GAIN;
}
"""
        out["reset"] += "    state->f2_y1 = 0.0;\n    state->f2_y2 = 0.0;\n"
        out["start"] += "        state->f2_y1 = f_value;\n        state->f2_y2 = f_value;\n"
        out["values"] += "    double d2_value;\n"
        out["rate"] += "    d2_value = rate2_update(&state->f2_y1, &state->f2_y2, f_value);\n"
        out["bias"] += ", d2_value"
    if plan.gradient:
        out["values"] += "    double g_value;\n"
        out["rate"] += "    g_value = housing_c - temperature;  /* NaN beyond the inverse */\n"
        out["bias"] += ", g_value"
    for name in plan.aux:
        centre = _literal(settings.aux_centres.get(name, 0.0), f"aux_centres[{name}]")
        out["constants"] += (f"/* training mean of aux_{name}, the logged column "
                             f"{_comment(settings.aux_columns.get(name, '?'))} */\n"
                             f"static const double AUX_CENTRE_{name} = {centre};\n")
        out["values"] += f"    const double a_{name}_value = aux_{name} - AUX_CENTRE_{name};\n"
        out["bias"] += f", a_{name}_value"
    return out
