"""C text of ``<prefix>_model.c``, the double and the float32 builds: one body, two types.

The body is written once and printed in the export's C type (:mod:`hrgtc.export.c.types`:
every declaration, literal and ``math.h`` call): the frequency change and the causal df/dt
filter, the drift model of Eq. (22) of [1], the scale factor, the thermometer's inverse
and ``step()``. What the float32 build does differently is what float32 needs, and only
that: the frequency enters centred on the model's f_ref (``f_hz``, the thermometer
written about the same centre, :mod:`hrgtc.export.c.float32`), and the df/dt filter takes
its time constant in float beside the double of its weights (its differences and
compensated sums are :mod:`hrgtc.export.c.rate_filter`'s). Products and sums are separate
statements, so a compiler that contracts ``a*b + c`` within an expression (C99
``FP_CONTRACT``) cannot fuse them and the rounding stays that of NumPy (double) or of the
float mirror (float32).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from hrgtc.export.c.expr import array, comment, term_expression
from hrgtc.export.c.header import sensor_words
from hrgtc.export.c.plan import TABLE_POINTS, CPlan
from hrgtc.export.c.rate_filter import filter_functions
from hrgtc.export.c.scale import scale_pieces
from hrgtc.export.c.step import step_tail
from hrgtc.export.c.thermometer import NEWTON_MAX_ITER, thermometer_functions
from hrgtc.export.c.types import DOUBLE, SINGLE, CType, ctype
from hrgtc.export.c.variables import RATES, bias_params, cname, extra_variables, levels, step_inputs
from hrgtc.model import Model

__all__ = ["BodyNumbers", "PlanNumbers", "bias_function", "source"]


class BodyNumbers(Protocol):
    """The numbers the body prints beyond the drift model's: the double plan's
    (:class:`PlanNumbers`) or the float32 build's, centred on f_ref
    (:class:`hrgtc.export.c.float32.FloatConstants`)."""

    reference_c: Any  #: origin of the housing variable h [°C]
    tau_s: Any  #: the df/dt filter's time constant [s]
    th_centre_c: Any  #: z = (T - th_centre_c) / th_scale_c [°C]
    th_scale_c: Any
    th_coefficients: Any  #: f(T), ascending in z (less the centre in float32) [Hz]
    th_derivative: Any  #: df/dz, ascending
    table_f: Any  #: the inverse's start table, ascending in f [Hz]
    table_t: Any  #: [°C]
    f_low: Any  #: calibrated frequency range [Hz]
    f_high: Any
    tolerance: Any  #: Newton tolerance of the inverse [°C]


@dataclass(frozen=True, eq=False)
class PlanNumbers:
    """:class:`BodyNumbers` of the double build: the plan's, the frequency not centred."""

    reference_c: float
    tau_s: float
    th_centre_c: float
    th_scale_c: float
    th_coefficients: Any
    th_derivative: Any
    table_f: Any
    table_t: Any
    f_low: float
    f_high: float
    tolerance: float

    @classmethod
    def of(cls, model: Model, plan: CPlan) -> PlanNumbers:
        th = model.thermometer
        return cls(model.drift.settings.reference_c, plan.tau_s, th.centre_c, th.scale_c,
                   plan.th_coefficients, plan.th_derivative, plan.grid_f, plan.grid_t,
                   plan.f_range[0], plan.f_range[1], plan.tolerance)


