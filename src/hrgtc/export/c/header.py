"""The header ``<prefix>_model.h`` of the firmware export, one template for both builds.

The double build (README by :mod:`hrgtc.export.c.text`) and the float32 build (its
sections by :mod:`hrgtc.export.c.single`) declare the same defines, state, output and
functions; they differ in the C type (:class:`~hrgtc.export.c.types.CType`), in the float build's
own defines (its centre and error bounds) and in its frequency input, which enters
centred (``f_hz = freq_hz - CENTRE_HZ``). :func:`header` writes both, so a change of
the interface is one edit.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from hrgtc.core.errors import InputError
from hrgtc.core.timeline import settle_threshold_s
from hrgtc.drift.features import settle_rows
from hrgtc.export.c.expr import comment
from hrgtc.export.c.plan import CPlan
from hrgtc.export.c.rate_filter import filter_struct
from hrgtc.export.c.scale import scale_pieces
from hrgtc.export.c.types import DOUBLE, SINGLE, CType
from hrgtc.export.c.variables import bias_params, extra_variables, step_inputs
from hrgtc.model import Model

#: Column of the field comments in the state and output structs.
_FIELD_WIDTH = 28


def header(model: Model, plan: CPlan, prefix: str, readme: str, sha256: str,
           t: CType = DOUBLE, *,
           centre_hz: float | None = None,
           bounds: tuple[float, float] | None = None) -> str:
    """Text of ``<prefix>_model.h``: the README block, defines, state and output structs
    and the prototypes, in the C type ``t``.

    Parameters
    ----------
    readme
        The README comment block (:func:`hrgtc.export.c.text.readme`).
    sha256
        SHA-256 of the model file (``<PREFIX>_MODEL_SHA256``).
    t
        :data:`~hrgtc.export.c.types.DOUBLE` or :data:`~hrgtc.export.c.types.SINGLE`.
    centre_hz, bounds
        The float build's centre of the frequency input (f_ref, in double) [Hz] and the
        bounds of its error against the double model (temperature [°C], bias [°/h]).
    """
    p, up = prefix, prefix.upper()
    real, lit, single = t.name, t.literal, t is SINGLE
    settings = model.drift.settings

    def field(name: str, comment: str) -> str:
        return f"    {f'{real} {name};':<{_FIELD_WIDTH}}/* {comment} */\n"

    state_h = (f"    {p}_rate_filter h_filter;   /* dh/dt filter of h [degC] */\n"
               if plan.housing else "")
    state_h += extra_variables(plan, settings, lit, comment, ctype=t, prefix=p)["state"]
    out_h = (field("h_c", "housing temperature change h [degC]")
             + field("dh_c_per_s", "its causal rate dh/dt [degC/s]")) if plan.housing else ""
    k = scale_pieces(model, plan, prefix)
    out_h += k["field"]
    arg_h = "".join(f", {real} {name}" for name in step_inputs(plan))
    bias_h = "".join(f", {real} {name}" for _, name in bias_params(plan)[2:])
    inputs = ((", housing_c [degC]" if plan.housing_input else "")
              + "".join(f", aux_{n}" for n in plan.aux))
    levels = " and ".join(v for v in plan.computed if v in ("f", "h"))
    rates = " and ".join(v for v in plan.computed if v in ("df", "dh"))
    settle_s = settle_threshold_s(settings.warmup_s)
    if single:
        if centre_hz is None or bounds is None:
            raise InputError("the float32 header needs its centre_hz and error bounds")
        defines = f"""\
/* This is the float32 build (hrgtc export-c --precision single). */
#define {up}_SINGLE_PRECISION 1
/* Centre of the frequency input: f_ref, the thermometer at {settings.reference_c:g} degC. [Hz] */
#define {up}_CENTRE_HZ {DOUBLE.literal(centre_hz, "centre_hz")}
/* The centred frequency {p}_step() takes, from a double freq_hz. [Hz] */
#define {up}_CENTRED_HZ(freq_hz) ((float)((freq_hz) - {up}_CENTRE_HZ))
/* Bound of the float32 error against the double model over the calibrated range, from the
   worst measured at export: resonator temperature [degC] and bias model [deg/h]. */
#define {up}_MAX_ERROR_C {lit(bounds[0], "max_error_c")}
#define {up}_MAX_ERROR_DPH {lit(bounds[1], "max_error_dph")}
"""
        settle_text = lit(settle_s, "settle_s")
        frequency, described = "f_hz", f"\n   f_hz = freq_hz - {up}_CENTRE_HZ [Hz], rate_dph"
        thermometer = f"""\
/* Thermometer, Eq. (18) form, centred: f(T) - {up}_CENTRE_HZ. [Hz] from [degC] */
float {p}_centred_frequency_hz(float temperature_c);

/* Its inverse: resonator temperature from f_hz = freq_hz - {up}_CENTRE_HZ; NaN beyond the
   monotonic extension. */
float {p}_temperature_c(float f_hz);

/* 1 when f_hz = freq_hz - {up}_CENTRE_HZ lies in the calibrated frequency range, else 0. */
int {p}_frequency_in_range(float f_hz);
"""
    else:
        defines, settle_text = "", repr(settle_s)
        frequency, described = "freq_hz", " freq_hz [Hz],\n   rate_dph"
        thermometer = f"""\
/* Thermometer f(T), Eq. (18) form. [Hz] from [degC] */
double {p}_frequency_hz(double temperature_c);

/* Its inverse: resonator temperature from frequency; NaN beyond the monotonic extension. */
double {p}_temperature_c(double freq_hz);

/* 1 when freq_hz lies in the calibrated frequency range, else 0. */
int {p}_frequency_in_range(double freq_hz);
"""
    text = f"""{readme}
