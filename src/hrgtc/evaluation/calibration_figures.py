"""A calibration's figures as a structured summary (:class:`hrgtc.core.summary.Summary`).

The thermometer (Eq. 18: order, coefficients ± 1σ, residual, R², calibrated range, the
largest Table 2 error, the prior's temperature uncertainty), the drift model (Eq. 22:
candidates, terms, intercept and coefficients ± 1σ with p-values, residual, R², windows,
samples), its stepwise steps (F and p of each), the housing baseline and each held-out run
(:func:`hrgtc.evaluation.run_figures.run_figures`): the one structure the plain text, the
CLI's rich tables (``hrgtc calibrate``), the HTML report and the JSON render. The equations
and what a figure cannot say (autocorrelation correction, cross-validation) are its notes.
See docs/architecture.md ("One result contract").
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from hrgtc.core.summary import Figure, Summary
from hrgtc.drift.drift_text import drift_notes

__all__ = ["calibration_summary", "drift_form", "drift_heading", "instrument_summary",
           "paper_tables", "power_text", "thermometer_equation", "thermometer_tables"]

#: Headings of :func:`thermometer_tables`' sections.
TABLE1, TABLE2, PLATEAUS, EQ18 = ("Table 1", "Table 2", "plateaus",
                                  "Eq. 18 beside the paper's")


#: Heading of the thermometer's section: a resonator's fit (Eq. 18) or the gyro's sensor.
THERMOMETER, SENSOR_THERMOMETER = "thermometer (Eq. 18)", "thermometer (temperature sensor)"

#: Heading of the drift model's section: the paper's Eq. 22 on a resonator's frequency, or
#: the same stepwise model on the gyro's temperature sensor (no equation of [1] is its).
DRIFT, SENSOR_DRIFT = "drift model (Eq. 22)", "drift model (temperature sensor)"


def drift_heading(sensor: bool) -> str:
    """The drift model's section heading in the words of its thermometer."""
    return SENSOR_DRIFT if sensor else DRIFT


def drift_form(model: Any, sensor: bool) -> str:
    """The drift model with numbers, introduced as the paper's "Eq. (22) form" on a
    resonator and as "drift model" on a temperature sensor."""
    return ("drift model: " if sensor else "Eq. (22) form: ") + model.equation(sensor)


def calibration_summary(model: Any, table: Sequence[Mapping[str, float]] = (),
                        validation: Sequence[Any] = (), prior_fit: Any = None,
                        warnings: bool = True,
                        temperature_map: Mapping[str, Any] | None = None) -> Summary:
    """The figures of a calibration: a :class:`~hrgtc.model.Model`, its Table 2 rows
    (``error_c``), the held-out :class:`~hrgtc.evaluation.Evaluation` s and the prior's fit
    (what :meth:`hrgtc.pipeline.axis_calibration.AxisCalibration.summary` holds; the report
    passes a model file's). ``warnings``: the held-out runs' range warnings among the notes
    (the CLI prints them apart). ``temperature_map``: the instrument's map of a raw sensor
    count to °C (a model file's ``temperature_map``, ``--temp-ref``), shown as the sensor
    thermometer's figures (a sensor has no Eq. 18 fit: no plateaus, no coefficients).
    """
    th = model.thermometer
    sensor = th.source == "sensor"
    sections = [(SENSOR_THERMOMETER, _sensor_figures(th, temperature_map)) if sensor else
                (THERMOMETER, _thermometer_figures(th, table, prior_fit)),
                (drift_heading(sensor), _drift_figures("drift", model.drift, th.source)),
                ("stepwise steps", _step_figures("drift", model.drift))]
    notes: list[str] = []
    if sensor:
        notes.append("thermometer: the gyro's temperature sensor (no frequency output); "
                     "drift terms in T and dT/dt")
    else:
        notes.append(thermometer_equation(th))
    if model.drift.accounting is not None:
        notes.append("drift training " + model.drift.accounting.summary().text())
    notes += [*drift_notes(model.drift), drift_form(model.drift, sensor)]
    if model.housing is not None:
        sections.append(("housing-thermistor baseline",
                         _drift_figures("housing", model.housing)))
        notes.append("housing-thermistor baseline: " + model.housing.equation())
    for k, run in enumerate(validation):
        figures = run.figures(f"validation[{k}]", sensor=sensor, warnings=warnings)
        sections += [(f"held-out run {run.file}: {heading}", part)
                     for heading, part in figures.sections]
        notes.extend(figures.notes)
    return Summary(f"calibration of {model.unit}", tuple(sections), tuple(notes))


