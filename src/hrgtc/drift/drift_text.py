"""How a drift model reads as text: its Eq. (22) form with numbers and units, and the
summary of its fit (stepwise history, coefficient table, statistics), in the words of
the thermometer that trained it (a resonator's Hz, or a temperature sensor's °C)."""

from __future__ import annotations

from typing import Any

from hrgtc.drift.features import variable_unit

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


def drift_summary(model: Any, sensor: bool = False) -> str:
    """Stepwise history, coefficient table and fit statistics (:meth:`DriftModel.summary`)."""
    lines = [
        f"Drift model: {len(model.selected)} of {len(model.candidates)} candidate terms, "
        f"{model.n_windows} windows of {model.window_s:g} s ({model.n_samples} samples)",
        "Steps:",
    ]
    if model.accounting is not None:
        lines.insert(1, f"Training {model.accounting.summary()}")
    for n, step in enumerate(model.history, start=1):
        lines.append(f"  {n:>2}. {step.action:<8} {step.term:<10} F = {step.fstat:<12.5g} "
                     f"p = {step.pvalue:.3g}")
    lines.append(f"{'term':<10}{'coefficient':>16}{'std error':>14}{'p-value':>11}")
    lines.append(
        f"{'const':<10}{model.intercept_dph:>16.6g}{model.standard_errors['const']:>14.4g}"
        f"{model.pvalues['const']:>11.3g}"
    )
    for name in model.selected:
        lines.append(
            f"{name:<10}{model.coefficients[name]:>16.6g}{model.standard_errors[name]:>14.4g}"
            f"{model.pvalues[name]:>11.3g}"
        )
    lines.append(
        f"residual std {model.residual_std_dph:.4g} °/h on {model.window_s:g} s means, "
        f"R² {model.rsquared:.6f}"
    )
    lines.extend(drift_notes(model))
    lines.append(drift_equation(model, sensor))
    return "\n".join(lines)


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
        lines.append(model.cross_validation.summary())
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
