"""C text of the firmware export: the README block, the header and the source.

The header is the template both builds share (:mod:`hrgtc.export.c.header`).

:mod:`hrgtc.export.export_c` decides what to export (the validated numbers of a
:class:`~hrgtc.model.UnitModel`); this module prints them as C99. Constants are
printed with ``%.17g`` so they read back to the same double. Products and sums are
separate statements, so a compiler that contracts ``a*b + c`` within an expression
(C99 ``FP_CONTRACT``) cannot fuse them and the rounding stays that of NumPy.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

from hrgtc.export.c.expr import array as _array
from hrgtc.export.c.expr import comment as _comment
from hrgtc.export.c.expr import term_expression as _term_expression
from hrgtc.export.c.header import header as template
from hrgtc.export.c.header import sensor_words
from hrgtc.export.c.plan import TABLE_POINTS, CPlan
from hrgtc.export.c.rate_filter import filter_functions
from hrgtc.export.c.step import step_tail
from hrgtc.export.c.thermometer import thermometer_functions
from hrgtc.export.c.types import DOUBLE, ctype
from hrgtc.export.c.variables import (
    RATES,
    bias_params,
    cname,
    extra_variables,
    levels,
    readme_lines,
    step_inputs,
)
from hrgtc.model import UnitModel

#: Iteration cap of the thermometer inverse (as :meth:`Thermometer.temperature`).
NEWTON_MAX_ITER = 60
_WIDTH = 92


def _literal(value: float, name: str) -> str:
    """``%.17g`` text of a finite double as a C double literal (reads back exactly)."""
    return DOUBLE.literal(value, name)


def sensor_note(model: UnitModel) -> list[str]:
    """Lines that say, for a model whose thermometer is the gyro's temperature sensor
    (``calibrate --thermometer sensor``), that every "Hz" of the export means °C.

    The export's text names f and df/dt in Hz and Hz/s throughout; with a sensor
    thermometer the input called freq_hz is a temperature. Empty for a resonator.
    """
    if model.thermometer.source != "sensor":
        return []
    return [
        "THERMOMETER: THE GYRO'S TEMPERATURE SENSOR (calibrate --thermometer sensor)",
        "  This unit has no frequency output. The input named freq_hz is the temperature",
        "  sensor's reading [degC], not a frequency: wherever this file says Hz or Hz/s",
        "  for freq_hz, f, df/dt, f_ref or their ranges, read degC and degC/s. The",
        "  thermometer is the identity, so resonator_c_est is that reading.",
        "",
    ]


def title(model: UnitModel) -> str:
    """What an export compensates, for its first line: an HRG's drift (a resonator
    thermometer), or a gyro's by its temperature sensor (``--thermometer sensor``)."""
    if model.thermometer.source == "sensor":
        return "gyro temperature-drift compensation (temperature sensor)"
    return "HRG temperature-drift compensation"


def offsets_note(model: UnitModel) -> list[str]:
    """Lines that say the export applies none of the model's per-run or per-orientation
    offsets (``calibrate --offsets``): its intercept is their mean over the training
    samples. Empty when the model has none."""
    drift = model.drift
    if not drift.offsets_dph:
        return []
    kind = drift.offset_mode  # "run" or "orientation"
    lines = [f"OFFSETS NOT APPLIED HERE (calibrate --offsets {kind})",
             f"  The fit gave each {kind} a constant offset (a nuisance parameter, from the",
             "  intercept), which this file does not apply: its intercept is their mean over",
             f"  the training samples, so a unit in one {kind} reads its offset in",
             f"  rate_comp_dph; add it in the firmware if the unit knows its {kind} [deg/h]:"]
    directions = list(drift.orientations or ())
    for name, value in drift.offsets_dph.items():
        where = ""
        index = name.removeprefix("orientation ")
        if index != name and index.isdigit() and int(index) < len(directions):
            where = (" (gravity along "
                     + ", ".join(f"{c:+.3f}" for c in directions[int(index)]) + ")")
        lines.append(f"    {name}: {value:+.6g}{where}")
    return [*lines, ""]


