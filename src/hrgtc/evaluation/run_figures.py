"""An evaluated run's figures as a structured summary (:class:`hrgtc.core.summary.Summary`).

Each bias stability with its chi-squared confidence interval and block count, the mean and
RMS of each series, the Allan noise terms, the improvement at 10 s, the shares beyond the
trained ranges, heating and cooling apart, and the samples read and left out: the one
structure the plain text (:meth:`Evaluation.summary`), the CLI's rich tables and the HTML
report render. A figure's name after its prefix is its place in
:meth:`Evaluation.to_dict` (``bias_stability_dph.raw.10`` is
``to_dict()["bias_stability_dph"]["raw"]["10"]``), so the ``--json`` document holds the
same value (``tests/evaluation/test_run_figures.py``).
"""

from __future__ import annotations

import math
from typing import Any

from hrgtc.core.accounting import REASONS
from hrgtc.core.summary import Figure, Summary

__all__ = ["NOISE_TERMS", "run_figures", "series_label"]

#: The Allan noise terms: (field of NoiseTerms, key of ``text``, label, unit).
NOISE_TERMS = (("arw_deg_per_rt_h", "arw", "ARW", "°/√h"),
               ("bias_instability_dph", "bias_instability", "bias instability", "°/h"),
               ("rrw_dph_per_rt_h", "rrw", "RRW", "°/h/√h"))


def series_label(series: str, sensor: bool = False) -> str:
    """What a reader calls an output series (``sensor``: the thermometer is a temperature
    sensor, not the resonator's frequency)."""
    return {"raw": "raw",
            "compensated": ("compensated (temperature sensor)" if sensor
                            else "compensated (frequency, Eq. 22)"),
            "housing": "compensated (housing thermistor)"}.get(series, series)


def run_figures(run: Any, key: str = "evaluation", sensor: bool = False,
                warnings: bool = True) -> Summary:
    """The figures of one evaluated run (an :class:`hrgtc.evaluation.Evaluation`; not
    imported here, which would close a circle); ``key`` prefixes every figure's name.

    ``sensor``: label the compensated series as a temperature sensor's; ``warnings``:
    the range warnings among the notes (the CLI prints them apart, on stderr with
    ``--json``).
    """
    sections = [("bias stability (1σ of τ-second means)", _stability(run, key, sensor)),
                ("offset and spread the bias stability does not show", _level(run, key, sensor))]
    if run.noise:
        sections.append(("Allan noise terms (IEEE Std 952)", _noise(run, key, sensor)))
    sections.append(("model", _model(run, key)))
    if run.directions is not None:
        what = "temperature" if sensor else "resonator temperature"
        sections.append((f"heating and cooling apart (sign of the {what} rate)",
                         _directions(run.directions, f"{key}.heating_cooling")))
    if run.accounting is not None:
        sections.append(("samples", _accounting(run.accounting, f"{key}.accounting")))
    notes = (tuple(run.range_warnings()) if warnings else ()) + tuple(run.notes)
    if run.accounting is not None and run.accounting.warning:
        notes += (f"warning: {run.accounting.warning}",)
    return Summary(f"{run.file}: {run.n_samples} samples at {run.sample_rate_hz:g} Hz",
                   tuple(sections), notes)


def _interval_kind(confidence: float, count: int | None) -> str:
    kind = f"{confidence:.1%} CI"
    return kind if count is None else f"{kind}, N {count}"


def _stability(run: Any, key: str, sensor: bool) -> tuple[Figure, ...]:
    return tuple(
        Figure(f"{key}.bias_stability_dph.{series}.{tau_s:g}",
               f"{series_label(series, sensor)}, τ = {tau_s:g} s", value, "°/h",
               run.stability_interval(series, tau_s),
               _interval_kind(run.confidence,
                              run.bias_stability_blocks.get(series, {}).get(float(tau_s))),
               digits=4)
        for series, row in run.bias_stability_dph.items() for tau_s, value in row.items())


