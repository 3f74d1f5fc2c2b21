"""C text of the firmware export: the README block and the double build's header.

The header is the template both builds share (:mod:`hrgtc.export.c.header`); the
``.c`` file is one body for both builds (:mod:`hrgtc.export.c.source`).

:mod:`hrgtc.export.export_c` decides what to export (the validated numbers of a
:class:`~hrgtc.model.Model`); this module says in words what the code computes, with
which numbers and how to use it (the float32 build replaces the UNITS and USAGE
sections with its own, :mod:`hrgtc.export.c.single`).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import re
import textwrap
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from hrgtc.export.c.expr import comment as _comment
from hrgtc.export.c.header import header as template
from hrgtc.export.c.plan import CPlan
from hrgtc.export.c.variables import (
    RATES,
    levels,
    readme_lines,
    step_inputs,
)
from hrgtc.model import Model

_WIDTH = 92


def sensor_note(model: Model) -> list[str]:
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
        *_count_map_note(model.temperature_map),
        "",
    ]


def _count_map_note(temperature_map: Mapping[str, Any] | None) -> list[str]:
    """Lines that say the sensor logged a raw count, mapped to degC by the model's map
    (``calibrate --temp-ref``): freq_hz is the mapped count, not the count itself."""
    if not temperature_map:
        return []
    scale, offset = temperature_map["scale_c_per_count"], temperature_map["offset_c"]
    bits = temperature_map.get("count_bits")
    lines = ["  The sensor logs a raw count, which calibrate --temp-ref mapped to degC (fitted",
             f"  on the reference log {temperature_map.get('reference') or '?'}): pass",
             "  freq_hz = T = S*count + O, not the count itself, with",
             f"    S = {scale:.17g} degC per count",
             f"    O = {offset:.17g} degC"]
    if bits:
        lines.append(f"  (a signed {bits}-bit count stored unsigned: a count of 2^{bits - 1} or "
                     f"more is taken minus 2^{bits} first).")
    return lines


def title(model: Model) -> str:
    """What an export compensates, for its first line: an HRG's drift (a resonator
    thermometer), or a gyro's by its temperature sensor (``--thermometer sensor``)."""
    if model.thermometer.source == "sensor":
        return "gyro temperature-drift compensation (temperature sensor)"
    return "HRG temperature-drift compensation"


def offsets_note(model: Model) -> list[str]:
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


def readme(model: Model, plan: CPlan, prefix: str, origin: str,
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


def header(model: Model, plan: CPlan, prefix: str, origin: str,
           sha256: str) -> str:
    """Text of ``<prefix>_model.h``: README block, state and output structs, prototypes
    (the template both builds share, :func:`hrgtc.export.c.header.header`)."""
    return template(model, plan, prefix, readme(model, plan, prefix, origin, sha256), sha256)
