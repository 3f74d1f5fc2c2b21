"""An instrument's evaluation as figures: its axes side by side and its scale-factor check.

:func:`evaluation_tables` builds the :class:`~hrgtc.core.summary.Summary` of an
:class:`~hrgtc.evaluation.run_evaluation.RunEvaluation` (``hrgtc evaluate`` of a
multi-axis model or a rate-table run): each axis's 10 s bias stability raw and compensated,
the improvement, the compensated output's mean and RMS and the shares beyond the trained
ranges (the rows of ``--json``'s ``summary``), and each rate-table temperature's
scale-factor error raw → compensated (:func:`scale_check_figures`). The CLI prints them as
tables, the report as HTML; see docs/architecture.md ("One result contract").
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from hrgtc.core.summary import Figure, Summary

__all__ = ["SCALE_CHECKS", "evaluation_tables", "scale_check_figures", "stability_table"]

#: The heading of the scale-factor check's table.
SCALE_CHECKS = ("Scale-factor error (ppm) at each temperature of the rate table "
                "(slope of rate − Ω against Ω, IEEE Std 1431), raw → compensated")

#: (key of an axis_summary() row, column, spec, unit, definition) of the axes' table.
_AXIS_COLUMNS = (
    ("raw_10s_dph", "raw", ".4f", "°/h", "1σ of the 10 s means of the raw rate."),
    ("compensated_10s_dph", "compensated", ".4f", "°/h",
     "1σ of the 10 s means of the compensated rate."),
    ("improvement_10s", "improvement", ".2f", "×", "raw / compensated, at 10 s."),
    ("compensated_mean_dph", "comp. mean", "+.4g", "°/h", "Mean of the compensated rate."),
    ("compensated_rms_dph", "comp. RMS", ".4g", "°/h", "RMS of the compensated rate."),
    ("out_of_range_fraction", "beyond T", ".1%", "",
     "Share of the samples beyond the trained temperatures."),
    ("rate_out_of_range_fraction", "beyond df/dt", ".1%", "",
     "Share of the samples beyond the trained df/dt."),
)


def scale_check_figures(checks: Sequence[Any]) -> tuple[Figure, ...]:
    """Each temperature of each scale-factor check (``scale_checks[i]``) as a row: axis,
    frequency, holds, raw and compensated error [ppm]."""
    out: list[Figure] = []
    for i, check in enumerate(checks):
        rows = zip(check.freq_hz, check.holds, check.raw_ppm, check.compensated_ppm,
                   strict=True)
        for k, (freq, holds, raw, comp) in enumerate(rows):
            key, row, where = f"scale_checks[{i}]", f"{i}.{k}", f"at {freq:.4f} Hz"
            out += [Figure(f"{key}.axis[{k}]", f"axis {where}", check.axis or "-", row=row,
                           column="axis"),
                    Figure(f"{key}.freq_hz[{k}]", f"frequency {where}", float(freq), "Hz",
                           spec=".4f", row=row, column="frequency"),
                    Figure(f"{key}.holds[{k}]", f"holds {where}", int(holds), row=row,
                           column="holds"),
                    Figure(f"{key}.raw_ppm[{k}]", f"raw {where}", float(raw), "ppm",
                           spec="+.2f", row=row, column="raw",
                           definition="Slope of raw rate − Ω against Ω over the holds."),
                    Figure(f"{key}.compensated_ppm[{k}]", f"compensated {where}", float(comp),
                           "ppm", spec="+.2f", row=row, column="compensated",
                           definition="The same of the compensated rate.")]
    return tuple(out)


def evaluation_tables(result: Any) -> Summary:
    """The figures of an instrument's evaluation beside its axes' own: for several axes a
    table of the axes (``summary[k].<key>`` of ``--json``), and the scale-factor check of a
    rate-table run (:func:`scale_check_figures`)."""
    sections: list[tuple[str, tuple[Figure, ...]]] = []
    if list(result.axes) != [""]:  # several axes, or one chosen of several
        cells: list[Figure] = []
        for k, row in enumerate(result.axis_summary()):
            cells.append(Figure(f"summary[{k}].axis", f"axis {row['axis']}", str(row["axis"]),
                                row=str(k), column="axis"))
            cells += [Figure(f"summary[{k}].{key}", f"axis {row['axis']}: {column}",
                             float(row[key]), unit, spec=spec, row=str(k), column=column,
                             definition=definition)
                      for key, column, spec, unit, definition in _AXIS_COLUMNS]
        sections.append((f"{result.model.unit}: 10 s bias stability per axis", tuple(cells)))
    if result.scale_checks:
        sections.append((SCALE_CHECKS, scale_check_figures(result.scale_checks)))
    return Summary("", tuple(sections))


def stability_table(runs: Sequence[tuple[str, Any]], paper_row: bool = True) -> Summary:
    """10 s bias stability raw → compensated of each (label, evaluation), after the paper's
    Section 4.2 figures (``paper_row``): what ``hrgtc demo`` prints at its end."""
    from hrgtc.thermometry import paper

    rows: list[tuple[str, str, float, float, float]] = []
    if paper_row:
        raw, comp = paper.BIAS_STABILITY_RAW_DPH, paper.BIAS_STABILITY_COMPENSATED_DPH
        rows.append(("paper", "paper (Section 4.2, cool-down, fitted on itself)", raw, comp,
                     raw / comp))
    rows += [(f"runs[{k}]", label, ev.raw_10s, ev.compensated_10s, ev.improvement_10s)
             for k, (label, ev) in enumerate(runs)]
    cells: list[Figure] = []
    for key, label, raw, comp, ratio in rows:
        cells += [Figure(f"{key}.label", "run", label, row=key, column="run"),
                  Figure(f"{key}.raw_10s_dph", f"{label}: raw", raw, "°/h", spec=".4f",
                         row=key, column="raw",
                         definition="1σ of the 10 s means of the raw rate."),
                  Figure(f"{key}.compensated_10s_dph", f"{label}: compensated", comp, "°/h",
                         spec=".4f", row=key, column="compensated",
                         definition="1σ of the 10 s means of the compensated rate."),
                  Figure(f"{key}.improvement_10s", f"{label}: improvement", ratio, "×",
                         spec=".2f", row=key, column="improvement",
                         definition="raw / compensated.")]
    return Summary("", (("10 s bias stability, raw → compensated", tuple(cells)),))