def thermometer_equation(thermometer: Any) -> str:
    """The thermometer in Eq. (18) form with numbers (``f = 1.5e-05·T³ ...  [Hz, T in °C]``)."""
    if thermometer.order == 3:
        c3, c2, c1, c0 = thermometer.coefficients_high_first
        return (f"Eq. (18) form: f = {c3:.4e}·T³ {c2:+.4e}·T² {c1:+.6f}·T {c0:+.4f}  "
                "[Hz, T in °C]")
    return thermometer.summary().text().splitlines()[-1]


def thermometer_tables(thermometer: Any, plateaus: Sequence[Any]) -> Summary:
    """A frequency thermometer's tables as cells (:meth:`Summary.grid`), printed to the
    digits the report and ``hrgtc calibrate`` show.

    ``Table 1``: each plateau's chamber temperature, settled frequency and the fit's residual
    (mHz); ``Table 2``: frequency, chamber temperature, temperature from frequency (the
    inverse of Eq. 18) and its error (``thermometer.table[k]`` of ``hrgtc calibrate
    --json``); ``plateaus``: how each settled frequency was found (``plateaus[k]`` of the
    model file); ``Eq. 18 beside the paper's``: the coefficients, highest power first,
    beside Eq. (18) of [1] as printed. No sections for the gyro's own temperature sensor.
    ``plateaus``: :class:`~hrgtc.thermometry.plateaus.Plateau` s, in the thermometer's
    Table 1 order (``AxisCalibration.plateaus``, a model file's ``plateaus``).
    """
    title = "the unit's Table 1 and Table 2"
    if thermometer.source == "sensor":
        return Summary(title, notes=("thermometer: the gyro's temperature sensor (no "
                                     "frequency output): no Table 1 or Table 2",))
    chamber = np.array([p.chamber_c for p in plateaus], dtype=np.float64)
    freq = np.array([p.settled_freq_hz for p in plateaus], dtype=np.float64)
    estimate = thermometer.temperature(freq, warn=False) if freq.size else freq
    table1: list[Figure] = []
    table2: list[Figure] = []
    found: list[Figure] = []
    for k, (p, t, f, e) in enumerate(zip(plateaus, chamber, freq, estimate, strict=True)):
        cell = functools.partial(_cell, k)
        residual = 1e3 * (float(f) - float(thermometer.frequency(float(t))))
        table1 += [cell(f"table1[{k}].chamber_c", "temperature", float(t), "°C", ".3f"),
                   cell(f"table1[{k}].freq_hz", "natural frequency", float(f), "Hz", ".5f"),
                   cell(f"table1[{k}].residual_mhz", "residual", residual, "mHz", "+.3f")]
        key = f"thermometer.table[{k}]"
        table2 += [cell(f"{key}.freq_hz", "frequency", float(f), "Hz", ".5f"),
                   cell(f"{key}.chamber_c", "chamber temperature", float(t), "°C", ".3f"),
                   cell(f"{key}.temperature_from_freq_c", "temperature from frequency",
                        float(e), "°C", ".4f"),
                   cell(f"{key}.error_c", "error", float(e - t), "°C", "+.4f")]
        source = str(p.source).replace("\\", "/").rsplit("/", 1)[-1] if p.source else "–"
        found += [cell(f"plateaus[{k}].chamber_c", "chamber", _float(p.chamber_c), "°C", ".3f"),
                  cell(f"plateaus[{k}].settled_freq_hz", "settled frequency",
                       _float(p.settled_freq_hz), "Hz", ".5f"),
                  cell(f"plateaus[{k}].settled_freq_std_mhz", "std error",
                       1e3 * _float(p.settled_freq_std_hz), "mHz", digits=2),
                  cell(f"plateaus[{k}].method", "from", p.method),
                  cell(f"plateaus[{k}].settled", "settled by slope",
                       "yes" if p.settled else "no"),
                  cell(f"plateaus[{k}].slope_hz_per_h", "final slope",
                       _float(p.slope_hz_per_h), "Hz/h", "+.3g"),
                  cell(f"plateaus[{k}].residual_unsettled_c", "unsettled at end",
                       _float(p.residual_unsettled_c), "°C", "+.4f"),
                  cell(f"plateaus[{k}].source", "soak file", source)]
    eq18 = _eq18_cells(thermometer.order, [("thermometer.coefficients_high_first", "this unit",
                                            10, thermometer.coefficients_high_first)])
    return Summary(title, ((TABLE1, tuple(table1)), (TABLE2, tuple(table2)),
                           (PLATEAUS, tuple(found)), (EQ18, tuple(eq18))),
                   (thermometer_equation(thermometer),))


