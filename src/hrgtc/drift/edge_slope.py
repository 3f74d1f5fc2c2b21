"""The slope a drift model carries beyond its trained temperatures, and whether it is known.

Beyond the training range of the thermometer variable compensation continues the model
along its tangent at the edge (:func:`hrgtc.drift.features.tangent_extension`): a later run
colder or warmer than the training sees the slope ``∂B/∂f`` at the coldest or the hottest
trained point, times its distance from it. On one long run the terms beyond the line (f²,
f³, f·df, ...) are chosen by held-out blocks at the run's own ends
(:func:`hrgtc.drift.cross_validation.guard_selection`), which cannot tell whether that slope
carries on: a bend that wins on the coldest block may leave at the edge a slope whose sign
the data do not know, where the line's is known (the VN-100 file's x axis,
docs/real-loggers/corpus.md). :func:`unknown_edge_slope` is the test of that rule.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any, Protocol

import numpy as np

from hrgtc.drift.features import parse_terms
from hrgtc.drift.regression import newey_west_inflation

#: A slope is known when it lies this many standard errors (Newey-West) from zero.
EDGE_SLOPE_Z = 2.0


class Windows(Protocol):
    """What the rule reads of the training windows
    (:class:`hrgtc.drift.cross_validation.Windowed`).

    Attributes
    ----------
    x_scaled, bias_dph
        The design (a column per candidate, terms of the scaled variables, offsets
        projected off) and the bias of each window. [°/h]
    names
        The candidates' names (the columns' order).
    time_s
        Window centre times (the residuals' order for the inflation). [s]
    variables
        Window means of every variable the terms use. [Hz, Hz/s, ...]
    scales
        Each variable's scale (the design's columns are terms of ``value / scale``).
    """

    x_scaled: np.ndarray
    bias_dph: np.ndarray
    names: tuple[str, ...]
    time_s: np.ndarray | None
    variables: Mapping[str, np.ndarray] | None
    scales: Mapping[str, float] | None


def edge_slopes(data: Windows, terms: Sequence[str],
                variable: str = "f") -> list[tuple[float, float]]:
    """The model's slope in ``variable`` at the windows of its lowest and its highest value,
    with its standard error.

    The terms are fitted by OLS (with an intercept) on the windows; the slope at a window
    is ``sum_k β_k ∂term_k/∂variable`` there, its variance ``g' C g`` with ``C`` the
    coefficients' covariance, inflated for autocorrelated residuals (Newey-West, as the
    F-tests: :func:`hrgtc.drift.regression.newey_west_inflation`).

    Parameters
    ----------
    data
        The training windows (their ``variables`` and ``scales`` given).
    terms
        The terms of the model.
    variable
        The variable of the slope (the thermometer variable).

    Returns
    -------
    list of (slope, standard error)
        At the lowest and at the highest window of ``variable``. [°/h per unit of it]
    """
    bias_dph, variables, scales = data.bias_dph, data.variables or {}, data.scales or {}
    columns = [list(data.names).index(t) for t in terms]
    design = np.column_stack([np.ones(bias_dph.size), data.x_scaled[:, columns]])
    solution, *_ = np.linalg.lstsq(design, bias_dph, rcond=None)
    residual = bias_dph - design @ solution
    order = (np.arange(bias_dph.size) if data.time_s is None
             else np.argsort(data.time_s, kind="stable"))
    inflation, _ = newey_west_inflation(residual[order])
    dof = max(bias_dph.size - design.shape[1], 1)
    covariance = (inflation * float(residual @ residual) / dof
                  * np.linalg.pinv(design.T @ design))
    parsed = parse_terms(terms)
    out = []
    for window in (int(np.argmin(variables[variable])), int(np.argmax(variables[variable]))):
        point = {v: np.asarray(values[window:window + 1], dtype=np.float64) / scales[v]
                 for v, values in variables.items() if v in scales}
        gradient = np.zeros(design.shape[1])
        for k, term in enumerate(parsed, start=1):
            multiplier, rest = term.derivative(variable)
            if multiplier:
                value = 1.0 if rest is None else float(rest.evaluate(point)[0])
                gradient[k] = multiplier * value / scales[variable]
        slope = float(gradient @ solution)
        out.append((slope, math.sqrt(max(float(gradient @ covariance @ gradient), 0.0))))
    return out


def unknown_edge_slope(data: Windows, kept: Sequence[str],
                       parents: Mapping[str, Sequence[str]] | None = None,
                       keep: Sequence[str] = (), line: str = "f",
                       ) -> tuple[tuple[str, ...], dict[str, Any] | None]:
    """The rule of one long run: the terms in the thermometer variable beyond the line go
    when they leave the slope at an edge of the trained range unknown where the line's is
    known.

    The line's own slope (``line`` alone) must lie at least :data:`EDGE_SLOPE_Z` standard
    errors from zero; the kept model's slope at the coldest or the hottest window
    (:func:`edge_slopes`) within :data:`EDGE_SLOPE_Z` of it. Then every kept term of
    ``line``'s variable other than the line (f², f³, f·df, ...) goes, except the terms of
    ``keep`` (the user's starting model) and their parents; the terms in the other
    variables stay. Compensation would otherwise carry beyond that edge a slope of unknown
    sign where the line's sign is known.

    Returns
    -------
    terms, record
        The kept terms (candidate order) and, when the rule was tested, what it found
        (``line``, ``cold``, ``hot``: [slope, standard error]; ``dropped``); None when
        there was nothing to test (no term beyond the line, or the line's slope unknown).
    """
    variable = parse_terms([line])[0].variables[0]
    beyond = [t for t in kept if t != line
              and parse_terms([t])[0].power_of(variable) > 0]
    if line not in kept or not beyond or (data.variables or {}).get(variable) is None:
        return tuple(kept), None
    z = EDGE_SLOPE_Z
    (line_slope, line_error), _ = edge_slopes(data, [line], variable)
    if not abs(line_slope) >= z * line_error:
        return tuple(kept), None
    cold, hot = edge_slopes(data, kept, variable)
    record: dict[str, Any] = {"line": [line_slope, line_error], "cold": list(cold),
                              "hot": list(hot), "z": z, "dropped": []}
    if all(abs(slope) >= z * error for slope, error in (cold, hot)):
        return tuple(kept), record
    stays = set(keep)
    for name in list(stays):  # the user's terms keep their parents
        stays |= _ancestors(name, parents or {})
    record["dropped"] = [t for t in beyond if t not in stays]
    return tuple(t for t in kept if t not in record["dropped"]), record


def _ancestors(name: str, parents: Mapping[str, Sequence[str]]) -> set[str]:
    out: set[str] = set()
    stack = list(parents.get(name, ()))
    while stack:
        parent = stack.pop()
        if parent not in out:
            out.add(parent)
            stack.extend(parents.get(parent, ()))
    return out
