"""``play``: a play (backlash) operator on the thermometer's temperature, minus that temperature.

``play = p - T``, with ``T`` the thermometer's temperature T(freq_hz) and
``p[k] = min(max(p[k-1], T[k] - w/2), T[k] + w/2)``: a rate-independent memory of the way
the temperature came (a soak settled after coming down reads ``+w/2``, after coming up
``-w/2``), which no function of f and its rates can give (docs/history.md). ``w`` is
``play_width_c`` (``--play-width-c``; :func:`learn_width` picks it from a grid by
leave-one-run-out).

**Power-on rule.** The history before a run is unknown: the state starts at the run's
first temperature (``p = T``, so ``play = 0``), and again at each restart row (a segment
of ``--gaps split``). The play operator moves two states no further apart
(``|p_a[k] - p_b[k]| <= |p_a[k-1] - p_b[k-1]|``), so whatever the true state at power-on
(any ``p`` within ``T ± w/2``), the variable is never more than ``w/2`` from the one that
history would give, and equal to it once the temperature has moved by ``w`` one way: a
term ``s·play`` is then off by at most ``|s| w/2`` and only at the start of a run.

Causal and chunk-invariant: the state is carried by the stream (``Inputs.memory``).
The numpy reference only: the fused kernel hands such a model to numpy and the exports
refuse it (docs/architecture.md, "Adding a drift variable").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.drift.variables.spec import DriftVariable, Inputs

#: w when ``--play-width-c`` is not given. [°C]
DEFAULT_WIDTH_C = 2.0
#: The grid :func:`learn_width` judges by default. [°C]
WIDTHS_C = (0.5, 1.0, 2.0, 4.0, 8.0)
_STATE = "play"


def play_lag(temperature_c: np.ndarray, width_c: float, state: float = math.nan,
             restart: np.ndarray | None = None) -> tuple[np.ndarray, float]:
    """``p - T`` of the play of width ``w`` over a chunk, and the state after it.

    Parameters
    ----------
    temperature_c
        The thermometer's temperature. [°C]
    width_c
        w. [°C]
    state
        The play's output before the chunk; NaN at power-on (the rule of the module). [°C]
    restart
        Boolean mask of rows where the state starts again at the temperature, or None.

    Returns
    -------
    values, state : numpy.ndarray, float
        [°C], [°C]

    Examples
    --------
    >>> values, last = play_lag(np.array([20.0, 21.5, 22.0, 21.0, 19.0]), 2.0)
    >>> values.tolist(), last
    ([0.0, -1.0, -1.0, 0.0, 1.0], 20.0)
    """
    from hrgtc.drift.variables._play_kernel import play_run  # compiled on first use

    x = np.ascontiguousarray(temperature_c, dtype=np.float64)
    mask = (np.zeros(0, dtype=np.bool_) if restart is None
            else np.ascontiguousarray(restart, dtype=np.bool_))
    out = np.empty_like(x)
    last = play_run(x, 0.5 * float(width_c), mask, float(state), out)
    return out, float(last)


def compute(inputs: Inputs, name: str) -> np.ndarray:
    """play = p - T(freq_hz), the state carried across chunks. [°C]"""
    temperature = inputs.thermometer.temperature(inputs.chunk["freq_hz"], warn=False)
    values, inputs.memory[_STATE] = play_lag(temperature, inputs.settings.play_width_c,
                                             inputs.memory.get(_STATE, math.nan),
                                             inputs.restart)
    return values


def check(settings: Any, thermometer: Any, name: str) -> str | None:
    if thermometer is None:
        return "the variable play needs the unit's thermometer for T(freq_hz)"
    if not settings.play_width_c > 0.0:
        return ("the variable play needs play_width_c > 0 in the feature settings "
                "(--play-width-c)")
    return None


def derive(names: tuple[str, ...], given: Mapping[str, Any]) -> dict[str, Any]:
    """w: ``--play-width-c``, else :data:`DEFAULT_WIDTH_C`. [°C]"""
    value = given["play_width_c"]
    return {"play_width_c": DEFAULT_WIDTH_C if value is None else float(value)}


def learn_width(score: Callable[[float], float], widths: Sequence[float] = WIDTHS_C
                ) -> tuple[float, dict[float, float]]:
    """The width whose fit scores lowest, and every width's score.

    Parameters
    ----------
    score
        ``score(width_c)``: the leave-one-run-out figure of a fit with that width (e.g.
        ``model.drift.cross_validation.score_dph`` of ``calibrate`` with
        ``play_width_c=width_c``, :class:`hrgtc.drift.cross_validation.CrossValidation`).
    widths
        The grid. [°C]

    Examples
    --------
    >>> learn_width(lambda w: (w - 2.0) ** 2, (1.0, 2.0, 4.0))
    (2.0, {1.0: 1.0, 2.0: 0.0, 4.0: 4.0})
    """
    grid = [float(w) for w in widths]
    if not grid or not all(math.isfinite(w) and w > 0.0 for w in grid):
        raise InputError(f"widths must be finite and > 0 [°C], got {widths!r}")
    scores = {w: float(score(w)) for w in grid}
    finite = {w: s for w, s in scores.items() if math.isfinite(s)}
    if not finite:
        raise InputError(f"no width of {grid} gave a finite leave-one-run-out score")
    return min(finite, key=finite.__getitem__), scores


VARIABLE = DriftVariable(
    name="play", unit="°C", sensor_unit="°C", kind="level",
    description="play (backlash) operator of width play_width_c on the thermometer's "
                "temperature, minus that temperature (state from the first sample)",
    backends=frozenset({"numpy"}), columns=("freq_hz",), compute=compute, order=8,
    check=check, settings_fields=(("play_width_c", records.NonNegative, 0.0),),
    derive=derive, omit_default_settings=True)