def _eq18_cells(order: int, columns: Sequence[tuple[str, str, int, Sequence[float]]],
                printed_name: str = "eq18[{i}].printed") -> list[Figure]:
    """Eq. 18's rows, highest power first: coefficient, term, each of ``columns`` (the name
    of its values, ``name[i]``; header; significant digits; the values, highest power
    first) and Eq. (18) of [1] as printed (``printed_name``, ``{i}`` the row)."""
    from hrgtc.thermometry import paper

    printed = dict(enumerate(reversed(paper.EQ18_PRINTED_HIGH_FIRST)))
    cells: list[Figure] = []
    for i, n in enumerate(range(order, -1, -1)):
        label, row = f"c{n}", str(i)
        cells += [Figure(f"eq18[{i}].coefficient", f"{label}, coefficient", label, row=row,
                         column="coefficient"),
                  Figure(f"eq18[{i}].term", f"{label}, term", power_text("T", n) or "const",
                         row=row, column="term")]
        for name, header, digits, values in columns:
            cells.append(Figure(f"{name}[{i}]", f"{label}, {header}", float(values[i]),
                                digits=digits, row=row, column=header))
        cells.append(Figure(printed_name.format(i=i), f"{label}, Eq. 18 of [1]",
                            float(printed.get(n, math.nan)), digits=7, row=row,
                            column="Eq. 18 of [1]"))
    return cells


def paper_tables(reproduction: Any) -> Summary:
    """``hrgtc paper``: Table 1 of [1] with the fit's residuals, Eq. (18) refitted (full
    precision, rounded to the printed digits, as printed), Table 2 recomputed beside the
    printed one, and the bias stability Section 4.2 of [1] reports. Each number of [1] is
    shown to the digit it is printed with; a figure's name is its place in ``hrgtc paper
    --json`` where it has one (``table2[k].computed_c``, ``eq18.rounded_high_first[i]``).
    ``reproduction``: :func:`hrgtc.thermometry.paper.reproduce`'s.
    """
    from hrgtc.thermometry import paper

    th = reproduction.thermometer
    table1: list[Figure] = []
    table2: list[Figure] = []
    rows = zip(paper.TABLE1_TEMPERATURE_C, paper.TABLE1_FREQUENCY_HZ, paper.TABLE2_CALCULATED_C,
               paper.TABLE2_CALCULATED_DECIMALS, reproduction.table2_computed_c, strict=True)
    for k, (t, f, published, decimals, computed) in enumerate(rows):
        cell = functools.partial(_cell, k)
        residual = 1e3 * (float(f) - float(th.frequency(float(t))))
        table1 += [cell(f"table1[{k}].chamber_c", "temperature", float(t), "°C", ".0f"),
                   cell(f"table1[{k}].freq_hz", "natural frequency", float(f), "Hz",
                        f".{paper.TABLE1_FREQUENCY_DECIMALS}f"),
                   cell(f"table1[{k}].residual_mhz", "fit residual", residual, "mHz", "+.1f")]
        table2 += [cell(f"table2[{k}].frequency_hz", "frequency", float(f), "Hz",
                        f".{paper.TABLE1_FREQUENCY_DECIMALS}f"),
                   cell(f"table2[{k}].actual_c", "actual", float(t), "°C", ".0f"),
                   cell(f"table2[{k}].published_c", "Table 2 of [1]", float(published), "°C",
                        f".{decimals}f"),
                   cell(f"table2[{k}].computed_c", "hrgtc", float(computed), "°C", ".4f"),
                   cell(f"table2[{k}].difference_c", "hrgtc − [1]",
                        float(computed) - float(published), "°C", "+.4f")]
    eq18 = _eq18_cells(th.order, [
        ("eq18.coefficients_high_first", "fitted", 9, reproduction.coefficients_high_first),
        ("eq18.rounded_high_first", "fitted, printed digits", 7,
         reproduction.rounded_high_first)], printed_name="eq18.published_high_first[{i}]")
    stability = (Figure("bias_stability_dph.raw", "raw", paper.BIAS_STABILITY_RAW_DPH, "°/h",
                        spec=".4f"),
                 Figure("bias_stability_dph.compensated", "compensated",
                        paper.BIAS_STABILITY_COMPENSATED_DPH, "°/h", spec=".4f"))
    return Summary(
        "Wang et al. (2012), doi:10.3390/s120506434: Table 1 -> Eq. (18) -> Table 2, recomputed",
        (("Table 1 of [1]: settled frequency of each soak", tuple(table1)),
         ("Eq. (18): f = c3·T³ + c2·T² + c1·T + c0, least squares on Table 1", tuple(eq18)),
         ("Table 2 of [1]: temperature from the frequency by inverting the fit",
          tuple(table2)),
         ("Section 4.2 of [1]: 1σ bias stability of the cool-down (as printed)", stability)),
        (thermometer_equation(th),
         "Section 4.2's bias stability is the paper's, as printed: it needs the paper's "
         "recordings; hrgtc demo runs the same campaign on the simulated paper-unit."))


