"""Resolution of a logged channel: the smallest step between its distinct values.

A rate logged to three significant figures in rad/s (``-6.53E-02``) moves in steps
of 10^-4 rad/s below 0.1 rad/s, about 20.6 °/h; a temperature logged as a raw count
moves in steps of one count. ``info`` shows it per channel, and the spike filter
(:mod:`hrgtc.recording.spikes`) never sets its threshold below a few of these steps,
so a quantised or pulse-type stream (MAD = 0) keeps its pulses.
"""

from __future__ import annotations

import numpy as np

__all__ = ["resolution"]

#: Steps smaller than this fraction of the largest magnitude are floating-point noise
#: of a unit conversion (e.g. ×648000/π), not steps of the logger.
FLOAT_NOISE = 1e-9


def resolution(values: np.ndarray) -> float | None:
    """Smallest step between distinct finite values, in the values' unit.

    Steps below :data:`FLOAT_NOISE` × the largest magnitude (the rounding of a unit
    conversion) are not steps. None for fewer than two distinct values.

    Examples
    --------
    >>> float(resolution(np.array([-0.0653, -0.0645, -0.0648, -0.0653])))  # doctest: +ELLIPSIS
    0.000299999...
    """
    finite = np.asarray(values, dtype=np.float64)
    finite = finite[np.isfinite(finite)]
    if finite.size < 2:
        return None
    distinct = np.unique(finite)
    if distinct.size < 2:
        return None
    steps = np.diff(distinct)
    floor = FLOAT_NOISE * float(np.max(np.abs(distinct)))
    steps = steps[steps > floor]
    return float(steps.min()) if steps.size else None