def readme(model: UnitModel, plan: CPlan, prefix: str, origin: str,
            sha256: str, sections: list[str] | None = None) -> str:
    """The README comment block at the top of the header: what, provenance, Eq. (22), units, use.

    ``sections`` replace the UNITS and USAGE sections (the float32 build writes its own).
    """
    from hrgtc.core.meta import PAPER_CITATION, PAPER_REFERENCE, __version__
    from hrgtc.export.c.scale import scale_pieces

    drift, thermometer, settings = model.drift, model.thermometer, model.drift.settings
    p, up = prefix, prefix.upper()
    prov = model.provenance
    sensor = thermometer.source == "sensor"
    lines = [
        f"{p}_model.h -- {title(model)} of unit {model.unit!r}",
        "",
        "WHAT THIS IS",
        "  Generated by hrgtc (hrgtc export-c); do not edit, regenerate from the model file.",
        "  A dependency-free C99 implementation (math.h only; no malloc, I/O or mutable "
        "globals) of the compensation hrgtc calibrated for this unit, sample by sample: the "
        + ("sensor temperature's change f" if sensor else "frequency change f")
        + ", its causal rate df/dt, the bias model"
        + ("" if sensor else " of Eq. (22) of [1]") + ", the compensated rate, "
        + ("the sensor temperature (resonator_c_est, the sensor's reading itself)" if sensor
           else "the resonator temperature from the frequency (inverse of Eq. (18), Table 2)")
        + " and an in-range flag, as hrgtc.compensate.Compensator computes them.",
        "",
        "PROVENANCE",
        f"  unit:            {model.unit}",
        f"  model:           {origin}",
        f"  model SHA-256:   {sha256}",
        f"  calibrated with: hrgtc {prov.get('hrgtc_version', 'unknown')}, "
        f"{prov.get('created_utc', 'time unknown')}",
        f"  exported by:     hrgtc {__version__}",
    ]
    for item in list(prov.get("inputs", []))[:12]:
        lines.append(f"  input ({item.get('role', '?')}): {Path(str(item.get('path', '?'))).name}"
                     f" sha256 {item.get('sha256', '?')}")
    terms = "".join(
        f" {'-' if drift.coefficients[n] < 0 else '+'} {abs(drift.coefficients[n]):.10g}*{n}"
        for n in drift.selected
    )
    f_low, f_high = plan.f_range
    th = " ".join(
        f"{c:+.10g}" + ("" if k == 0 else ("*T" if k == 1 else f"*T^{k}"))
        for k, c in reversed(list(enumerate(thermometer.coefficients)))
    )
    def ranges(kind: tuple[str, ...]) -> str:
        return ", ".join(f"{v} in [{drift.ranges[v][0]:.6g}, {drift.ranges[v][1]:.6g}]"
                         for v in plan.computed if v in drift.ranges and v in kind) or "none"

    housing_arg = "".join(f"double {name}, " for name in step_inputs(plan))
    housing_use = "".join(f"{name}, " for name in step_inputs(plan))
    lines += ["", *sensor_note(model), *offsets_note(model)]
    lines += [
        "THE MODEL (" + ("" if sensor else "Eq. (22) form of [1]; ")
        + "coefficients rounded here for reading)",
        f"  B = {drift.intercept_dph:.10g}{terms}   [deg/h]",
        f"  f  = freq_hz - f_ref, f_ref = {settings.reference_freq_hz:.12g} Hz "
        f"(the thermometer at {settings.reference_c:g} degC)   [Hz]",
        "  df = df/dt by the causal filter D(s) = s/(tau s + 1)^2 (tau = "
        f"{settings.rate_tau_s:g} s), each step exact over its own dt (the input moving "
        "linearly over the step; a gap is bridged with its dt):",
        "         y1 += a*(f_prev - y1) + p*(f - f_prev);",
        "         y2 += a*(y1_prev - y2) + p*(y1 - y1_prev),",
        "         df = (y1 - y2)/tau,  a = 1 - exp(-dt/tau), p = 1 - a*tau/dt,",
        "         y1 = y2 = f at the first sample   [Hz/s]",
    ]
    if plan.housing:
        lines.append(f"  h  = housing_c - {settings.reference_c:g} degC, dh = its rate by the "
                     "same filter   [degC, degC/s]")
    lines += readme_lines(plan, settings)  # d2, g, a_NAME: each from its module
    lines += [
        "  The code evaluates B on the scaled variables v/scale_v with the exact (%.17g)",
        "  coefficients of the model file; algebraically the same polynomial. Beyond a",
        "  variable's training range B continues along its tangent at the range's edge",
        "  (a law linear in df/dt stays exact; cubic terms do not run away).",
        "  rate_comp_dph = rate_dph - B",
        f"  Thermometer: the gyro's temperature sensor, freq = {th}   [degC, T in degC]"
        if sensor else f"  Thermometer (Eq. (18) form): freq = {th}   [Hz, T in degC]",
        "  resonator_c_est = the T with freq(T) = freq_hz (Newton iteration on a bracket);",
        f"  NaN beyond the monotonic extension {plan.extension[0]:g} to "
        f"{plan.extension[1]:g} degC.",
        f"  in_range = 1 when freq_hz is in the calibrated range [{f_low:.10g}, {f_high:.10g}] "
        f"Hz ({thermometer.temperature_range_c[0]:g} to {thermometer.temperature_range_c[1]:g} "
        f"degC), the training ranges of the levels hold: {ranges(levels(plan))}, rate_in_range "
        f"is 1 and the filter has settled (the samples of the first {settings.warmup_s:g} s "
        f"of a run, the sum of dt_s ({up}_SETTLE_S), which training leaves out too, are 0); "
        "else 0.",
        f"  rate_in_range = 1 when the rates are in their training ranges: "
        f"{ranges(RATES)}; else 0 (a model trained on a cool-down has seen only "
        "negative df/dt).",
        "",
        "UNITS",
        "  inputs:  "
        + ("freq_hz [degC] the temperature sensor's reading" if sensor
           else "freq_hz [Hz] resonator natural frequency")
        + "; rate_dph [deg/h] gyro output "
        "(input rate included)"
        + ("; housing_c [degC] housing thermistor" if plan.housing_input else "")
        + "".join(f"; aux_{n} the logged {settings.aux_columns.get(n, '?')!r}"
                  for n in plan.aux)
        + "; dt_s [s] the time since the previous sample (any steps: jittered, bursts; "
        f"ignored on the first sample after init/reset). The model was trained at "
        f"{settings.sample_rate_hz:g} Hz ({up}_SAMPLE_RATE_HZ).",
        f"  gaps:    pass the gap's length as dt_s to carry the filter across it (bridge), "
        f"or call {p}_reset() to restart it at rest (split: the samples of the first "
        f"{up}_SETTLE_S seconds are then flagged again).",
        "  outputs: rate_comp_dph, bias_model_dph [deg/h]; resonator_c_est [degC];",
        "           f_hz [Hz]; df_hz_per_s [Hz/s]; in_range, rate_in_range 1/0.",
        "",
        "USAGE",
        f'  #include "{p}_model.h"',
        f"  static {p}_state gyro;",
        f"  {p}_init(&gyro);                      // once; {p}_reset(&gyro) at a new run",
        "  for (;;) {                              // each sample",
        f"      {p}_output out;",
        f"      double rate = {p}_step(&gyro, dt_s, freq_hz, rate_dph, {housing_use}&out);",
        "      if (!out.in_range) { flag_sample(); }  // outside the calibration",
        "  }",
        f"  Build: cc -std=c99 -O2 -c {p}_model.c, link with -lm. Double precision is needed",
        "  (f is a few Hz out of 4.4 kHz). Do not use -ffast-math; with -ffp-contract=off (GCC's "
        "default under -std=c99) the filter and the thermometer round exactly as hrgtc does "
        "(fused multiply-add would change only the last bits).",
        f"  The step signature: double {p}_step({p}_state *, double dt_s, double freq_hz, "
        "double rate_dph, "
        f"{housing_arg}{p}_output *out);",
        "",
        "REFERENCE",
        f"  [1] {PAPER_CITATION if sensor else PAPER_REFERENCE}",
    ]
    scale = scale_pieces(model, plan, prefix)["readme"]
    if scale:
        lines[lines.index("  rate_comp_dph = rate_dph - B")] = scale
    if sections is not None:
        lines[lines.index("UNITS"):lines.index("REFERENCE")] = sections
    wrapped = []
    for line in lines:
        head = re.match(r"^\s*(?:\S+:\s+|\S+ = |\[\d+\] )?", line)
        indent = " " * (head.end() if head else 0)
        wrapped += textwrap.wrap(_comment(line), width=_WIDTH, subsequent_indent=indent,
                                 break_on_hyphens=False, break_long_words=False) or [""]
    return "/*\n" + "\n".join((" * " + line).rstrip() for line in wrapped) + "\n */\n"