def _float(value: Any) -> float:
    """A number of a plateau; NaN (shown "-") where it has none."""
    return math.nan if value is None else float(value)


def _cell(k: int, name: str, column: str, value: Any, unit: str = "", spec: str = "",
          digits: int = 6) -> Figure:
    """Plateau ``k``'s cell in ``column`` of a table."""
    return Figure(name, f"plateau {k + 1}, {column}", value, unit, digits=digits, spec=spec,
                  row=str(k), column=column)


def power_text(symbol: str, n: int) -> str:
    """``T³`` style powers (plain text, for tables and equations)."""
    digits = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")
    return "" if n == 0 else symbol if n == 1 else symbol + str(n).translate(digits)


def _thermometer_figures(thermometer: Any, table: Sequence[Mapping[str, float]],
                         prior_fit: Any = None) -> tuple[Figure, ...]:
    """Order, coefficients ± 1σ, residual, R², calibrated range, worst Table 2 error."""
    sensor = thermometer.source == "sensor"
    unit = "°C" if sensor else "Hz"
    low, high = thermometer.temperature_range_c
    figures = [Figure("thermometer.order", "order", thermometer.order),
               Figure("thermometer.n_points", "soak plateaus", thermometer.n_points)]
    for k, (c, se) in enumerate(zip(thermometer.coefficients, thermometer.standard_errors,
                                    strict=True)):
        figures.append(Figure.with_error(f"thermometer.coefficients[{k}]", f"c{k}", c, se,
                                         unit if k == 0 else f"{unit}/°C^{k}"))
        if k < len(thermometer.pvalues):
            figures.append(Figure(f"thermometer.pvalues[{k}]", f"p of c{k}",
                                  float(thermometer.pvalues[k]), digits=3))
    figures += [Figure("thermometer.residual_std_hz", "residual std",
                       thermometer.residual_std_hz, unit, digits=4),
                Figure("thermometer.rsquared", "R²", thermometer.rsquared, digits=10),
                Figure("thermometer.temperature_range_c", "calibrated temperatures",
                       high - low, "°C", (low, high), "range", digits=4)]
    errors = [abs(row["error_c"]) for row in table if math.isfinite(row.get("error_c", math.nan))]
    if errors:
        figures.append(Figure("thermometer.max_error_c", "largest Table 2 error", max(errors),
                              "°C", digits=3))
    if prior_fit is not None:
        figures += [Figure("thermometer.prior.n_units", "units of the prior",
                           prior_fit.prior.n_units),
                    Figure("thermometer.prior.max_temperature_std_c",
                           "largest temperature 1σ (prior fit)",
                           prior_fit.max_temperature_std_c, "°C", digits=4)]
    return tuple(figures)


