"""Lag or hysteresis (issue 29, item 1): the experiment of :mod:`hrgtc.simulate.history`.

On ``unit-b`` (its heating/cooling term is ``h tanh(G/G_h)`` of the gradient: no memory),
on ``unit-play`` (a true play memory, the play of :class:`hrgtc.simulate.laws.BiasLaw`) and on
``unit-b`` without its tanh term (a pure lag): the heating - cooling split of the bias at
20 °C for ramps of 1 ... 0.01 °C/min (and its line to rate 0), and the settled bias after
approaching 20 °C from 30 °C and from 10 °C. One JSON line per unit (docs/history.md).
"""

from __future__ import annotations

import json
import time
from dataclasses import replace


def run(quick: bool = False) -> list[dict]:
    from hrgtc.simulate import units
    from hrgtc.simulate.history import HistoryExperiment, classify

    base = units.get("unit-b")
    lag = replace(base, name="unit-b-lag-only",
                  bias_law=replace(base.bias_law, hysteresis_dph=0.0))
    experiment = HistoryExperiment(rates_c_per_min=(1.0, 0.1, 0.01) if quick
                                   else (1.0, 0.3, 0.1, 0.03, 0.01))
    lines = []
    for unit in ("unit-b", "unit-play", lag):
        start = time.perf_counter()
        verdict = classify(unit, experiment).to_dict()
        seconds = time.perf_counter() - start
        line = {"name": f"history_{verdict['unit']}", "n": len(verdict["rates_c_per_min"]),
                "seconds": round(seconds, 2), "rate": round(1.0 / seconds, 3)}
        for key, value in verdict.items():
            line[key] = ([round(v, 4) for v in value] if isinstance(value, list)
                         else round(value, 9) if isinstance(value, float) else value)
        lines.append(line)
    return lines


if __name__ == "__main__":
    import sys

    for line in run(quick="--quick" in sys.argv):
        print(json.dumps(line))
