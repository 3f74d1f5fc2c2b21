"""C text of the causal df/dt filter on the time axis, for the double and float32 exports.

The generated ``step()`` takes the time since the previous sample, ``dt_s``, and
advances each filter by the exact first-order-hold update over that step
(:mod:`hrgtc.drift.rate_filter`): the statements below are those of
:func:`hrgtc.drift._rate_numba.filter_run`, one operation per statement so no
fused multiply-add changes the rounding. A gap is bridged by passing the gap's Δt;
``reset()`` restarts the filters at rest (a new run, or a segment start of
``--gaps split``).

The weights a = 1 - exp(-r), p = 1 - a/r (r = Δt/tau) are computed in double in
both builds (``expm1`` and a 9-term Taylor series for small r), only when Δt moves
by more than :data:`~hrgtc.drift.rate_filter.DT_REL_TOLERANCE` of itself, and kept
in the filter's struct; the float32 build rounds them to float once and keeps the
filter as differences with compensated (Kahan) sums, as before.
"""

from __future__ import annotations

from hrgtc.drift.rate_filter import DT_REL_TOLERANCE, SERIES_LIMIT, series_coefficients
from hrgtc.export.c.types import DOUBLE, SINGLE

__all__ = ["filter_functions", "filter_struct"]


def filter_struct(p: str, single: bool) -> str:
    """``typedef struct {p}_rate_filter``: one filter's state (per filtered input)."""
    if single:
        return f"""/* One causal rate filter (two first-order stages y1, y2 of an input x), kept as
   differences with compensated sums; the weights of its last step are cached. */
typedef struct {p}_rate_filter {{
    float previous;             /* x at the previous sample */
    float lag;                  /* previous x - y1 */
    float lag_carry;            /* what its float sums rounded off */
    float difference;           /* y1 - y2 */
    float difference_carry;     /* what its float sums rounded off */
    float dt;                   /* step of the cached weights [s] (-1: none yet) */
    float a, p;                 /* the weights 1 - exp(-dt/tau), 1 - a tau/dt */
}} {p}_rate_filter;
"""
    return f"""/* One causal rate filter (two first-order stages y1, y2 of an input x), kept as
   differences; the weights of its last step are cached. */
typedef struct {p}_rate_filter {{
    double previous;            /* x at the previous sample */
    double lag;                 /* previous x - y1 */
    double difference;          /* y1 - y2 */
    double dt;                  /* step of the cached weights [s] (-1: none yet) */
    double a, p;                /* the weights 1 - exp(-dt/tau), 1 - a tau/dt */
}} {p}_rate_filter;
"""


def _weights() -> str:
    series = ", ".join(DOUBLE.literal(c, f"series[{k}]")
                       for k, c in enumerate(series_coefficients()))
    return f"""/* Taylor series of p(r) = 1 - (1 - exp(-r))/r = sum_k RATE_SERIES[k] r^(k+1),
   used below r = RATE_SERIES_LIMIT where the direct formula cancels. */
static const double RATE_SERIES[{len(series_coefficients())}] = {{{series}}};
static const double RATE_SERIES_LIMIT = {DOUBLE.literal(SERIES_LIMIT, "series_limit")};

/* Weights of one step of dt seconds through a first-order lag of time constant tau,
   exact for an input moving linearly over the step: y += a (x_prev - y) + p (x - x_prev). */
static void rate_weights(double dt, double tau, double *a, double *p)
{{
    const double r = dt / tau;
    double q;
    int k;
    *a = -expm1(-r);
    if (r < RATE_SERIES_LIMIT) {{
        q = RATE_SERIES[{len(series_coefficients()) - 1}];
        for (k = {len(series_coefficients()) - 2}; k >= 0; --k) {{
            q = q * r;
            q = q + RATE_SERIES[k];
        }}
        *p = q * r;
    }} else {{
        *p = (r - *a) / r;
    }}
}}
"""


