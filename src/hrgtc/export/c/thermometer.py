"""C text of the thermometer's inverse, shared by the double and the float32 exports.

Horner evaluation of f(T) and its slope, the calibrated-range test and the
safeguarded Newton inverse T(f) started from a table (as
:meth:`hrgtc.thermometry.Thermometer.temperature`), in the C type of the export.
"""

from __future__ import annotations

__all__ = ["NEWTON_MAX_ITER", "thermometer_functions"]

#: Iteration cap of the thermometer inverse (as :meth:`Thermometer.temperature`).
NEWTON_MAX_ITER = 60


def thermometer_functions(*, p: str, n_th: int, above: str, real: str, fabs: str, half: str,
                          fn: str, arg: str) -> str:
    """The functions' C text.

    Parameters
    ----------
    p
        Prefix of the exported names.
    n_th
        Number of the thermometer's coefficients.
    above
        C test that the residual of f(t) is above the input (the bracket's side).
    real, fabs, half
        The C type, its absolute-value function and the literal 0.5 in that type.
    fn, arg
        Name of the exported f(T) function and of the frequency argument (``freq_hz``,
        or ``f_hz`` for the float32 export's centred frequency).
    """
    return f"""static {real} horner(const {real} *c, int n, {real} z)
{{
    {real} r = c[n - 1];
    int k;
    for (k = n - 2; k >= 0; --k) {{
        const {real} product = r * z;
        r = product + c[k];
    }}
    return r;
}}

{real} {fn}({real} temperature_c)
{{
    const {real} z = (temperature_c - TH_CENTRE_C) / TH_SCALE_C;
    return horner(TH_COEFFICIENTS, {n_th}, z);
}}

static {real} slope_hz_per_c({real} temperature_c)
{{
    const {real} z = (temperature_c - TH_CENTRE_C) / TH_SCALE_C;
    return horner(TH_DERIVATIVE, {n_th - 1}, z) / TH_SCALE_C;
}}

int {p}_frequency_in_range({real} {arg})
{{
    return {arg} >= TH_F_LOW_HZ && {arg} <= TH_F_HIGH_HZ;
}}

{real} {p}_temperature_c({real} {arg})
{{
    int low = 0;
    int high = TH_TABLE_POINTS - 1;
    int k;
    {real} t, lower, upper, t0, t1, f0, f1;
    if (!({arg} >= TH_TABLE_F[0] && {arg} <= TH_TABLE_F[TH_TABLE_POINTS - 1])) {{
        return NAN;  /* beyond the monotonic extension, or not a number */
    }}
    /* first table entry not below {arg} (numpy.searchsorted), at least the second */
    while (low < high) {{
        const int middle = low + (high - low) / 2;
        if (TH_TABLE_F[middle] < {arg}) {{ low = middle + 1; }} else {{ high = middle; }}
    }}
    low = low < 1 ? 1 : low;
    f0 = TH_TABLE_F[low - 1];
    f1 = TH_TABLE_F[low];
    t0 = TH_TABLE_T[low - 1];
    t1 = TH_TABLE_T[low];
    lower = t0 < t1 ? t0 : t1;
    upper = t0 < t1 ? t1 : t0;
    t = t0 + ({arg} - f0) * (t1 - t0) / (f1 - f0);
    t = t < lower ? lower : (t > upper ? upper : t);
    /* safeguarded Newton: keep the bracket, bisect when a step leaves it */
    for (k = 0; k < TH_MAX_ITER; ++k) {{
        const {real} residual = {fn}(t) - {arg};
        const {real} step = residual / slope_hz_per_c(t);
        {real} candidate = t - step;
        {real} change;
        if ({above}) {{ upper = t < upper ? t : upper; }} else {{ lower = t > lower ? t : lower; }}
        if (!(candidate >= lower && candidate <= upper)) {{ candidate = {half} * (lower + upper); }}
        change = {fabs}(candidate - t);
        t = candidate;
        if (!(change > TH_TOLERANCE_C)) {{ break; }}
    }}
    return t;
}}

"""