def header(model: UnitModel, plan: CPlan, prefix: str, origin: str,
           sha256: str) -> str:
    """Text of ``<prefix>_model.h``: README block, state and output structs, prototypes
    (the template both builds share, :func:`hrgtc.export.c.header.header`)."""
    return template(model, plan, prefix, readme(model, plan, prefix, origin, sha256), sha256)


def _bias_function(model: UnitModel, plan: CPlan, prefix: str) -> str:
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
        # held at the edge of the training range; the tangent there continues the model
        # beyond it, as DriftModel.predict(extrapolation="tangent")
        u = cname(v)
        body.append(f"    const {real} c_{v} = {names[v]} < CLAMP_{u}_LOW ? CLAMP_{u}_LOW : "
                    f"({names[v]} > CLAMP_{u}_HIGH ? CLAMP_{u}_HIGH : {names[v]});")
        body.append(f"    const {real} x_{v} = c_{v} / SCALE_{u};")
    body.append(f"    {real} sum = {zero};")
    body.append(f"    {real} term;")
    for k, term in enumerate(drift.terms):
        body.append(f"    term = {_term_expression(term, t)};  /* {term.name} */")
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
            expression = factor if rest is None else f"{factor} * {_term_expression(rest, t)}"
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
                         f"{_array(drift.scaled_coefficients, 'scaled_coefficients', t)};")
    return "\n".join(constants) + f"""

{real} {prefix}_bias_dph({signature})
{{
""" + "\n".join(body) + "\n}\n"