def filter_functions(p: str, single: bool) -> str:
    """``rate_weights``, ``rate_start`` and ``rate_update`` of the ``.c`` file."""
    if single:
        tolerance = SINGLE.literal(DT_REL_TOLERANCE, "dt_tolerance")
        return f"""{_weights()}
/* A step whose dt is within this share of the cached one reuses its weights. */
static const float RATE_DT_TOLERANCE = {tolerance};

/* The filter at rest on x (rate 0). */
static void rate_start({p}_rate_filter *s, float x)
{{
    s->previous = x;
    s->lag = 0.0f;
    s->lag_carry = 0.0f;
    s->difference = 0.0f;
    s->difference_carry = 0.0f;
    s->dt = -1.0f;
    s->a = 0.0f;
    s->p = 0.0f;
}}

/* One step of dt seconds to input x; returns the rate (y1 - y2) / tau. Each difference is
   updated by a small increment; compensated (Kahan) summation keeps what the float sum
   rounds off in a carry, so the state does not drift by rounding. */
static float rate_update({p}_rate_filter *s, float x, float dt, double tau_d, float tau)
{{
    float delta, c1, c2, t, increment, sum;
    if (!(dt > 0.0f)) {{
        dt = 0.0f;
    }}
    if (!(fabsf(dt - s->dt) <= RATE_DT_TOLERANCE * s->dt)) {{
        double a, p;
        rate_weights((double)dt, tau_d, &a, &p);
        s->a = (float)a;
        s->p = (float)p;
        s->dt = dt;
    }}
    delta = x - s->previous;
    s->previous = x;
    c1 = s->a * s->lag;
    t = s->p * delta;
    c1 = c1 + t;                /* the change of y1 */
    increment = delta - c1;     /* the change of previous x - y1 */
    increment = increment - s->lag_carry;
    sum = s->lag + increment;
    s->lag_carry = (sum - s->lag) - increment;
    s->lag = sum;
    c2 = s->a * s->difference;
    t = s->p * c1;
    c2 = c2 + t;                /* the change of y2 */
    increment = c1 - c2;        /* the change of y1 - y2 */
    increment = increment - s->difference_carry;
    sum = s->difference + increment;
    s->difference_carry = (sum - s->difference) - increment;
    s->difference = sum;
    return s->difference / tau;
}}
"""
    tolerance = DOUBLE.literal(DT_REL_TOLERANCE, "dt_tolerance")
    return f"""{_weights()}
/* A step whose dt is within this share of the cached one reuses its weights. */
static const double RATE_DT_TOLERANCE = {tolerance};

/* The filter at rest on x (rate 0). */
static void rate_start({p}_rate_filter *s, double x)
{{
    s->previous = x;
    s->lag = 0.0;
    s->difference = 0.0;
    s->dt = -1.0;
    s->a = 0.0;
    s->p = 0.0;
}}

/* One step of dt seconds to input x; returns the rate (y1 - y2) / tau. */
static double rate_update({p}_rate_filter *s, double x, double dt, double tau)
{{
    double delta, c1, c2, t;
    if (!(dt > 0.0)) {{
        dt = 0.0;
    }}
    if (!(fabs(dt - s->dt) <= RATE_DT_TOLERANCE * s->dt)) {{
        rate_weights(dt, tau, &s->a, &s->p);
        s->dt = dt;
    }}
    delta = x - s->previous;
    c1 = s->a * s->lag;
    t = s->p * delta;
    c1 = c1 + t;                /* the change of y1 */
    t = s->lag + delta;
    s->lag = t - c1;            /* previous x - y1 */
    c2 = s->a * s->difference;
    t = s->p * c1;
    c2 = c2 + t;                /* the change of y2 */
    t = s->difference + c1;
    s->difference = t - c2;     /* y1 - y2 */
    s->previous = x;
    return s->difference / tau;
}}
"""
