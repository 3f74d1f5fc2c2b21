"""Runs at a glance: each run's 10 s bias stability raw and compensated, as table cells.

The report's "At a glance" tables (a unit's, beside the paper's Section 4.2, and an
instrument's, one row per axis and run with its scale-factor fit) are a
:class:`~hrgtc.core.summary.Summary` of one grid section, built from each run's own figures
(:meth:`hrgtc.evaluation.Evaluation.figures`), so the glance shows what the run's tables show.
See docs/architecture.md ("One result contract").
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

from hrgtc.core.summary import Figure, Summary
from hrgtc.thermometry import paper

__all__ = ["GLANCE", "glance_summary", "instrument_glance_summary"]

#: The heading of the glance's one section.
GLANCE = "at a glance: 10 s bias stability"

#: (place in a run's figures, column) of the glance, in order.
_COLUMNS = (("bias_stability_dph.raw.10", "raw"),
            ("bias_stability_dph.compensated.10", "compensated"),
            ("improvement_10s", "improvement"),
            ("bias_stability_dph.housing.10", "housing baseline"),
            ("share", "outside calibrated range"),
            ("mean_dph.compensated", "compensated mean"),
            ("rms_dph.compensated", "compensated RMS"))
_UNITS = {"raw": "°/h", "compensated": "°/h", "improvement": "×", "housing baseline": "°/h",
          "compensated mean": "°/h", "compensated RMS": "°/h"}


def _run_cells(run: Any, key: str, row: str, columns: Sequence[str]) -> list[Figure]:
    """A run's cells in ``columns``, copied from its figures (NaN where it has none)."""
    figures = run.figures(warnings=False).figures()
    share = ("ranges.temperature_fraction" if run.ranges is not None  # not other variables'
             else "out_of_range_fraction")
    cells = [Figure(f"{key}.name", f"{run.name}, run", run.name, row=row, column="run")]
    for place, column in _COLUMNS:
        if column not in columns:
            continue
        place = share if place == "share" else place
        found = figures.get(f"evaluation.{place}")
        label = f"{run.name}, {column}"
        if found is None or not isinstance(found.value, float | int):
            found = Figure("", "", math.nan, _UNITS.get(column, ""))
        cells.append(dataclasses.replace(
            found, name=f"{key}.{place}", label=label, unit=_UNITS.get(column, ""),
            interval=None, interval_kind="", row=row, column=column,
            spec=".1%" if column == "outside calibrated range" else found.spec))
    return cells


def glance_summary(runs: Sequence[Any], paper_row: bool = True) -> Summary:
    """A unit's runs at a glance: one row per :class:`~hrgtc.evaluation.Evaluation` (its
    10 s bias stability raw, compensated and with the housing baseline, the improvement, the
    share beyond the calibrated temperatures, the compensated mean and RMS; ``runs[i]`` and
    the place of each figure in ``Evaluation.to_dict()``), then (``paper_row``) the paper's
    cool-down (Section 4.2 of [1])."""
    columns = [column for _, column in _COLUMNS]
    cells: list[Figure] = []
    for i, run in enumerate(runs):
        cells += _run_cells(run, f"runs[{i}]", str(i), columns)
    if paper_row and runs:
        raw, comp = paper.BIAS_STABILITY_RAW_DPH, paper.BIAS_STABILITY_COMPENSATED_DPH
        name = "paper [1], Section 4.2 (its cool-down)"
        values = {"raw": (raw, 5), "compensated": (comp, 4), "improvement": (raw / comp, 3)}
        cells.append(Figure("paper.name", f"{name}, run", name, row="paper", column="run"))
        for column in columns:
            value, digits = values.get(column, (math.nan, 6))
            cells.append(Figure(f"paper.{column}", f"{name}, {column}", value,
                                _UNITS.get(column, ""), digits=digits, row="paper",
                                column=column))
    return Summary("runs at a glance", ((GLANCE, tuple(cells)),) if cells else ())


def instrument_glance_summary(model: Any, runs: Mapping[str, Sequence[Any]]) -> Summary:
    """An instrument's runs at a glance: one row per axis and run (``axes.<axis>.runs[i]``)
    as :func:`glance_summary` without the housing baseline, with each axis's scale-factor
    fit residual (``axes.<axis>.scale_factor.residual_ppm``); an axis without runs has a
    row of its own. ``model``: the :class:`~hrgtc.model.Model`."""
    columns = [column for _, column in _COLUMNS if column != "housing baseline"]
    cells: list[Figure] = []
    for axis, found in runs.items():
        sf = model.axes[axis].scale_factor
        key = f"axes.{axis or '-'}"
        scale = Figure("scale_factor.residual_ppm", "", math.nan if sf is None
                       else sf.residual_ppm, "ppm RMS", digits=3,
                       column="scale-factor fit residual")
        rows = [(f"{key}.runs[{i}]", f"{axis}/{i}", _run_cells(run, f"{key}.runs[{i}]",
                                                               f"{axis}/{i}", columns))
                for i, run in enumerate(found)]
        if not rows:
            rows = [(key, axis, [Figure(f"{key}.name", "", "–", row=axis, column="run")]
                     + [Figure(f"{key}.{c}", "", math.nan, _UNITS.get(c, ""), row=axis,
                               column=c) for c in columns])]
        for row_key, row, row_cells in rows:
            name = row_cells[0].value
            axis_cell = Figure(f"{row_key}.axis", f"{axis}, {name}, axis", axis, row=row,
                               column="axis")
            labelled = [dataclasses.replace(c, label=f"{axis}, {name}, {c.column}")
                        for c in row_cells]
            at = [c.column for c in labelled].index("outside calibrated range") + 1
            cells += [axis_cell, *labelled[:at],
                      dataclasses.replace(scale, name=f"{row_key}.{scale.name}",
                                          label=f"{axis}, {name}, {scale.column}", row=row),
                      *labelled[at:]]
    return Summary(f"instrument {model.unit}: runs at a glance",
                   ((GLANCE, tuple(cells)),) if cells else ())