def bias_function(model: Model, plan: CPlan, prefix: str) -> str:
    """``<prefix>_bias_dph()`` and its constants: Eq. (22) of [1] on the scaled variables,
    each held at the edge of its training range and continued along the tangent there (as
    ``DriftModel.predict(extrapolation="tangent")``), in the plan's C type."""
    drift = model.drift
    names = dict(bias_params(plan))
    params = list(names.values())
    used = [v for v in names if v in drift.variables and drift.selected]
    body = []
    t = ctype(plan)  # the C type: every declaration, literal and math call below
    real, lit, zero = t.name, t.literal, t.literal(0.0, "zero")
    for v in names:
        if v not in used:
            body.append(f"    (void){names[v]};")
    for v in used:
        u = cname(v)
        body.append(f"    const {real} c_{v} = {names[v]} < CLAMP_{u}_LOW ? CLAMP_{u}_LOW : "
                    f"({names[v]} > CLAMP_{u}_HIGH ? CLAMP_{u}_HIGH : {names[v]});")
        body.append(f"    const {real} x_{v} = c_{v} / SCALE_{u};")
    body.append(f"    {real} sum = {zero};")
    body.append(f"    {real} term;")
    for k, term in enumerate(drift.terms):
        body.append(f"    term = {term_expression(term, t)};  /* {term.name} */")
        body.append(f"    term = COEFFICIENTS[{k}] * term;")
        body.append("    sum = sum + term;")
    for v in used:
        u = cname(v)
        body.append(f"    if ({names[v]} < CLAMP_{u}_LOW || {names[v]} > CLAMP_{u}_HIGH) {{"
                    f"  /* beyond the training range of {v} */")
        body.append(f"        {real} gradient = {zero};")
        for k, term in enumerate(drift.terms):
            multiplier, rest = term.derivative(v)
            if not multiplier:
                continue
            factor = f"COEFFICIENTS[{k}] * {lit(multiplier, 'multiplier')} / SCALE_{u}"
            expression = factor if rest is None else f"{factor} * {term_expression(rest, t)}"
            body.append(f"        gradient = gradient + {expression};  /* d({term.name})/d{v} */")
        body.append(f"        sum = sum + gradient * ({names[v]} - c_{v});")
        body.append("    }")
    body.append("    return INTERCEPT_DPH + sum;")
    if not drift.terms:
        body = [line for line in body if "term" not in line]
    signature = ", ".join(f"{real} {name}" for name in params)
    constants = [f"static const {real} INTERCEPT_DPH = "
                 f"{lit(drift.intercept_dph, 'intercept_dph')};"]
    for v in used:
        u = cname(v)
        constants.append(f"static const {real} SCALE_{u} = "
                         f"{lit(drift.settings.scales[v], f'scales[{v}]')};")
        low, high = drift.ranges[v]
        constants.append(f"static const {real} CLAMP_{u}_LOW = "
                         f"{lit(low, f'ranges[{v}][0]')};")
        constants.append(f"static const {real} CLAMP_{u}_HIGH = "
                         f"{lit(high, f'ranges[{v}][1]')};")
    if drift.terms:
        listed = ", ".join(drift.selected)
        constants.append(f"/* Coefficients on scaled variables, in this order: {listed} */")
        constants.append(f"static const {real} COEFFICIENTS[{len(drift.terms)}] = "
                         f"{array(drift.scaled_coefficients, 'scaled_coefficients', t)};")
    return "\n".join(constants) + f"""

{real} {prefix}_bias_dph({signature})
{{
""" + "\n".join(body) + "\n}\n"


def _housing(plan: CPlan, t: CType, reference_c: float, tau: str) -> dict[str, str]:
    """The housing thermistor's pieces (h, dh), empty when the terms use neither;
    ``arg``: the inputs of ``step()`` beyond freq_hz and rate_dph."""
    real, zero = t.name, t.literal(0.0, "zero")
    h = {
        "constants": f"static const {real} REFERENCE_C = "
                     f"{t.literal(reference_c, 'reference_c')};\n",
        "start": "        rate_start(&state->h_filter, h_value);\n",
        "values": f"    const {real} h_value = housing_c - REFERENCE_C;\n"
                  f"    {real} dh_value = {zero};\n",
        "rate": f"        dh_value = rate_update(&state->h_filter, h_value, dt_s, {tau});\n",
        "out": "        out->h_c = h_value;\n        out->dh_c_per_s = dh_value;\n",
        "bias": ", h_value, dh_value",
        "reset": f"    rate_start(&state->h_filter, {zero});\n",
    }
    if not plan.housing:
        h = dict.fromkeys(h, "")
    h["arg"] = "".join(f", {real} {name}" for name in step_inputs(plan))
    return h


