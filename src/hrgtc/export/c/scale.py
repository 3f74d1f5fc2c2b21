"""C text of the scale-factor correction in the firmware export (double and float32 builds).

When the unit's model has a scale factor (:class:`hrgtc.drift.scale_factor.ScaleFactorModel`,
k(f) in ppm, a polynomial in x_f = (freq_hz - reference_hz) / scale_hz continued along its
tangent beyond the rate-table runs' frequency range), the generated ``step()`` divides
the bias-corrected rate by ``1 + 1e-6 k``, as :class:`hrgtc.compensate.Compensator` does:
``rate_comp = (rate - B) / (1 + 1e-6 k)``. :func:`scale_pieces` gives the pieces the
header and source templates insert; all are empty for a model without a scale factor,
so those files stay as they were.
"""

from __future__ import annotations

from hrgtc.drift.scale_factor import ScaleFactorModel
from hrgtc.export.c.expr import array as _array
from hrgtc.export.c.expr import term_expression as _term_expression
from hrgtc.export.c.plan import CPlan
from hrgtc.export.c.types import CType, ctype
from hrgtc.model import Model

PIECES = ("define", "field", "prototype", "function", "declare", "apply", "out", "readme")


def scale_factor_of(model: Model) -> ScaleFactorModel | None:
    """The model's scale factor, or None."""
    return model.scale_factor


def _function(model: Model, prefix: str, t: CType) -> str:
    sf = scale_factor_of(model)
    assert sf is not None
    real, lit = t.name, t.literal
    low = sf.freq_range_hz[0] - sf.reference_hz  # as ScaleFactorModel.ppm, in double
    high = sf.freq_range_hz[1] - sf.reference_hz
    if t.suffix:  # float: the centred f_hz of the drift model, shifted to k's own reference
        offset = sf.reference_hz - model.drift.settings.reference_freq_hz
        argument = "f_hz"
        first = (f"    const {real} f = f_hz - SF_OFFSET_HZ;\n" if offset else
                 f"    const {real} f = f_hz;\n")
        offset_constant = (f"static const {real} SF_OFFSET_HZ = {lit(offset, 'sf offset')};  "
                           "/* k's reference - CENTRE_HZ */\n" if offset else "")
    else:
        argument = "freq_hz"
        first = f"    const {real} f = freq_hz - SF_REFERENCE_HZ;\n"
        offset_constant = (f"static const {real} SF_REFERENCE_HZ = "
                           f"{lit(sf.reference_hz, 'sf reference_hz')};\n")
    lines = [
        "",
        "/* ---- the scale-factor error k(f) (hrgtc.drift.scale_factor.ScaleFactorModel) ---- */",
        offset_constant.rstrip("\n") or None,
        f"static const {real} SF_INTERCEPT_PPM = {lit(sf.intercept_ppm, 'sf intercept')};",
        f"static const {real} SF_SCALE_F = {lit(sf.scale_hz, 'sf scale_hz')};",
        f"static const {real} SF_LOW_F = {lit(low, 'sf low')};",
        f"static const {real} SF_HIGH_F = {lit(high, 'sf high')};",
    ]
    terms = sf.terms
    if terms:
        lines.append(f"/* Coefficients on x_f, in this order: {', '.join(sf.selected)} */")
        lines.append(f"static const {real} SF_COEFFICIENTS[{len(terms)}] = "
                     f"{_array(sf.scaled_coefficients, 'sf coefficients', t)};")
    lines += ["", f"{real} {prefix}_scale_ppm({real} {argument})", "{", first.rstrip("\n")]
    lines += [f"    const {real} c_f = f < SF_LOW_F ? SF_LOW_F : (f > SF_HIGH_F ? SF_HIGH_F : f);",
              f"    const {real} x_f = c_f / SF_SCALE_F;",
              f"    {real} k = SF_INTERCEPT_PPM;"]
    if terms:
        lines.append(f"    {real} term;")
    else:
        lines.append("    (void)x_f;")
    for j, term in enumerate(terms):
        lines += [f"    term = {_term_expression(term, t)};  /* {term.name} */",
                  f"    term = SF_COEFFICIENTS[{j}] * term;",
                  "    k = k + term;"]
    if terms:
        lines += ["    if (f < SF_LOW_F || f > SF_HIGH_F) {  /* beyond the rate-table range */",
                  f"        {real} gradient = {lit(0.0, 'zero')};"]
        for j, term in enumerate(terms):
            multiplier, rest = term.derivative("f")
            factor = f"SF_COEFFICIENTS[{j}] * {lit(multiplier, 'multiplier')} / SF_SCALE_F"
            expression = factor if rest is None else f"{factor} * {_term_expression(rest, t)}"
            lines.append(f"        gradient = gradient + {expression};  /* d({term.name})/df */")
        lines += ["        k = k + gradient * (f - c_f);", "    }"]
    lines += ["    return k;", "}"]
    return "\n".join(line for line in lines if line is not None) + "\n"


def scale_pieces(model: Model, plan: CPlan, prefix: str) -> dict[str, str]:
    """Text the header and source templates insert for the scale factor ('' without one)."""
    if scale_factor_of(model) is None:
        return dict.fromkeys(PIECES, "")
    t = ctype(plan)
    real, lit = t.name, t.literal
    up = prefix.upper()
    argument = "f_value" if t.suffix else "freq_hz"
    sf = model.scale_factor
    return {
        "define": f"/* 1: {prefix}_step() also corrects the scale factor, "
                  "rate_comp = (rate - B) / (1 + 1e-6 k). */\n"
                  f"#define {up}_USES_SCALE_FACTOR 1\n",
        "field": f"    {real} scale_model_ppm;{' ' * (8 - len(real))}"
                 "    /* scale-factor error k at this frequency [ppm] */\n",
        "prototype": f"/* Scale-factor error k(f) from rate-table runs. [ppm] */\n"
                     f"{real} {prefix}_scale_ppm({real} "
                     f"{'f_hz' if t.suffix else 'freq_hz'});\n\n",
        "function": _function(model, prefix, t),
        "declare": f"    {real} scale, product, divisor;\n",
        "apply": f"    scale = {prefix}_scale_ppm({argument});\n"
                 f"    product = {lit(1e-6, 'ppm')} * scale;\n"
                 f"    divisor = {lit(1.0, 'one')} + product;\n"
                 "    compensated = compensated / divisor;  /* (rate - B) / (1 + 1e-6 k) */\n",
        "out": "        out->scale_model_ppm = scale;\n",
        "readme": f"  rate_comp_dph = (rate_dph - B) / (1 + 1e-6*k), the scale-factor error "
                  f"{sf.equation()} from rate-table runs over {sf.freq_range_hz[0]:.10g} to "
                  f"{sf.freq_range_hz[1]:.10g} Hz (continued along its tangent beyond).",
    }
