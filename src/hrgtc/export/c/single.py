"""C text of the float32 firmware export (``hrgtc export-c --precision single``).

For FPU-only microcontrollers (Cortex-M4F and the like: single precision in hardware,
double in software). The same computation as the double build of
:mod:`hrgtc.export.c.text`, in ``float`` throughout (``f`` literals, ``powf``,
``fabsf``), with the frequency entering centred, the thermometer written about the
same centre and the df/dt filter kept as differences (see
:mod:`hrgtc.export.c.float32`, whose numpy mirror evaluates exactly these
statements). The drift terms are printed by the shared
:func:`hrgtc.export.c.text._bias_function` with the float :class:`CType`.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from hrgtc.export.c.float32 import MARGIN, FloatAccuracy, FloatConstants
from hrgtc.export.c.header import header as template
from hrgtc.export.c.header import sensor_words
from hrgtc.export.c.plan import TABLE_POINTS, CPlan
from hrgtc.export.c.rate_filter import filter_functions
from hrgtc.export.c.scale import scale_factor_of, scale_pieces
from hrgtc.export.c.step import step_tail
from hrgtc.export.c.text import NEWTON_MAX_ITER, _array, _bias_function, _comment, readme
from hrgtc.export.c.thermometer import thermometer_functions
from hrgtc.export.c.types import DOUBLE, SINGLE
from hrgtc.export.c.variables import RATES, extra_variables, levels, step_inputs
from hrgtc.model import UnitModel


def _sections(model: UnitModel, plan: CPlan, prefix: str, accuracy: FloatAccuracy) -> list[str]:
    """UNITS, USAGE and ACCURACY of the float build's README block."""
    p, up = prefix, prefix.upper()
    settings = model.drift.settings
    fs = settings.sample_rate_hz
    housing_use = "".join(f"{name}, " for name in step_inputs(plan))
    housing_arg = "".join(f"float {name}, " for name in step_inputs(plan))
    return [
        "FLOAT32 BUILD (for FPU-only microcontrollers, e.g. Cortex-M4F)",
        "  Everything is float: constants, state, arithmetic (powf, fabsf). The frequency "
        f"enters CENTRED: pass f_hz = freq_hz - {up}_CENTRE_HZ (the model's f_ref, "
        f"{model.drift.settings.reference_freq_hz:.12g} Hz) as a float. Take that difference "
        "where the frequency is still exact: in double (one software subtraction per sample, "
        f"the macro {up}_CENTRED_HZ(freq_hz) does it) or in the units of your frequency "
        "counter; a float freq_hz would already have lost 0.5 mHz (2 mdegC) to rounding. "
        "The thermometer polynomial is written about the same centre and the df/dt filter "
        "keeps its state as the differences f_prev - y1 and y1 - y2, updated with "
        "compensated (Kahan) sums (algebraically the same filter; float32 keeps their "
        "digits); its weights for each step's dt_s are computed in double (expm1) only "
        "when dt_s changes by more than 1e-6 of itself.",
        "",
        "ACCURACY (float32 against hrgtc's double model, measured at export by evaluating "
        "this code's float32 operations in numpy)",
        f"  resonator_c_est: worst {accuracy.temperature_c:.2g} degC over the calibrated "
        "frequency range.",
        f"  bias_model_dph:  worst {accuracy.bias_dph:.2g} deg/h over a grid of "
        f"{accuracy.grid_points} points of the trained ranges of its variables; "
        f"{accuracy.ramp_bias_dph:.2g} deg/h end to end through the df/dt filter on steady "
        "ramps over the trained df/dt range.",
        "  rate_comp_dph:   the bias error plus the float rounding of rate_dph itself "
        "(6e-8 of |rate|: 0.06 deg/h at 300 deg/s)"
        + (f"; scale_model_ppm: worst {accuracy.scale_ppm:.2g} ppm over the calibrated "
           "frequency range, and the float rounding of 1 + 1e-6 k (0.06 ppm)."
           if scale_factor_of(model) is not None else "."),
        f"  Stated bounds ({MARGIN:g} x the worst measured, for inputs between the grid "
        f"points): {up}_MAX_ERROR_C = {accuracy.bound_c:.2g} degC, {up}_MAX_ERROR_DPH = "
        f"{accuracy.bound_dph:.2g} deg/h.",
        "",
        "UNITS",
        f"  inputs:  f_hz = freq_hz - {up}_CENTRE_HZ [Hz]; rate_dph [deg/h] gyro output "
        "(input rate included)"
        + ("; housing_c [degC] housing thermistor" if plan.housing_input else "")
        + "".join(f"; aux_{n} the logged {settings.aux_columns.get(n, '?')!r} (float)"
                  for n in plan.aux)
        + "; dt_s [s] the time since the previous sample (any steps; ignored on the first "
        f"sample after init/reset). The model was trained at {fs:g} Hz.",
        "  gaps:    pass the gap's length as dt_s to carry the filter across it (bridge), "
        f"or call {p}_reset() to restart it (split).",
        "  outputs: rate_comp_dph, bias_model_dph [deg/h]; resonator_c_est [degC];",
        "           f_hz [Hz]; df_hz_per_s [Hz/s]; in_range, rate_in_range 1/0.",
        "",
        "USAGE",
        f'  #include "{p}_model.h"',
        f"  static {p}_state gyro;",
        f"  {p}_init(&gyro);                      // once; {p}_reset(&gyro) at a new run",
        "  for (;;) {                              // each sample",
        f"      {p}_output out;",
        f"      float rate = {p}_step(&gyro, dt_s, {up}_CENTRED_HZ(freq_hz), rate_dph, "
        f"{housing_use}&out);",
        "      if (!out.in_range) { flag_sample(); }  // outside the calibration",
        "  }",
        f"  Build: cc -std=c99 -O2 -c {p}_model.c (arm-none-eabi-gcc -mfpu=fpv4-sp-d16 "
        "-mfloat-abi=hard for a Cortex-M4F), link with -lm. Do not use -ffast-math (it "
        "would undo the filter's compensated sums); with "
        "-ffp-contract=off (GCC's default under -std=c99) the code rounds exactly as the "
        "mirror that measured the figures above (fused multiply-add changes only last bits).",
        f"  The step signature: float {p}_step({p}_state *, float dt_s, float f_hz, "
        "float rate_dph, "
        f"{housing_arg}{p}_output *out);",
        "",
    ]


