"""C text of the float32 firmware export (``hrgtc export-c --precision single``).

For FPU-only microcontrollers (Cortex-M4F and the like: single precision in hardware,
double in software). The ``.c`` file is the double build's body printed in ``float``
(:mod:`hrgtc.export.c.source`: ``f`` literals, ``powf``, ``fabsf``), with the frequency
entering centred, the thermometer written about the same centre and the df/dt filter kept
as differences (see :mod:`hrgtc.export.c.float32`, whose numpy mirror evaluates exactly
these statements). This module writes what the float build's header says beyond the
double one's: its UNITS, USAGE and ACCURACY sections, the centre and the error bounds.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from hrgtc.export.c.float32 import MARGIN, FloatAccuracy, FloatConstants
from hrgtc.export.c.header import header as template
from hrgtc.export.c.plan import CPlan
from hrgtc.export.c.scale import scale_factor_of
from hrgtc.export.c.text import readme
from hrgtc.export.c.types import SINGLE
from hrgtc.export.c.variables import step_inputs
from hrgtc.model import Model


def _sections(model: Model, plan: CPlan, prefix: str, accuracy: FloatAccuracy) -> list[str]:
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


def header(model: Model, plan: CPlan, prefix: str, origin: str, sha256: str,
           constants: FloatConstants, accuracy: FloatAccuracy) -> str:
    """Text of the float build's ``<prefix>_model.h`` (the template both builds share,
    :func:`hrgtc.export.c.header.header`, in float, with the centre and error bounds)."""
    text = readme(model, plan, prefix, origin, sha256,
                  _sections(model, plan, prefix, accuracy))
    return template(model, plan, prefix, text, sha256, SINGLE, centre_hz=constants.centre_hz,
                    bounds=(accuracy.bound_c, accuracy.bound_dph))