def _level(run: Any, key: str, sensor: bool) -> tuple[Figure, ...]:
    return tuple(
        figure for series in run.bias_stability_dph if series in run.mean_dph for figure in (
            Figure(f"{key}.mean_dph.{series}", f"{series_label(series, sensor)} mean",
                   run.mean_dph[series], "°/h", digits=4),
            Figure(f"{key}.rms_dph.{series}", f"{series_label(series, sensor)} RMS",
                   run.rms_dph.get(series, math.nan), "°/h", digits=4)))


def _noise(run: Any, key: str, sensor: bool) -> tuple[Figure, ...]:
    figures = []
    for series, terms in run.noise.items():
        for field, term, label, unit in NOISE_TERMS:
            value = getattr(terms, field)
            name, text = f"{key}.allan.{series}.{field}", f"{series_label(series, sensor)} {label}"
            if value is None:  # the reason it is missing, in its place
                figures.append(Figure(name, text, getattr(terms, f"{term}_reason") or "n/a"))
                continue
            interval = getattr(terms, f"{term}_interval")
            figures.append(Figure(name, text, float(value), unit, interval,
                                  _interval_kind(run.confidence, getattr(terms, f"{term}_n"))
                                  if interval is not None else "", digits=4))
    return tuple(figures)


def _model(run: Any, key: str) -> tuple[Figure, ...]:
    figures = [Figure(f"{key}.improvement_10s", "improvement at 10 s", run.improvement_10s, "×",
                      digits=3),
               Figure(f"{key}.out_of_range_fraction",
                      "share beyond the calibrated temperatures or a level variable's range",
                      run.out_of_range_fraction, digits=3),
               Figure(f"{key}.rate_out_of_range_fraction", "share with df/dt beyond its "
                      "training range", run.rate_out_of_range_fraction, digits=3)]
    if run.ranges is not None:  # one share per variable: a gradient is not a temperature
        figures.append(Figure(f"{key}.ranges.temperature_fraction",
                              "share of samples with the temperature out of its trained range",
                              run.ranges.temperature_fraction, digits=3))
        figures += [Figure(f"{key}.ranges.variables[{k}].fraction",
                           f"share beyond the trained range of {v.name}", v.fraction, digits=3)
                    for k, v in enumerate(run.ranges.variables)]
    std = run.prediction_std_dph
    if std is not None:
        figures += [Figure(f"{key}.prediction_std_dph.{which}",
                           f"1σ of the drift model line (coefficient covariance), {which}",
                           std[which], "°/h", digits=4) for which in ("median", "max")]
    if run.residual_rms_dph is not None:
        figures.append(Figure(f"{key}.residual_rms_dph", "RMS of true bias minus model",
                              run.residual_rms_dph, "°/h", digits=4))
    if run.n_not_at_rest:
        figures.append(Figure(f"{key}.n_not_at_rest",
                              "samples not at rest left out of the figures", run.n_not_at_rest))
    return tuple(figures)


def _directions(directions: Any, key: str) -> tuple[Figure, ...]:
    figures = []
    for d in ("heating", "cooling"):
        figures += [Figure(f"{key}.{d}.blocks", f"{d}: {directions.block_s:g} s blocks",
                           directions.blocks[d]),
                    Figure(f"{key}.{d}.raw_dph", f"{d}: bias stability raw",
                           directions.raw_dph[d], "°/h", digits=4),
                    Figure(f"{key}.{d}.compensated_dph", f"{d}: bias stability compensated",
                           directions.compensated_dph[d], "°/h", digits=4),
                    Figure(f"{key}.{d}.improvement", f"{d}: improvement",
                           directions.improvement(d), "×", digits=3)]
        if directions.residual_rms_dph is not None:
            figures.append(Figure(f"{key}.{d}.residual_rms_dph", f"{d}: RMS model - true bias",
                                  directions.residual_rms_dph[d], "°/h", digits=4))
    return tuple(figures)


def _accounting(accounting: Any, key: str) -> tuple[Figure, ...]:
    figures = [Figure(f"{key}.read", "read", accounting.read),
               Figure(f"{key}.used", "used", accounting.used)]
    for kind in ("dropped", "flagged"):
        figures += [Figure(f"{key}.{kind}.{reason}", f"{kind}: {REASONS.get(reason, reason)}",
                           count) for reason, count in getattr(accounting, kind).items()]
    return tuple(figures)