def header(model: UnitModel, plan: CPlan, prefix: str, origin: str, sha256: str,
           constants: FloatConstants, accuracy: FloatAccuracy) -> str:
    """Text of the float build's ``<prefix>_model.h`` (the template both builds share,
    :func:`hrgtc.export.c.header.header`, in float, with the centre and error bounds)."""
    text = readme(model, plan, prefix, origin, sha256,
                  _sections(model, plan, prefix, accuracy))
    return template(model, plan, prefix, text, sha256, SINGLE, centre_hz=constants.centre_hz,
                    bounds=(accuracy.bound_c, accuracy.bound_dph))


def source(model: UnitModel, plan: CPlan, prefix: str, constants: FloatConstants) -> str:
    """Text of the float build's ``<prefix>_model.c``."""
    p, up = prefix, prefix.upper()
    c = constants
    lit = SINGLE.literal
    drift = model.drift
    ranges = [(v, lit(drift.ranges[v][0], f"ranges[{v}][0]"),
               lit(drift.ranges[v][1], f"ranges[{v}][1]"))
              for v in plan.computed if v in drift.ranges]

    def checks(kind: tuple[str, ...]) -> str:
        return "".join(f"\n        && {v}_value >= RANGE_{v.upper()}_LOW "
                       f"&& {v}_value <= RANGE_{v.upper()}_HIGH"
                       for v, _, _ in ranges if v in kind)

    range_constants = "".join(f"static const float RANGE_{v.upper()}_LOW = {low};\n"
                              f"static const float RANGE_{v.upper()}_HIGH = {high};\n"
                              for v, low, high in ranges)
    above = "residual > 0.0f" if plan.increasing else "!(residual > 0.0f)"
    h = {
        "constants": f"static const float REFERENCE_C = {lit(c.reference_c, 'reference_c')};\n",
        "start": "        rate_start(&state->h_filter, h_value);\n",
        "values": "    const float h_value = housing_c - REFERENCE_C;\n"
                  "    float dh_value = 0.0f;\n",
        "rate": "        dh_value = rate_update(&state->h_filter, h_value, dt_s, RATE_TAU_S, "
                "RATE_TAU);\n",
        "out": "        out->h_c = h_value;\n        out->dh_c_per_s = dh_value;\n",
        "arg": ", float housing_c",
        "bias": ", h_value, dh_value",
        "reset": "    rate_start(&state->h_filter, 0.0f);\n",
    }
    if not plan.housing:
        h = dict.fromkeys(h, "")
    h["arg"] = "".join(f", float {name}" for name in step_inputs(plan))
    # the variables beyond f, df, h, dh, each from its module (g = housing_c - T(f) needs
    # the temperature, computed before the bias)
    g = extra_variables(plan, model.drift.settings, lit, _comment, ctype=SINGLE, prefix=p)
    h["constants"] += g["constants"]
    n_th = c.th_coefficients.size
    thermometer_text = thermometer_functions(
        p=p, n_th=n_th, above=above, real="float", fabs="fabsf", half="0.5f",
        fn=f"{p}_centred_frequency_hz", arg="f_hz")
    k = scale_pieces(model, plan, prefix)
    level_test = f"{p}_frequency_in_range(f_value)" + checks(levels(plan))
    tail = step_tail(up=up, level_test=level_test, rate_test="1" + checks(RATES),
                     h=h, k=k)
    text = f"""/* {p}_model.c -- generated by hrgtc export-c --precision single for unit \
{_comment(model.unit)};
 * see {p}_model.h for what it computes, its accuracy, its provenance and its use. Do not edit.
 * Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
 */
#include "{p}_model.h"

#include <math.h>

/* ---- the causal df/dt filter (hrgtc.drift.rate_filter), kept as differences ---- */
{h['constants']}/* time constant of each df/dt stage, in double (the weights) and float [s] */
static const double RATE_TAU_S = {DOUBLE.literal(c.tau_s, 'rate_tau_s')};
static const float RATE_TAU = {lit(c.tau, 'tau')};

{filter_functions(p, True)}
/* ---- the drift model, Eq. (22) of [1] (hrgtc.drift.DriftModel.predict) ---- */
{_bias_function(model, plan, p)}{k['function']}
/* ---- the thermometer, Eq. (18) of [1], centred on {up}_CENTRE_HZ ---- */
static const float TH_CENTRE_C = {lit(c.th_centre_c, 'centre_c')};
static const float TH_SCALE_C = {lit(c.th_scale_c, 'scale_c')};
/* f(T) - CENTRE_HZ = sum_k TH_COEFFICIENTS[k] z^k, z = (T - TH_CENTRE_C) / TH_SCALE_C [Hz] */
static const float TH_COEFFICIENTS[{n_th}] = {_array(c.th_coefficients, 'coefficients', SINGLE)};
/* d f / d z, ascending */
static const float TH_DERIVATIVE[{n_th - 1}] = {_array(c.th_derivative, 'derivative', SINGLE)};
/* calibrated range of f_hz [Hz] */
static const float TH_F_LOW_HZ = {lit(c.f_low, 'f_low')};
static const float TH_F_HIGH_HZ = {lit(c.f_high, 'f_high')};
/* table of f(T) - CENTRE_HZ over the monotonic extension, ascending: starts Newton */
#define TH_TABLE_POINTS {TABLE_POINTS}
static const float TH_TABLE_F[TH_TABLE_POINTS] = {_array(c.table_f, 'table_f', SINGLE)};
static const float TH_TABLE_T[TH_TABLE_POINTS] = {_array(c.table_t, 'table_t', SINGLE)};
static const float TH_TOLERANCE_C = {lit(c.tolerance, 'tolerance')};
#define TH_MAX_ITER {NEWTON_MAX_ITER}

{thermometer_text}/* ---- streaming compensation (hrgtc.compensate.Compensator) ---- */
/* training ranges of the drift model's variables (as the model file stores them) */
{range_constants}
void {p}_reset({p}_state *state)
{{
    rate_start(&state->f_filter, 0.0f);
{h['reset']}{g['reset']}    state->started = 0;
    state->samples = 0UL;
    state->elapsed_s = 0.0f;
    state->out_of_range = 0UL;
    state->rate_out_of_range = 0UL;
}}

void {p}_init({p}_state *state)
{{
    {p}_reset(state);
}}

float {p}_step({p}_state *state, float dt_s, float f_hz, float rate_dph{h['arg']},
{p}_output *out)
{{
    const float f_value = f_hz;
{h['values']}{g['values']}    float df_value = 0.0f, bias, compensated, temperature;
    int in_range, rate_in_range, level_in_range, settled;
{k['declare']}    if (!state->started) {{  /* the filters start at rest on the first sample */
        rate_start(&state->f_filter, f_value);
{h['start']}{g['start']}        state->started = 1;
    }} else {{  /* each filter steps over this sample's dt_s */
        df_value = rate_update(&state->f_filter, f_value, dt_s, RATE_TAU_S, RATE_TAU);
{h['rate']}{g['rate']}    }}
    temperature = {p}_temperature_c(f_value);
{g['gradient']}    bias = {p}_bias_dph(f_value, df_value{h['bias']}{g['bias']});
{tail}"""
    return sensor_words(model, text)
