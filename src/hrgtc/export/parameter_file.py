"""The plain parameter file (``hrgtc export-c --format params``): every number, documented.

For firmware that evaluates its own polynomials (in its own language, fixed point,
an FPGA): ``key = value`` lines, one number each (a term's spelling is the only
text value), a ``#`` comment above each key saying what it is and its unit, and a
header comment giving the formula to evaluate, step by step, in the order
:class:`hrgtc.compensate.Compensator` computes it. Numbers are printed with
``%.17g`` so they read back to the same double.

The computation written out in the header is the one of :mod:`hrgtc.export.export_c`:
the causal df/dt filter of :func:`hrgtc.drift.features.causal_rate`, the drift model of
Eq. (22) of [1] on scaled variables, continued along its tangent beyond the training
ranges, and the thermometer of Eq. (18) (its inverse gives Table 2).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.core.timeline import settle_threshold_s
from hrgtc.drift.features import settle_rows
from hrgtc.drift.variables import DRIFT_VARIABLES, ascii_unit, refusal, variable
from hrgtc.export.c.header import sensor_words
from hrgtc.export.c.plan import CPlan
from hrgtc.export.c.text import offsets_note, sensor_note, title
from hrgtc.export.c.thermometer import NEWTON_MAX_ITER
from hrgtc.export.c.types import DOUBLE
from hrgtc.model import Model

#: Version of the file's layout (a key of the file).
FORMAT_VERSION = 1


def _unit(model: Model, name: str) -> str:
    """A variable's unit as this file writes it (from :mod:`hrgtc.drift.variables`)."""
    if name.startswith("a_"):
        column = model.drift.settings.aux_columns.get(name[2:], "?")
        return f"unit of the column {column}"
    return ascii_unit(name, model.thermometer.source)


def _number(value: float, name: str) -> str:
    return DOUBLE.literal(value, name)


def formula(key: str = "", sensor: bool = False) -> list[str]:
    """The header's formula, with ``key`` the key prefix (``x_`` for axis x, '' for one);
    ``sensor``: the thermometer is the gyro's temperature sensor (step 6 is then its
    temperature, not the resonator's)."""
    lines = [
        "FORMULA (per sample, dt = its time since the previous sample [s], any steps; "
        "keys below are written <key>)",
        "  1. f = freq_hz - <{k}reference_freq_hz>                                  [Hz]",
        "  2. df/dt, a causal filter started at rest (y1 = y2 = f on the first sample),",
        "     each step exact over its dt for an input moving linearly over the step",
        "     (a gap is bridged with its dt): with tau = <{k}rate_tau_s>, r = dt/tau,",
        "       a = 1 - exp(-r),  p = 1 - a/r  (= r/2 - r^2/6 + r^3/24 - ... for small r)",
        "       y1' = y1 + a*(f_prev - y1) + p*(f - f_prev)",
        "       y2' = y2 + a*(y1 - y2) + p*(y1' - y1)",
        "       df = (y1' - y2') / tau                                              [Hz/s]",
        "     (when <{k}uses_housing> = 1: h = housing_c - <{k}reference_c> [degC] and dh its",
        "      rate by the same filter on its own y1, y2 [degC/s])",
        "     (when <{k}uses_rate2> = 1: d2, the rate of f by the same filter with",
        "      tau = <{k}rate_tau2_s>, on its own y1, y2 [Hz/s])",
        "     (when <{k}uses_gradient> = 1: g = housing_c - T [degC], T the resonator",
        "      temperature of step 6, NaN where the inverse has no solution)",
        "     (for each NAME of <{k}aux_names>: a_NAME = aux_NAME - <{k}aux_centre_NAME>,",
        "      aux_NAME the logged channel <{k}aux_column_NAME> [its unit])",
        "     (the keys of d2, g and a_NAME are written only when the terms use them: a",
        "      missing uses_rate2, uses_gradient or aux_names means not used)",
        "  3. for each variable v in f, df, h, dh, d2, g, a_NAME that the terms use:",
        "       c_v = v held in [<{k}range_v_low>, <{k}range_v_high>];  x_v = c_v / <{k}scale_v>",
        "  4. B = <{k}intercept_dph> + sum over k = 1..<{k}n_terms> of",
        "         <{k}coefficient_k> * product over the factors v^p of <{k}term_k> of x_v^p",
        "     beyond a range (v != c_v) B continues along its tangent at the edge:",
        "       B += dB/dv * (v - c_v), dB/dv = sum_k <{k}coefficient_k> * p_v(k) *",
        "            (term_k with v's power lowered by one, on x) / <{k}scale_v>    [deg/h]",
        "     (algebraically, inside the ranges B = <{k}intercept_dph> + sum_k",
        "      <{k}coefficient_raw_k> * term_k(f, df, h, dh), Eq. (22) of [1])",
        "  5. rate_comp_dph = rate_dph - B                                          [deg/h]",
        "     or, when <{k}uses_scale_factor> = 1, with the scale-factor error k [ppm]:",
        "       g = freq_hz - <{k}sf_reference_hz>; c_g = g held in [<{k}sf_range_low_hz>,",
        "       <{k}sf_range_high_hz>] - <{k}sf_reference_hz>; x = c_g / <{k}sf_scale_hz>;",
        "       k = <{k}sf_intercept_ppm> + sum_k <{k}sf_coefficient_k> * x^(power of",
        "       <{k}sf_term_k>), continued along its tangent beyond the range as B is;",
        "       rate_comp_dph = (rate_dph - B) / (1 + 1e-6 * k)",
        "  6. resonator temperature: the T in [<{k}inverse_low_c>, <{k}inverse_high_c>] with",
        "       F(T) = freq_hz, F(T) = sum_j <{k}thermometer_coefficient_j> * z^j,",
        "       z = (T - <{k}thermometer_centre_c>) / <{k}thermometer_scale_c>        [Hz]",
        "     (Newton's iteration to <{k}inverse_tolerance_c>; no solution: NaN). Same F:",
        "       sum_j <{k}thermometer_raw_coefficient_j> * T^j, Eq. (18) of [1].",
        "  7. in_range = freq_hz in [<{k}calibrated_freq_low_hz>, <{k}calibrated_freq_high_hz>]",
        "     and every variable computed (f, df, h, dh, d2, g, a_NAME) in its range and at",
        "     at least <{k}settle_s> seconds (the sum of dt) since the start of the run.",
    ]
    if sensor:
        lines = [line.replace("T the resonator", "T the sensor's")
                 .replace("6. resonator temperature:", "6. sensor temperature:")
                 for line in lines]
    return [line.replace("{k}", key) for line in lines]


