"""The constants of the rate filter's step weights (:mod:`hrgtc.drift.rate_filter`).

One step of Δt through a first-order lag of time constant tau has the weights
a = 1 - exp(-r) and p = 1 - a/r (r = Δt/tau). Below :data:`SERIES_LIMIT`, p comes from
its Taylor series (the direct formula cancels), and a step whose Δt is within
:data:`DT_REL_TOLERANCE` of the previous one reuses its weights. The numpy path, the
compiled kernel and the C export all take these numbers from here.
"""

from __future__ import annotations

import math

#: Below this r = Δt/tau the weight p comes from its Taylor series.
SERIES_LIMIT = 0.1
#: Terms of that series (the first neglected one is below 1e-16 of p at SERIES_LIMIT).
SERIES_TERMS = 9
#: A step whose Δt is within this share of the last one reuses its weights.
DT_REL_TOLERANCE = 1e-6


def series_coefficients() -> tuple[float, ...]:
    """(-1)^(k+1) / (k+1)! for k = 1..SERIES_TERMS: p(r) = sum_k c_k r^k."""
    return tuple((-1.0) ** (k + 1) / math.factorial(k + 1) for k in range(1, SERIES_TERMS + 1))