def source(model: UnitModel, plan: CPlan, prefix: str) -> str:
    """Text of ``<prefix>_model.c``: filter, drift model, thermometer inverse, step()."""
    from hrgtc.export.c.scale import scale_pieces

    p, up = prefix, prefix.upper()
    drift, th = model.drift, model.thermometer
    settings = drift.settings
    ranges = []
    for v in plan.computed:
        if v in drift.ranges:
            low, high = drift.ranges[v]
            ranges.append((v, _literal(low, f"ranges[{v}][0]"), _literal(high, f"ranges[{v}][1]")))
    def checks(kind: tuple[str, ...]) -> str:
        return "".join(
            f"\n        && {v}_value >= RANGE_{u}_LOW && {v}_value <= RANGE_{u}_HIGH"
            for v, u in ((v, cname(v)) for v, _, _ in ranges) if v in kind
        )

    range_constants = "".join(
        f"static const double RANGE_{cname(v)}_LOW = {low};\n"
        f"static const double RANGE_{cname(v)}_HIGH = {high};\n"
        for v, low, high in ranges
    )
    above = "residual > 0.0" if plan.increasing else "!(residual > 0.0)"
    # the housing thermistor's pieces, empty when the terms do not use h or dh
    reference_c = _literal(settings.reference_c, "reference_c")
    h = {
        "constants": f"static const double REFERENCE_C = {reference_c};\n",
        "start": "        rate_start(&state->h_filter, h_value);\n",
        "values": "    const double h_value = housing_c - REFERENCE_C;\n"
                  "    double dh_value = 0.0;\n",
        "rate": "        dh_value = rate_update(&state->h_filter, h_value, dt_s, RATE_TAU_S);\n",
        "out": "        out->h_c = h_value;\n        out->dh_c_per_s = dh_value;\n",
        "arg": ", double housing_c",
        "bias": ", h_value, dh_value",
        "reset": "    rate_start(&state->h_filter, 0.0);\n",
    }
    if not plan.housing:
        h = dict.fromkeys(h, "")
    h["arg"] = "".join(f", double {name}" for name in step_inputs(plan))
    extra = extra_variables(plan, settings, _literal, _comment, prefix=p)
    n_th = len(plan.th_coefficients)
    thermometer_text = thermometer_functions(
        p=p, n_th=n_th, above=above, real="double", fabs="fabs", half="0.5",
        fn=f"{p}_frequency_hz", arg="freq_hz")
    k = scale_pieces(model, plan, prefix)
    level_test = f"{p}_frequency_in_range(freq_hz)" + checks(levels(plan))
    tail = step_tail(up=up, level_test=level_test, rate_test="1" + checks(RATES), h=h, k=k)
    text = f"""/* {p}_model.c -- generated by hrgtc export-c for unit {_comment(model.unit)};
 * see {p}_model.h for what it computes, its provenance and its use. Do not edit.
 * Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
 */
#include "{p}_model.h"

#include <math.h>

/* ---- frequency change and the causal df/dt filter (hrgtc.drift.rate_filter) ---- */
static const double REFERENCE_FREQ_HZ = \
{_literal(settings.reference_freq_hz, 'reference_freq_hz')};
{h['constants']}{extra['constants']}\
/* time constant of each stage of the df/dt filter [s] */
static const double RATE_TAU_S = {_literal(plan.tau_s, 'rate_tau_s')};

{filter_functions(p, False)}{extra['functions']}
/* ---- the drift model, Eq. (22) of [1] (hrgtc.drift.DriftModel.predict) ---- */
{_bias_function(model, plan, p)}{k['function']}
/* ---- the thermometer, Eq. (18) of [1] (hrgtc.thermometry.Thermometer) ---- */
static const double TH_CENTRE_C = {_literal(th.centre_c, 'centre_c')};
static const double TH_SCALE_C = {_literal(th.scale_c, 'scale_c')};
/* f(T) = sum_k TH_COEFFICIENTS[k] z^k, z = (T - TH_CENTRE_C) / TH_SCALE_C [Hz] */
static const double TH_COEFFICIENTS[{n_th}] = \
{_array(plan.th_coefficients, 'scaled_coefficients')};
/* d f / d z, ascending */
static const double TH_DERIVATIVE[{n_th - 1}] = {_array(plan.th_derivative, 'derivative')};
/* calibrated frequency range [Hz] */
static const double TH_F_LOW_HZ = {_literal(plan.f_range[0], 'f_low')};
static const double TH_F_HIGH_HZ = {_literal(plan.f_range[1], 'f_high')};
/* table of f(T) over the monotonic extension, ascending in f: starts the Newton iteration */
#define TH_TABLE_POINTS {TABLE_POINTS}
static const double TH_TABLE_F[TH_TABLE_POINTS] = {_array(plan.grid_f, 'table_f')};
static const double TH_TABLE_T[TH_TABLE_POINTS] = {_array(plan.grid_t, 'table_t')};
static const double TH_TOLERANCE_C = {_literal(plan.tolerance, 'tolerance')};
#define TH_MAX_ITER {NEWTON_MAX_ITER}

{thermometer_text}/* ---- streaming compensation (hrgtc.compensate.Compensator) ---- */
/* training ranges of the drift model's variables (as the model file stores them) */
{range_constants}
void {p}_reset({p}_state *state)
{{
    rate_start(&state->f_filter, 0.0);
{h['reset']}{extra['reset']}    state->started = 0;
    state->samples = 0UL;
    state->elapsed_s = 0.0;
    state->out_of_range = 0UL;
    state->rate_out_of_range = 0UL;
}}

void {p}_init({p}_state *state)
{{
    {p}_reset(state);
}}

double {p}_step({p}_state *state, double dt_s, double freq_hz, double rate_dph{h['arg']}, \
{p}_output *out)
{{
    const double f_value = freq_hz - REFERENCE_FREQ_HZ;
{h['values']}{extra['values']}    double df_value = 0.0, bias, compensated, temperature;
    int in_range, rate_in_range, level_in_range, settled;
{k['declare']}    if (!state->started) {{  /* the filters start at rest on the first sample */
        rate_start(&state->f_filter, f_value);
{h['start']}{extra['start']}        state->started = 1;
    }} else {{  /* each filter steps over this sample's dt_s */
        df_value = rate_update(&state->f_filter, f_value, dt_s, RATE_TAU_S);
{h['rate']}{extra['rate']}    }}
    temperature = {p}_temperature_c(freq_hz);
{extra['gradient']}    bias = {p}_bias_dph(f_value, df_value{h['bias']}{extra['bias']});
{tail}"""
    return sensor_words(model, text)