def parameter_lines(model: Model, plan: CPlan, key: str = "") -> list[str]:
    """``key = value`` lines of one unit's compensation, each documented by a comment above.

    Parameters
    ----------
    model, plan
        The unit's model and its export plan.
    key
        Prefix of every key (``x_`` for axis x of an instrument; '' for a single gyro).
    """
    drift = model.drift
    refused = refusal(drift.variables, "params", drift.selected)
    if refused is not None:
        raise InputError(refused)
    lines: list[str] = []

    def put(name: str, value: float | int | str, comment: str) -> None:
        if isinstance(value, str):
            text = value
        elif isinstance(value, int):
            text = str(value)
        else:
            text = _number(value, key + name)
        lines.extend([f"# {sensor_words(model, comment)}", f"{key}{name} = {text}", ""])

    _settings_lines(model, plan, put)
    _extra_variable_lines(model, plan, put)
    _scale_and_range_lines(model, plan, put)
    _term_lines(model, put)
    _scale_factor_lines(model, put)
    _thermometer_lines(model, plan, put)
    return lines


def _settings_lines(model: Model, plan: CPlan, put: Any) -> None:
    """The keys of the drift settings the compensation needs: rate, references, filter."""
    settings = model.drift.settings
    put("sample_rate_hz", settings.sample_rate_hz,
        "Sample rate of the training runs (settle_rows counts samples at it). [Hz]")
    put("reference_freq_hz", settings.reference_freq_hz,
        f"f_ref: the thermometer's frequency at {settings.reference_c:g} degC; "
        "f = freq_hz - f_ref. [Hz]")
    put("reference_c", settings.reference_c,
        "Reference temperature; origin of h = housing_c - reference_c. [degC]")
    put("uses_housing", int(plan.housing),
        "1 when the terms use the housing thermistor (h, dh): then housing_c is an input.")
    put("rate_tau_s", settings.rate_tau_s,
        "Time constant of each of the two low-pass stages of the df/dt filter. [s]")
    put("settle_s", settle_threshold_s(settings.warmup_s),
        "Seconds at the start of a run (the sum of dt) flagged (in_range 0) while the filter "
        "settles, as training leaves them out. [s]")
    put("settle_rows", settle_rows(settings),
        "settle_s in samples at the training rate (a continuous run). [1]")