def _sensor_figures(thermometer: Any,
                    temperature_map: Mapping[str, Any] | None) -> tuple[Figure, ...]:
    """A sensor thermometer: what it is (the sensor read directly, or its raw count through
    the reference log's map: scale, offset, residual, points, lag) and the temperatures
    trained on. No order, plateaus or c0/c1: ``f = T`` is no fit."""
    low, high = thermometer.temperature_range_c
    if temperature_map is None:
        figures = [Figure("thermometer.source", "thermometer",
                          "temperature sensor, read directly")]
    else:
        figures = [
            Figure("thermometer.source", "thermometer", "sensor count, mapped to °C"),
            Figure("temperature_map.reference", "reference log",
                   str(temperature_map.get("reference") or "-")),
            Figure("temperature_map.scale_c_per_count", "map scale",
                   float(temperature_map["scale_c_per_count"]), "°C/count", digits=6),
            Figure("temperature_map.offset_c", "map offset",
                   float(temperature_map["offset_c"]), "°C", digits=6),
            Figure("temperature_map.residual_rms_c", "map residual RMS",
                   _float(temperature_map.get("residual_rms_c")), "°C", digits=3),
            Figure("temperature_map.points", "reference points",
                   temperature_map.get("points", "-")),
            Figure("temperature_map.lag_s", "reference lag",
                   _float(temperature_map.get("lag_s")), "s", spec="+.0f")]
    figures.append(Figure("thermometer.temperature_range_c", "trained temperatures",
                          high - low, "°C", (low, high), "range", digits=4))
    return tuple(figures)


def _drift_figures(key: str, model: Any, source: str = "resonator") -> tuple[Figure, ...]:
    """Candidates, terms, intercept and coefficients ± 1σ with p-values, residual, R²,
    windows, samples; ``source``: the thermometer's (a sensor's f is in °C, not Hz)."""
    figures = [Figure(f"{key}.candidates", "candidate terms", ", ".join(model.candidates)),
               Figure(f"{key}.selected", "terms", ", ".join(model.selected) or "(none)"),
               Figure.with_error(f"{key}.intercept_dph", "B0", model.intercept_dph,
                                 model.standard_errors.get("const", math.nan), "°/h")]
    for term in model.terms:
        name = term.name
        figures.append(Figure.with_error(
            f"{key}.coefficients.{name}", f"k of {name}", model.coefficients[name],
            model.standard_errors.get(name, math.nan), f"°/h per {term.unit_for(source)}"))
        figures.append(Figure(f"{key}.pvalues.{name}", f"p of {name}",
                              model.pvalues.get(name, math.nan), digits=3))
    figures += [Figure(f"{key}.residual_std_dph", "residual std (window means)",
                       model.residual_std_dph, "°/h", digits=4),
                Figure(f"{key}.rsquared", "R²", model.rsquared, digits=6),
                Figure(f"{key}.n_windows", f"windows of {model.window_s:g} s", model.n_windows),
                Figure(f"{key}.n_samples", "training samples read", model.n_samples)]
    return tuple(figures)


def _step_figures(key: str, model: Any) -> tuple[Figure, ...]:
    """F and p of each stepwise step (``history[k]`` of ``--json``)."""
    figures = []
    for n, step in enumerate(model.history):
        what = f"{n + 1}. {step.action} {step.term}"
        figures += [Figure(f"{key}.history[{n}].fstat", f"{what}: F", step.fstat, digits=5),
                    Figure(f"{key}.history[{n}].pvalue", f"{what}: p", step.pvalue, digits=3)]
    return tuple(figures)