#ifndef {up}_MODEL_H
#define {up}_MODEL_H

#ifdef __cplusplus
extern "C" {{
#endif

{defines}\
/* Sample rate of the training runs; step() takes each sample's dt_s, any rate works. [Hz] */
#define {up}_SAMPLE_RATE_HZ {lit(settings.sample_rate_hz, "sample_rate_hz")}
/* SETTLE_S in samples at the training rate (on a continuous run; in_range uses SETTLE_S). */
#define {up}_SETTLE_ROWS {settle_rows(settings)}UL
/* Seconds since init/reset (the sum of dt_s) from which the filter has settled:
   samples before are flagged (in_range 0), as training leaves them out. [s] */
#define {up}_SETTLE_S {settle_text}
/* 1 when {p}_step() takes the housing temperature (the model uses h, dh or g terms). */
#define {up}_USES_HOUSING {1 if plan.housing_input else 0}
/* Extra logged channels {p}_step() takes after housing_c (aux_NAME, --aux NAME=COLUMN). */
#define {up}_AUX_INPUTS {len(plan.aux)}
/* SHA-256 of the model this code was generated from. */
#define {up}_MODEL_SHA256 "{sha256}"
{k['define']}
{filter_struct(p, single)}
/* Filter state of one gyro; initialise with {p}_init(). */
typedef struct {p}_state {{
    {p}_rate_filter f_filter;   /* df/dt filter of f [Hz] */
{state_h}    int started;                /* 0 until the first sample after init/reset */
    unsigned long samples;      /* samples since init/reset */
{field("elapsed_s", "seconds since init/reset, up to SETTLE_S [s]")}\
    unsigned long out_of_range; /* of which settled, outside the calibrated temperature */
    unsigned long rate_out_of_range; /* of which settled, with rate_in_range == 0 */
}} {p}_state;

/* Everything one step computes. */
typedef struct {p}_output {{
{field("rate_comp_dph", "compensated rate, rate_dph - bias_model_dph [deg/h]")}\
{field("bias_model_dph", "modelled bias B, Eq. (22) [deg/h]")}\
{field("resonator_c_est", "resonator temperature from frequency [degC] (NaN: beyond)")}\
{field("f_hz", "frequency change f = freq_hz - f_ref [Hz]")}\
{field("df_hz_per_s", "its causal rate df/dt [Hz/s]")}\
{out_h}    int in_range;               /* 1: frequency calibrated, {levels} and rates in training
                                   range, filter settled */
    int rate_in_range;          /* 1: {rates} in training range (else extrapolated in time) */
}} {p}_output;

/* Set the state to the start of a run (before first use). */
void {p}_init({p}_state *state);

/* Start a new run (or a segment after a gap, split): the df/dt filter restarts at rest
   on the next sample. */
void {p}_reset({p}_state *state);

/* Compensate one sample; returns rate_comp_dph and fills *out unless out is NULL.
   dt_s [s] time since the previous sample (a gap's length bridges it),{described} \
[deg/h]{inputs}. */
{real} {p}_step({p}_state *state, {real} dt_s, {real} {frequency}, {real} rate_dph{arg_h},
{" " * (len(real) + 10)}{p}_output *out);

/* Bias model B of Eq. (22) from the variables. [deg/h] */
{real} {p}_bias_dph({real} f_hz, {real} df_hz_per_s{bias_h});

{k['prototype']}{thermometer}
#ifdef __cplusplus
}}
#endif

#endif /* {up}_MODEL_H */
"""
    return sensor_words(model, text)


#: The export's words for a resonator's thermometer and the paper's equation numbers, and
#: what a model of the gyro's temperature sensor says instead: its thermometer is the
#: identity on °C, no fit of Eq. (18), and its drift model is in T and dT/dt, not the
#: paper's Eq. (22) of a resonator's frequency.
_SENSOR_WORDS = (
    ("resonator temperature from frequency", "sensor temperature"),
    ("resonator temperature from f_hz", "sensor temperature from f_hz"),
    ("worst measured at export: resonator temperature",
     "worst measured at export: sensor temperature"),
    ("/* Thermometer f(T), Eq. (18) form. [Hz] from [degC] */",
     "/* Thermometer f(T) = T, the identity. [degC] from [degC] */"),
    ("/* Thermometer, Eq. (18) form, centred:", "/* Thermometer f(T) = T, the identity, centred:"),
    ("modelled bias B, Eq. (22) [deg/h]", "modelled bias B [deg/h]"),
    ("Bias model B of Eq. (22) from", "Bias model B from"),
    ("the drift model, Eq. (22) of [1] (", "the drift model ("),
    ("the thermometer, Eq. (18) of [1] (",
     "the thermometer, f(T) = T, the identity ("),
    ("the thermometer, Eq. (18) of [1], centred on",
     "the thermometer, f(T) = T, the identity, centred on"),
    ("/ TH_SCALE_C [Hz] */", "/ TH_SCALE_C [degC] */"),
    (", Eq. (22) of [1])", ")"),
    (", Eq. (18) of [1].", "."),
    ("the drift model (Eq. 22).", "the drift model."),
    ("on the raw variables, Eq. (22) form.", "on the raw variables."),
    ("polynomial F(T) (Eq. 18).", "polynomial F(T) (1: the identity F(T) = T)."),
    ("The same F(T) in T (Eq. 18):", "The same F(T) in T:"),
)


def sensor_words(model: Model, text: str) -> str:
    """``text`` (a C header or source, a parameter file's lines) in the words of a model of
    the gyro's temperature sensor (``--thermometer sensor``); a resonator's model keeps the
    paper's words, unchanged."""
    if model.thermometer.source != "sensor":
        return text
    for old, new in _SENSOR_WORDS:
        text = text.replace(old, new)
    return text