def _scale_and_range_lines(model: Model, plan: CPlan, put: Any) -> None:
    """The scale of each computed variable, then its training range."""
    drift = model.drift
    settings = drift.settings
    for v in plan.computed:
        if v in settings.scales and v in drift.variables:
            put(f"scale_{v}", settings.scales[v],
                f"Scale of {v} ({variable(v).description}): x_{v} = {v} / scale_{v}. "
                f"[{_unit(model, v)}]")
    for v in plan.computed:
        if v in drift.ranges:
            low, high = drift.ranges[v]
            put(f"range_{v}_low", low, f"Training range of {v}, low end (as the model file "
                "stores it); the model is continued along its tangent below it. "
                f"[{_unit(model, v)}]")
            put(f"range_{v}_high", high, f"Training range of {v}, high end. "
                f"[{_unit(model, v)}]")


def _term_lines(model: Model, put: Any) -> None:
    """B0 and each selected term of Eq. (22): its name, scaled and raw coefficients."""
    drift, th = model.drift, model.thermometer
    put("intercept_dph", drift.intercept_dph, "B0: the bias at f = df = 0 (h = dh = 0). [deg/h]")
    put("n_terms", len(drift.terms), "Number of selected terms of the drift model (Eq. 22).")
    for k, (term, scaled) in enumerate(zip(drift.terms, drift.scaled_coefficients,
                                           strict=True), start=1):
        factors = " * ".join(f"x_{v}" if p == 1 else f"x_{v}^{p}" for v, p in term.powers)
        put(f"term_{k}", term.name,
            f"Term {k}: its factors v^p (variables f, df, h, dh, d2, g, a_NAME); on the "
            "scaled variables "
            f"it is {factors}.")
        put(f"coefficient_{k}", scaled,
            f"Coefficient of term {k} ({term.name}) on the scaled variables. [deg/h]")
        put(f"coefficient_raw_{k}", drift.coefficients[term.name],
            f"Coefficient of term {k} ({term.name}) on the raw variables, Eq. (22) form. "
            f"[deg/h per {term.unit_for(th.source)}]".replace("·", " "))


def _thermometer_lines(model: Model, plan: CPlan, put: Any) -> None:
    """The thermometer F(T) (Eq. 18), its calibrated ranges and its inverse's interval."""
    th = model.thermometer
    put("thermometer_order", th.order, "Order of the thermometer polynomial F(T) (Eq. 18).")
    put("thermometer_centre_c", th.centre_c,
        "z = (T - thermometer_centre_c) / thermometer_scale_c. [degC]")
    put("thermometer_scale_c", th.scale_c, "Scale of z. [degC]")
    for j, value in enumerate(th.scaled_coefficients):
        put(f"thermometer_coefficient_{j}", value,
            f"F(T) = sum_j thermometer_coefficient_j z^j: coefficient of z^{j}. [Hz]")
    for j, value in enumerate(th.coefficients):
        put(f"thermometer_raw_coefficient_{j}", value,
            f"The same F(T) in T (Eq. 18): coefficient of T^{j}. [Hz/degC^{j}]")
    t_low, t_high = th.temperature_range_c
    put("calibrated_temperature_low_c", t_low, "Calibrated temperature range, low end. [degC]")
    put("calibrated_temperature_high_c", t_high, "Calibrated temperature range, high end. [degC]")
    put("calibrated_freq_low_hz", plan.f_range[0],
        "Calibrated frequency range (F over the calibrated temperatures), low end. [Hz]")
    put("calibrated_freq_high_hz", plan.f_range[1],
        "Calibrated frequency range, high end. [Hz]")
    put("inverse_low_c", plan.extension[0],
        "The inverse T(freq_hz) is defined on [inverse_low_c, inverse_high_c] (F monotonic "
        "there); beyond: NaN. [degC]")
    put("inverse_high_c", plan.extension[1], "High end of the inverse's interval. [degC]")
    put("inverse_freq_low_hz", float(plan.grid_f[0]),
        "Frequencies the inverse accepts: F over that interval, low end. [Hz]")
    put("inverse_freq_high_hz", float(plan.grid_f[-1]), "High end. [Hz]")
    put("inverse_tolerance_c", plan.tolerance,
        "Stop Newton's iteration when a step changes T by at most this. [degC]")
    put("inverse_max_iterations", NEWTON_MAX_ITER, "Iteration cap of the inverse. [1]")


def _extra_variable_lines(model: Model, plan: CPlan, put: Any) -> None:
    """The keys of the variables beyond f, df, h and dh the terms use (d2, g, a_NAME), in
    grammar order, each written by its module's ``params`` (:mod:`hrgtc.drift.variables`);
    a model without them has none of these keys (older files' keys unchanged)."""
    for entry in DRIFT_VARIABLES:
        names = tuple(n for n in plan.computed if variable(n) is entry)
        if names and entry.params is not None:
            entry.params(names, model.drift.settings, put)


