"""Student's t tail, the p-values of the regressions, without importing ``scipy.stats``.

``scipy.stats`` takes a second or more to import (it parses the docstrings of every
distribution); the p-values of :mod:`hrgtc.drift` and :mod:`hrgtc.thermometry` need one
function of it. :func:`t_sf` is ``scipy.stats.t.sf(x, df)`` (location 0, scale 1) value for
value: ``scipy.special.stdtr(df, -x)`` where ``scipy.stats`` calls it, and its answers
elsewhere (NaN for a NaN ``x`` or ``df <= 0``, 1 at ``x = -inf``, 0 at ``x = +inf``);
``tests/core/test_student_t.py`` compares the two bit for bit.
"""

from __future__ import annotations

from typing import Any

import numpy as np


def t_sf(x: Any, df: Any) -> Any:
    """Survival function ``P(T > x)`` of Student's t with ``df`` degrees of freedom.

    Parameters
    ----------
    x
        The statistic (a number or an array).
    df
        Degrees of freedom (a number or an array broadcast with ``x``); NaN where not > 0.

    Returns
    -------
    float or numpy.ndarray
        A numpy scalar for scalar input, else an array of the broadcast shape.

    Examples
    --------
    >>> float(t_sf(0.0, 5))
    0.5
    """
    from scipy.special import stdtr  # imported on first use: a faster start

    x = np.asarray(x)
    x = np.asarray(x, dtype=np.promote_types(x.dtype, np.float64))
    x, df = np.broadcast_arrays(x, np.asarray(df))
    valid = df > 0
    inside = (-np.inf < x) & (x < np.inf)
    out = np.zeros(x.shape, x.dtype)
    out[~valid | np.isnan(x)] = np.nan
    out[valid & (x <= -np.inf)] = 1.0
    good = valid & inside
    if np.any(good):
        out[good] = stdtr(df[good], -x[good])
    return out[()] if out.ndim == 0 else out