def instrument_summary(calibration: Any) -> Summary:
    """What a :class:`~hrgtc.pipeline.calibration.Calibration` shows beside its
    axes' own summaries: each held-out rate table's scale-factor error at each temperature
    raw and compensated (``scale_factor_checks[i]`` of ``--json``), each cross-axis trial
    (``cross_axis.<axis>``) and, for several axes, each axis's held-out median 10 s bias
    stability and scale-factor figures (``axes.<axis>``)."""
    sections: list[tuple[str, tuple[Figure, ...]]] = []
    notes: list[str] = []
    for i, check in enumerate(calibration.scale_checks):
        key = f"scale_factor_checks[{i}]"
        figures = [Figure(f"{key}.n_temperatures", "temperatures", len(check.raw_ppm))]
        for k, (freq, raw, comp) in enumerate(zip(check.freq_hz, check.raw_ppm,
                                                  check.compensated_ppm, strict=True)):
            figures += [Figure(f"{key}.raw_ppm[{k}]", f"at {freq:.8g} Hz: raw", raw, "ppm",
                               digits=4),
                        Figure(f"{key}.compensated_ppm[{k}]", f"at {freq:.8g} Hz: compensated",
                               comp, "ppm", digits=4)]
        figures += [Figure(f"{key}.raw_max_ppm", "largest |error|, raw", check.raw_max_ppm,
                           "ppm", digits=4),
                    Figure(f"{key}.compensated_max_ppm", "largest |error|, compensated",
                           check.compensated_max_ppm, "ppm", digits=4)]
        name = str(check.file).replace("\\", "/").rsplit("/", 1)[-1]
        sections.append((f"held-out rate table {name}"
                         + (f", axis {check.axis}" if check.axis else "")
                         + ": scale-factor error", tuple(figures)))
    for axis, trial in calibration.cross_axis.items():
        if "why" in trial:
            notes.append(f"axis {axis}: cross-axis terms not tried: {trial['why']}")
            continue
        key = f"cross_axis.{axis}"
        sections.append((f"axis {axis}: cross-axis terms (the other resonators' frequencies)", (
            Figure(f"{key}.channels", "channels", ", ".join(trial["channels"].values())),
            Figure(f"{key}.held_out_10s_dph_with", "held-out 10 s bias stability, with",
                   trial["held_out_10s_dph_with"], "°/h", digits=4),
            Figure(f"{key}.held_out_10s_dph_without", "held-out 10 s bias stability, without",
                   trial["held_out_10s_dph_without"], "°/h", digits=4),
            Figure(f"{key}.kept", "kept", "kept" if trial["kept"] else "not kept"),
            Figure(f"{key}.selected", "terms", ", ".join(trial["selected"]) or "(none)"))))
    if not calibration.model.is_single_axis:
        for axis, unit_model in calibration.model.axes.items():
            sections.append((f"axis {axis}: summary (held-out median)",
                             _axis_figures(calibration, axis, unit_model)))
    return Summary(f"instrument {calibration.model.unit}", tuple(sections), tuple(notes))


def _axis_figures(calibration: Any, axis: str, unit_model: Any) -> tuple[Figure, ...]:
    key = f"axes.{axis or '-'}"
    runs = calibration.axes[axis].validation
    checks = [c for c in calibration.scale_checks if c.axis == axis]

    def median(values: list[float]) -> float:
        return float(np.median(values)) if values else math.nan

    sf = unit_model.scale_factor
    return (Figure(f"{key}.drift_terms", "drift terms", ", ".join(unit_model.drift.selected)
                   or "(none)"),
            Figure(f"{key}.raw_10s_dph", "raw 10 s", median([v.raw_10s for v in runs]), "°/h",
                   digits=4),
            Figure(f"{key}.compensated_10s_dph", "compensated 10 s",
                   median([v.compensated_10s for v in runs]), "°/h", digits=4),
            Figure(f"{key}.scale_terms", "scale-factor terms",
                   "-" if sf is None else ", ".join(sf.selected) or "(none)"),
            Figure(f"{key}.scale_raw_max_ppm", "scale-factor error raw, largest",
                   max((c.raw_max_ppm for c in checks), default=math.nan), "ppm", digits=4),
            Figure(f"{key}.scale_residual_max_ppm", "scale-factor error compensated, largest",
                   max((c.compensated_max_ppm for c in checks), default=math.nan), "ppm",
                   digits=4))