def _scale_factor_lines(model: Model, put: Any) -> None:
    """The scale factor's keys (``uses_scale_factor`` 0 and nothing else without one)."""
    sf = model.scale_factor
    put("uses_scale_factor", int(sf is not None),
        "1 when rate_comp also corrects the scale factor: (rate - B) / (1 + 1e-6 k).")
    if sf is None:
        return
    put("sf_reference_hz", sf.reference_hz,
        "Reference of the scale factor's variable g = freq_hz - sf_reference_hz. [Hz]")
    put("sf_scale_hz", sf.scale_hz, "Scale of g: x = g / sf_scale_hz. [Hz]")
    put("sf_range_low_hz", sf.freq_range_hz[0],
        "Frequency range of the rate-table runs, low end; k continues along its tangent "
        "beyond. [Hz]")
    put("sf_range_high_hz", sf.freq_range_hz[1], "High end of that range. [Hz]")
    put("sf_intercept_ppm", sf.intercept_ppm, "k at freq_hz = sf_reference_hz. [ppm]")
    put("sf_n_terms", len(sf.terms), "Number of terms of k(f).")
    for j, (term, scaled) in enumerate(zip(sf.terms, sf.scaled_coefficients, strict=True),
                                       start=1):
        put(f"sf_term_{j}", term.name, f"Scale-factor term {j}: a power of f (= g).")
        put(f"sf_coefficient_{j}", scaled,
            f"Coefficient of scale-factor term {j} ({term.name}) on x. [ppm]")
        put(f"sf_coefficient_raw_{j}", sf.coefficients_ppm[term.name],
            f"Coefficient of term {j} ({term.name}) on g itself. [ppm per {term.unit}]")


def _head(model: Model, origin: str, sha256: str, key: str = "") -> list[str]:
    from hrgtc.core.meta import PAPER_CITATION, PAPER_REFERENCE, __version__

    prov = model.provenance
    sensor = model.thermometer.source == "sensor"
    return [
        f"hrgtc parameter file -- {title(model)} of unit {model.unit!r}",
        "Generated by hrgtc export-c --format params; do not edit, regenerate from the model.",
        "Lines are 'key = value'; lines starting with # are comments. Numbers are %.17g",
        "(they read back to the same double).",
        "",
        f"unit:            {model.unit}",
        f"model:           {origin}",
        f"model SHA-256:   {sha256}",
        f"calibrated with: hrgtc {prov.get('hrgtc_version', 'unknown')}, "
        f"{prov.get('created_utc', 'time unknown')}",
        f"exported by:     hrgtc {__version__}",
        "",
        *sensor_note(model),
        *offsets_note(model),
        *(sensor_words(model, line) for line in formula(key, sensor)),
        "",
        f"[1] {PAPER_CITATION if sensor else PAPER_REFERENCE}",
    ]


def parameter_text(model: Model, plan: CPlan, origin: str, sha256: str) -> str:
    """The whole parameter file of one unit."""
    lines = [("# " + line).rstrip() for line in _head(model, origin, sha256)]
    lines += ["", "# Layout version of this file.", f"format_version = {FORMAT_VERSION}", ""]
    lines += parameter_lines(model, plan)
    return "\n".join(lines).rstrip() + "\n"


def instrument_parameter_text(axes: dict[str, Model], plans: dict[str, CPlan],
                              origin: str, sha256: str) -> str:
    """The parameter file of an instrument: every axis's keys, prefixed ``<axis>_``."""
    names = list(axes)
    head = _head(axes[names[0]], origin, sha256, "<axis>_")
    head[0] = (f"hrgtc parameter file -- {title(axes[names[0]])} of the axes "
               f"{', '.join(names)} of unit {axes[names[0]].unit!r}")
    head.insert(4, "Every axis has its own keys, written <axis>_<key>: x_sample_rate_hz, ...")
    lines = [("# " + line).rstrip() for line in head]
    lines += ["", "# Layout version of this file.", f"format_version = {FORMAT_VERSION}", "",
              "# Number of axes.", f"n_axes = {len(names)}", "",
              "# The axes' names, in file order (the <axis> of every other key).",
              f"axes = {' '.join(names)}", ""]
    for name in names:
        lines += [f"# ---- axis {name} " + "-" * 60, ""]
        lines += parameter_lines(axes[name], plans[name], key=f"{name}_")
    return "\n".join(lines).rstrip() + "\n"