def source(model: Model, plan: CPlan, prefix: str,
           numbers: BodyNumbers | None = None) -> str:
    """Text of ``<prefix>_model.c`` in the plan's precision: filter, drift model,
    thermometer inverse, ``step()``.

    ``numbers``: the float32 build's constants (centred on f_ref,
    :func:`hrgtc.export.c.float32.float_constants`); the double build's are the plan's.
    """
    t = ctype(plan)
    single = t is SINGLE
    if numbers is None:
        if single:
            raise ValueError("the float32 body prints the float constants: pass numbers")
        numbers = PlanNumbers.of(model, plan)
    p, up = prefix, prefix.upper()
    real, lit, zero = t.name, t.literal, t.literal(0.0, "zero")
    drift, settings, n = model.drift, model.drift.settings, numbers
    ranges = [(v, cname(v), lit(drift.ranges[v][0], f"ranges[{v}][0]"),
               lit(drift.ranges[v][1], f"ranges[{v}][1]"))
              for v in plan.computed if v in drift.ranges]

    def checks(kind: tuple[str, ...]) -> str:
        return "".join(f"\n        && {v}_value >= RANGE_{u}_LOW && {v}_value <= RANGE_{u}_HIGH"
                       for v, u, _, _ in ranges if v in kind)

    range_constants = "".join(f"static const {real} RANGE_{u}_LOW = {low};\n"
                              f"static const {real} RANGE_{u}_HIGH = {high};\n"
                              for _, u, low, high in ranges)
    # the float filter takes tau in double (its weights) and in float (the rate)
    tau = "RATE_TAU_S, RATE_TAU" if single else "RATE_TAU_S"
    h = _housing(plan, t, n.reference_c, tau)
    extra = extra_variables(plan, settings, lit, comment, ctype=t, prefix=p)
    k = scale_pieces(model, plan, prefix)
    # the frequency input: freq_hz in double; in float32 f_hz = freq_hz - CENTRE_HZ,
    # centred by the caller where it is still exact
    frequency = "f_hz" if single else "freq_hz"
    f_value = "f_hz" if single else "freq_hz - REFERENCE_FREQ_HZ"
    temperature_of = "f_value" if single else "freq_hz"
    thermometer_text = thermometer_functions(
        p=p, n_th=len(n.th_coefficients), above=f"residual > {zero}" if plan.increasing
        else f"!(residual > {zero})", real=real, fabs=t.call("fabs"), half=lit(0.5, "half"),
        fn=f"{p}_centred_frequency_hz" if single else f"{p}_frequency_hz", arg=frequency)
    level_test = f"{p}_frequency_in_range({temperature_of})" + checks(levels(plan))
    tail = step_tail(up=up, level_test=level_test, rate_test="1" + checks(RATES), h=h, k=k)
    n_th = len(n.th_coefficients)
    if single:
        generated = "export-c --precision single"
        sees = "its accuracy, its provenance and its use"
        filter_title = "the causal df/dt filter (hrgtc.drift.rate_filter), kept as differences"
        reference = ""
        tau_text = ("/* time constant of each df/dt stage, in double (the weights) and float "
                    f"[s] */\nstatic const double RATE_TAU_S = "
                    f"{DOUBLE.literal(n.tau_s, 'rate_tau_s')};\n"
                    f"static const float RATE_TAU = {lit(n.tau_s, 'tau')};\n")
        th_title = f"the thermometer, Eq. (18) of [1], centred on {up}_CENTRE_HZ"
        f_of_t, f_range = "f(T) - CENTRE_HZ", "calibrated range of f_hz [Hz]"
        table = "f(T) - CENTRE_HZ over the monotonic extension, ascending: starts Newton"
        step_break = ",\n"
    else:
        generated = "export-c"
        sees = "its provenance and its use"
        filter_title = "frequency change and the causal df/dt filter (hrgtc.drift.rate_filter)"
        reference = ("static const double REFERENCE_FREQ_HZ = "
                     f"{lit(settings.reference_freq_hz, 'reference_freq_hz')};\n")
        tau_text = ("/* time constant of each stage of the df/dt filter [s] */\n"
                    f"static const double RATE_TAU_S = {lit(n.tau_s, 'rate_tau_s')};\n")
        th_title = "the thermometer, Eq. (18) of [1] (hrgtc.thermometry.Thermometer)"
        f_of_t, f_range = "f(T)", "calibrated frequency range [Hz]"
        table = "f(T) over the monotonic extension, ascending in f: starts the Newton iteration"
        step_break = ", "
    text = f"""/* {p}_model.c -- generated by hrgtc {generated} for unit {comment(model.unit)};
 * see {p}_model.h for what it computes, {sees}. Do not edit.
 * Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
 */
#include "{p}_model.h"

#include <math.h>

/* ---- {filter_title} ---- */
{reference}{h['constants']}{extra['constants']}{tau_text}
{filter_functions(p, single)}{extra['functions']}
/* ---- the drift model, Eq. (22) of [1] (hrgtc.drift.DriftModel.predict) ---- */
{bias_function(model, plan, p)}{k['function']}
/* ---- {th_title} ---- */
static const {real} TH_CENTRE_C = {lit(n.th_centre_c, 'centre_c')};
static const {real} TH_SCALE_C = {lit(n.th_scale_c, 'scale_c')};
/* {f_of_t} = sum_k TH_COEFFICIENTS[k] z^k, z = (T - TH_CENTRE_C) / TH_SCALE_C [Hz] */
static const {real} TH_COEFFICIENTS[{n_th}] = \
{array(n.th_coefficients, 'scaled_coefficients', t)};
/* d f / d z, ascending */
static const {real} TH_DERIVATIVE[{n_th - 1}] = {array(n.th_derivative, 'derivative', t)};
/* {f_range} */
static const {real} TH_F_LOW_HZ = {lit(n.f_low, 'f_low')};
static const {real} TH_F_HIGH_HZ = {lit(n.f_high, 'f_high')};
/* table of {table} */
#define TH_TABLE_POINTS {TABLE_POINTS}
static const {real} TH_TABLE_F[TH_TABLE_POINTS] = {array(n.table_f, 'table_f', t)};
static const {real} TH_TABLE_T[TH_TABLE_POINTS] = {array(n.table_t, 'table_t', t)};
static const {real} TH_TOLERANCE_C = {lit(n.tolerance, 'tolerance')};
#define TH_MAX_ITER {NEWTON_MAX_ITER}

{thermometer_text}/* ---- streaming compensation (hrgtc.compensate.Compensator) ---- */
/* training ranges of the drift model's variables (as the model file stores them) */
{range_constants}
void {p}_reset({p}_state *state)
{{
    rate_start(&state->f_filter, {zero});
{h['reset']}{extra['reset']}    state->started = 0;
    state->samples = 0UL;
    state->elapsed_s = {zero};
    state->out_of_range = 0UL;
    state->rate_out_of_range = 0UL;
}}

void {p}_init({p}_state *state)
{{
    {p}_reset(state);
}}

{real} {p}_step({p}_state *state, {real} dt_s, {real} {frequency}, {real} rate_dph{h['arg']}\
{step_break}{p}_output *out)
{{
    const {real} f_value = {f_value};
{h['values']}{extra['values']}    {real} df_value = {zero}, bias, compensated, temperature;
    int in_range, rate_in_range, level_in_range, settled;
{k['declare']}    if (!state->started) {{  /* the filters start at rest on the first sample */
        rate_start(&state->f_filter, f_value);
{h['start']}{extra['start']}        state->started = 1;
    }} else {{  /* each filter steps over this sample's dt_s */
        df_value = rate_update(&state->f_filter, f_value, dt_s, {tau});
{h['rate']}{extra['rate']}    }}
    temperature = {p}_temperature_c({temperature_of});
{extra['gradient']}    bias = {p}_bias_dph(f_value, df_value{h['bias']}{extra['bias']});
{tail}"""
    return sensor_words(model, text)
