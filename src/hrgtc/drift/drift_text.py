"""How a drift model reads as text: its Eq. (22) form with numbers and units, and the
summary of its fit (stepwise history, coefficient table, statistics), in the words of
the thermometer that trained it (a resonator's Hz, or a temperature sensor's °C). The
summary is a :class:`~hrgtc.core.summary.Summary` whose text is the layout below."""

from __future__ import annotations

from typing import Any

from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.drift.features import variable_unit
from hrgtc.drift.stepwise import step_figures

#: What f and its rates are when a temperature sensor takes the frequency's place.
_SENSOR_VARIABLES = {"f": "f = T in °C", "df": "df = dT/dt in °C/s"}


def _variable_text(variable: str, sensor: bool) -> str:
    """``f in Hz`` for a resonator; ``f = T in °C`` (Hz read as °C) for a temperature sensor."""
    if sensor and variable in _SENSOR_VARIABLES:
        return _SENSOR_VARIABLES[variable]
    unit = variable_unit(variable)
    return f"{variable} in {unit.replace('Hz', '°C') if sensor else unit}"


def drift_equation(model: Any, sensor: bool = False) -> str:
    """The model in Eq. (22) form with numbers (see :meth:`DriftModel.equation`)."""
    parts = [f"B = {model.intercept_dph:.6g}"]
    for name in model.selected:
        value = model.coefficients[name]
        sign = "-" if value < 0 else "+"
        parts.append(f" {sign} {abs(value):.6g}·{name}")
    units = ", ".join(_variable_text(v, sensor) for v in model.variables)
    return "".join(parts) + f"   [°/h; {units}]"


def drift_summary(model: Any, sensor: bool = False) -> Summary:
    """The fit (windows, samples, residual, R²), the stepwise steps, the coefficient table
    and the training samples (:meth:`DriftModel.summary`); the notes and the Eq. (22) form
    are its notes. Its text: the layout ``hrgtc`` printed before the figures were data."""
    fit = (Figure("n_windows", "windows", model.n_windows,
                  definition="Windows whose means the model is fitted on."),
           Figure("window_s", "window", model.window_s, "s", definition="Length of a window."),
           Figure("n_samples", "samples", model.n_samples,
                  definition="Samples in the windows."),
           Figure("residual_std_dph", "residual std", model.residual_std_dph, "°/h", digits=4,
                  definition="Standard deviation of the fit's residuals on the window means."),
           Figure("rsquared", "R²", model.rsquared, spec=".6f",
                  definition="Share of the variance of the window means the fit explains."))
    table: list[Figure] = []
    rows = []
    for name in ("const", *model.selected):
        value = model.intercept_dph if name == "const" else model.coefficients[name]
        key = "intercept_dph" if name == "const" else f"coefficients.{name}"
        table += [Figure(f"terms.{name}", f"{name}", name, row=name, column="term"),
                  Figure(key, f"coefficient of {name}", value, row=name, column="coefficient",
                         definition=f"The fitted coefficient of {name} [°/h per unit]."),
                  Figure(f"standard_errors.{name}", f"std error of {name}",
                         model.standard_errors[name], digits=4, row=name, column="std error"),
                  Figure(f"pvalues.{name}", f"p of {name}", model.pvalues[name], digits=3,
                         row=name, column="p-value")]
        rows.append(f"{{terms.{name}:<10}}{{{key}:>16.6g}}{{standard_errors.{name}:>14.4g}}"
                    f"{{pvalues.{name}:>11.3g}}")
    layout = [f"Drift model: {len(model.selected)} of {len(model.candidates)} candidate terms, "
              "{n_windows} windows of {window_s:g} s ({n_samples} samples)", "Steps:"]
    sections = [("fit", fit)]
    if model.accounting is not None:
        training = model.accounting.summary().renamed("accounting.")
        layout.insert(1, "Training " + training.lines()[0])
        sections += [("training samples", training.sections[0][1])]
    layout += [f"  {n:>2}. {{history[{n - 1}].action:<8}} {{history[{n - 1}].term:<10}} "
               f"F = {{history[{n - 1}].fstat:<12.5g}} p = {{history[{n - 1}].pvalue:.3g}}"
               for n in range(1, len(model.history) + 1)]
    layout += [f"{'term':<10}{'coefficient':>16}{'std error':>14}{'p-value':>11}", *rows,
               "residual std {residual_std_dph:.4g} °/h on {window_s:g} s means, "
               "R² {rsquared:.6f}"]
    notes = (*drift_notes(model), drift_equation(model, sensor))
    layout += [escape(line) for note in notes for line in note.splitlines()]
    title = (f"Drift model: {len(model.selected)} of {len(model.candidates)} candidate "
             "terms")
    return Summary(title, (*sections, ("steps", step_figures(model.history)),
                           ("coefficients", tuple(table))), notes, tuple(layout))


def drift_notes(model: Any) -> list[str]:
    """What a fit's figures cannot say: the autocorrelation correction, the
    cross-validation, the guarded selection, the samples not at rest, the offsets."""
    lines: list[str] = []
    if model.variance_inflation > 1.0 or model.bandwidth_windows:
        lines.append(
            f"F-tests corrected for autocorrelated residuals (Newey-West, "
            f"{model.bandwidth_windows} windows): variance inflation "
            f"{model.variance_inflation:.3g}"
        )
    if model.cross_validation is not None:
        lines.append(model.cross_validation.summary().text())
    if model.pruning is not None and model.pruning.get("dropped"):
        p = model.pruning
        lines.append(f"guarded selection: dropped {', '.join(p['dropped'])} (held-out RMS "
                     f"over {p['folds']} {p['before_dph']:.4g} -> {p['after_dph']:.4g} °/h)")
        if p.get("edge_slope"):  # drift/edge_slope.py: why a single run's bend went
            e = p["edge_slope"]
            lines.append(f"  {', '.join(e['dropped'])}: the slope at an edge of the trained "
                         f"range unknown (cold {e['cold'][0]:.3g} ± {e['cold'][1]:.2g}, hot "
                         f"{e['hot'][0]:.3g} ± {e['hot'][1]:.2g}) where the line's is known "
                         f"({e['line'][0]:.3g} ± {e['line'][1]:.2g}) [°/h per unit of f]")
    if model.n_not_at_rest:
        lines.append(f"{model.n_not_at_rest} training samples not at rest were left out")
    if model.offsets_dph:
        lines.append(f"offsets ({model.offset_mode}, nuisance, from the intercept) [°/h]: "
                     + ", ".join(f"{k} {v:+.4g}" for k, v in model.offsets_dph.items()))
    return lines
