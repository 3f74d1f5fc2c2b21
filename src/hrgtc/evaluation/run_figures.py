"""An evaluated run's figures as a structured summary (:class:`hrgtc.core.summary.Summary`).

Each bias stability with its chi-squared confidence interval, the mean and RMS of each
series, the improvement at 10 s and the shares beyond the trained ranges: what
:meth:`Evaluation.summary` writes as text, as data for the text, rich and HTML renderers
and ``--json``.
"""

from __future__ import annotations

from typing import Any

from hrgtc.core.summary import Figure, Summary


def run_figures(run: Any, key: str = "evaluation") -> Summary:
    """The figures of one evaluated run (an :class:`hrgtc.evaluation.Evaluation`; not
    imported here, which would close a circle); ``key`` prefixes every figure's name."""
    kind = f"{run.confidence:.1%} CI"
    stability = tuple(
        Figure(f"{key}.bias_stability_dph.{series}.{tau_s:g}",
               f"bias stability {series}, {tau_s:g} s", value, "°/h",
               run.stability_interval(series, tau_s), kind, digits=4)
        for series, row in run.bias_stability_dph.items() for tau_s, value in row.items())
    level = tuple(
        figure for series in run.bias_stability_dph for figure in (
            Figure(f"{key}.mean_dph.{series}", f"mean {series}",
                   run.mean_dph.get(series, float("nan")), "°/h", digits=4),
            Figure(f"{key}.rms_dph.{series}", f"RMS {series}",
                   run.rms_dph.get(series, float("nan")), "°/h", digits=4)))
    model = [Figure(f"{key}.improvement_10s", "improvement at 10 s", run.improvement_10s, "×",
                    digits=3),
             Figure(f"{key}.out_of_range_fraction", "beyond the calibrated temperatures",
                    run.out_of_range_fraction, digits=3),
             Figure(f"{key}.rate_out_of_range_fraction", "df/dt beyond its training range",
                    run.rate_out_of_range_fraction, digits=3)]
    if run.residual_rms_dph is not None:
        model.append(Figure(f"{key}.residual_rms_dph", "RMS of true bias minus model",
                            run.residual_rms_dph, "°/h", digits=4))
    return Summary(f"{run.file}: {run.n_samples} samples at {run.sample_rate_hz:g} Hz",
                   (("bias stability", stability), ("level", level), ("model", tuple(model))),
                   tuple(run.range_warnings()) + tuple(run.notes))
