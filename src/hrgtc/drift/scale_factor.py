"""Scale factor against temperature: k(f) from rate-table segments.

The gyro's output at input rate Ω is rate = b + (1 + k)·Ω, with b the bias and
k the scale-factor error; both change with temperature. Wang et al. [1] model
the bias from the resonator frequency f (Eq. 21-22); here k is modelled the same
way, as a polynomial in the same scaled variable
x_f = (freq_hz - f_ref) / scale_f of the drift model (its ``FeatureSettings``),
so one evaluation of x_f serves both, and its terms are selected by the same
stepwise regression (Section 4.1 of [1]).

Fitting takes :class:`~hrgtc.drift.rate_segments.RateSegment` holds (rate-table
segments, :func:`~hrgtc.drift.rate_segments.find_rate_segments`) and

1. groups them by temperature: segments whose mean frequencies lie within
   ``tolerance_hz`` of each other, in frequency order, form one group;
2. fits each group by least squares, rate - Ω = b + k·Ω over its segments (b a
   nuisance), giving k in ppm with its standard error;
3. selects and fits k_ppm(x_f) by stepwise regression on the groups, weighted by
   1/se² when every group has a finite, positive standard error.

Compensation applies bias and scale factor together:
rate_comp = (rate - bias(f, df)) / (1 + ppm(f)·1e-6).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.errors import HrgtcWarning, InputError
from hrgtc.core.summary import Figure, Summary
from hrgtc.drift.features import (
    FeatureSettings,
    ParsedTerms,
    Term,
    linear_combination,
    parse_terms,
    tangent_extension,
)
from hrgtc.drift.rate_segments import RateSegment
from hrgtc.drift.stepwise import Step, StepwiseRules, stepwise
from hrgtc.settings.drift import PENTER, PREMOVE_FLOOR

__all__ = [
    "SCALE_FACTOR_JSON_SCHEMA",
    "ScaleFactorModel",
    "ScaleGroup",
    "fit_scale_factor",
    "group_segments",
]

#: Default candidate terms of k(f).
SCALE_TERMS = ("f", "f^2", "f^3")
#: Default grouping tolerance as a share of the drift model's frequency scale.
TOLERANCE_SHARE = 0.02


@dataclass(frozen=True)
class ScaleGroup(records.Written):
    """Segments at one temperature and their scale-factor error.

    Attributes
    ----------
    freq_hz
        Mean of the segments' mean frequencies. [Hz]
    k_ppm, k_se_ppm
        Scale-factor error of the group's fit rate - Ω = b + k·Ω, and its standard
        error (NaN with two segments). [ppm]
    bias_dph
        The group's b. [°/h]
    n
        Number of segments.
    rows
        Number of samples in the segments.
    """

    forbid_unknown_fields = True

    freq_hz: float
    k_ppm: float
    k_se_ppm: records.Statistic
    bias_dph: float
    n: Annotated[int, Meta(ge=2)]
    rows: Annotated[int, Meta(ge=1)]


#: The record of :class:`ScaleGroup` (nested in :class:`ScaleFactorRecord`).
ScaleGroupRecord = records.record_of(ScaleGroup)


#: A term of k(f): a power of f.
_FTerm = Annotated[str, Meta(pattern=r"^f(\^[0-9]+)?$")]
#: A stepwise threshold, a p-value strictly between 0 and 1.
_Threshold = Annotated[float, Meta(gt=0, lt=1)]
#: One step of the scale factor's stepwise selection in a file (a :class:`Step` of a term
#: of k(f)).
ScaleStepRecord = records.variant(
    Step, "ScaleStepRecord", "One step of the scale factor's stepwise selection in a file.",
    forbid_unknown_fields=True, term=_FTerm)


@dataclass(frozen=True, eq=False)
class ScaleFactorModel(ParsedTerms, records.Written):
    """A fitted scale-factor error k_ppm = c0 + sum c_i term_i(f).

    Attributes
    ----------
    reference_hz, scale_hz
        f_ref and scale_f of x_f = (freq_hz - f_ref)/scale_f (the drift model's). [Hz]
    candidates, selected
        Candidate terms and those kept by the stepwise selection (in candidate order).
    intercept_ppm
        c0: k at f_ref. [ppm]
    coefficients_ppm
        Term name -> coefficient in user units. [ppm per Hz^p]
    standard_errors_ppm, pvalues
        Term name -> standard error (user units) and p-value; intercept under ``"const"``.
    scaled_coefficients
        Coefficients on x_f, in ``selected`` order (what :meth:`ppm` uses). [ppm]
    covariance
        Covariance of (intercept, scaled coefficients). [ppm²]
    freq_range_hz
        Range of the segments' mean frequencies. [Hz]
    input_rate_range_dph
        Range of |input rate| of the segments. [°/h]
    residual_ppm
        Root mean square of k_ppm(group) - ppm(group frequency) over the groups. [ppm]
    groups
        The temperature groups, in frequency order.
    history
        Steps of the stepwise selection.
    weighted
        Whether the groups were weighted by 1/se².
    penter, premove
        Stepwise thresholds used.
    """

    #: Its record (the model file's ``scale_factor``) is generated from these fields.
    constants = (("kind", "hrgtc.ScaleFactorModel"),)
    not_written = ("_terms",)
    forbid_unknown_fields = True

    reference_hz: float
    scale_hz: records.Positive
    candidates: Annotated[tuple[_FTerm, ...], Meta(min_length=1)]
    selected: tuple[_FTerm, ...]
    intercept_ppm: float
    coefficients_ppm: dict[str, float]
    standard_errors_ppm: dict[str, records.Statistic]
    pvalues: dict[str, records.Statistic]
    scaled_coefficients: tuple[float, ...]
    covariance: tuple[tuple[records.Statistic, ...], ...]
    freq_range_hz: records.Range
    input_rate_range_dph: records.Range
    residual_ppm: records.Statistic
    groups: Annotated[tuple[ScaleGroup, ...], Meta(min_length=1)]
    history: tuple[Annotated[Step, ScaleStepRecord], ...] = ()
    weighted: bool = False
    penter: _Threshold = PENTER
    premove: _Threshold = 0.10
    _terms: tuple[Term, ...] = field(default=(), repr=False, compare=False)

    def _args(self, freq_hz: Any) -> tuple[dict[str, np.ndarray], dict[str, float],
                                           dict[str, tuple[float, float]]]:
        f = np.atleast_1d(np.asarray(freq_hz, dtype=np.float64)) - self.reference_hz
        ranges = {"f": (self.freq_range_hz[0] - self.reference_hz,
                        self.freq_range_hz[1] - self.reference_hz)}
        return {"f": f}, {"f": self.scale_hz}, ranges

    def ppm(self, freq_hz: Any, extrapolation: str = "tangent") -> np.ndarray:
        """Scale-factor error at resonator frequencies ``freq_hz`` [Hz]. [ppm]

        Beyond the calibrated frequency range the polynomial is continued along
        its tangent (``"tangent"``, default, as the drift model does), evaluated
        anyway (``"polynomial"``) or held at the edge (``"clamp"``).
        """
        values, scales, ranges = self._args(freq_hz)
        if not self._terms:
            return np.full(values["f"].shape, self.intercept_ppm)
        args = (self._terms, self.scaled_coefficients)
        if extrapolation == "tangent":
            return tangent_extension(*args, values, scales, ranges, self.intercept_ppm)
        if extrapolation == "clamp":
            values = {"f": np.clip(values["f"], *ranges["f"])}
        elif extrapolation != "polynomial":
            raise InputError(f"extrapolation must be 'tangent', 'polynomial' or 'clamp', "
                             f"got {extrapolation!r}")
        return linear_combination(*args, values, scales, self.intercept_ppm)

    def ppm_std(self, freq_hz: Any) -> np.ndarray:
        """1σ uncertainty of :meth:`ppm` from the coefficients' covariance. [ppm]"""
        values, scales, ranges = self._args(freq_hz)
        n = values["f"].size
        columns = [np.ones(n)]
        for k in range(len(self._terms)):
            unit = np.zeros(len(self._terms))
            unit[k] = 1.0
            columns.append(tangent_extension(self._terms, unit, values, scales, ranges, 0.0))
        jacobian = np.column_stack(columns)
        cov = np.asarray(self.covariance, dtype=np.float64)
        return np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", jacobian, cov, jacobian), 0.0))

    def equation(self) -> str:
        """The model with numbers, e.g. ``k = 120 - 3.1·f + ...   [ppm; f in Hz]``."""
        parts = [f"k = {self.intercept_ppm:.6g}"]
        for name in self.selected:
            value = self.coefficients_ppm[name]
            parts.append(f" {'-' if value < 0 else '+'} {abs(value):.6g}·{name}")
        return "".join(parts) + f"   [ppm; f = freq_hz - {self.reference_hz:.10g} Hz]"

    def summary(self, key: str = "scale_factor") -> Summary:
        """The model's figures (:class:`~hrgtc.core.summary.Summary`): its temperature
        groups as a table (mean frequency, k ± its standard error, the model's k, bias,
        holds), k(f)'s intercept and coefficients ± 1σ with p-values, the residual and the
        calibrated frequencies; the equation is its note. Render it with ``.text()``, as
        rich tables (``hrgtc calibrate``) or in the report; a figure's name after ``key``
        is its place in :meth:`to_dict` (``scale_factor.groups[0].k_ppm``)."""
        groups: list[Figure] = []
        for k, g in enumerate(self.groups):
            model_ppm = float(self.ppm(np.array([g.freq_hz]))[0])
            cells = (("freq_hz", "mean frequency", g.freq_hz, "Hz", 10),
                     ("k_ppm", "k", g.k_ppm, "ppm", 5),
                     ("k_se_ppm", "std error", g.k_se_ppm, "ppm", 3),
                     ("model_ppm", "model k", model_ppm, "ppm", 5),
                     ("bias_dph", "bias", g.bias_dph, "°/h", 5),
                     ("n", "holds", g.n, "", 6))
            groups += [Figure(f"{key}.groups[{k}].{name}", f"group {k + 1}, {column}", value,
                              unit, digits=digits, row=str(k), column=column)
                       for name, column, value, unit, digits in cells]
        fit = [Figure(f"{key}.candidates", "candidate terms", ", ".join(self.candidates)),
               Figure(f"{key}.selected", "terms", ", ".join(self.selected) or "(none)"),
               Figure.with_error(f"{key}.intercept_ppm", "k at f_ref (c0)", self.intercept_ppm,
                                 self.standard_errors_ppm.get("const", math.nan), "ppm")]
        if "const" in self.pvalues:
            fit.append(Figure(f"{key}.pvalues.const", "p of c0", self.pvalues["const"],
                              digits=3))
        for term in self.terms:
            name = term.name
            fit += [Figure.with_error(f"{key}.coefficients_ppm.{name}", f"k of {name}",
                                      self.coefficients_ppm[name],
                                      self.standard_errors_ppm.get(name, math.nan),
                                      f"ppm per {term.unit}"),
                    Figure(f"{key}.pvalues.{name}", f"p of {name}",
                           self.pvalues.get(name, math.nan), digits=3)]
        low, high = self.freq_range_hz
        fit += [Figure(f"{key}.residual_ppm", "residual (RMS over the groups)",
                       self.residual_ppm, "ppm", digits=4),
                Figure(f"{key}.freq_range_hz", "calibrated frequencies", high - low, "Hz",
                       (low, high), "range", digits=10),
                Figure(f"{key}.input_rate_max_dps", "largest |input rate|",
                       self.input_rate_range_dph[1] / 3600.0, "°/s", digits=4)]
        title = (f"scale-factor model: {len(self.selected)} of {len(self.candidates)} "
                 f"candidate terms, {len(self.groups)} temperature groups"
                 f"{' (weighted 1/se²)' if self.weighted else ''}")
        return Summary(title, (("scale-factor temperature groups", tuple(groups)),
                               ("scale-factor model k(f)", tuple(fit))),
                       (self.equation(),))


#: :class:`ScaleFactorModel` in a file, generated from its fields.
ScaleFactorRecord = records.record_of(
    ScaleFactorModel, "ScaleFactorRecord",
    "A :class:`ScaleFactorModel` in a file (the model file's ``scale_factor``).")


def group_segments(segments: Sequence[RateSegment],
                   tolerance_hz: float) -> tuple[tuple[RateSegment, ...], ...]:
    """Segments grouped by temperature: sorted by mean frequency, a new group at each gap
    wider than ``tolerance_hz`` [Hz] (single-linkage clustering). Groups in frequency order.

    Examples
    --------
    >>> hold = lambda f: RateSegment(0.0, 1.0, 36000.0, 36000.0, f, 10)
    >>> [len(g) for g in group_segments([hold(4420.0), hold(4432.1), hold(4420.05)], 0.1)]
    [2, 1]
    """
    if not (math.isfinite(tolerance_hz) and tolerance_hz > 0):
        raise InputError(f"tolerance_hz must be a positive number of Hz, got {tolerance_hz!r}")
    ordered = sorted(segments, key=lambda s: (s.freq_hz, s.start_s))
    groups: list[list[RateSegment]] = []
    for seg in ordered:
        if groups and seg.freq_hz - groups[-1][-1].freq_hz <= tolerance_hz:
            groups[-1].append(seg)
        else:
            groups.append([seg])
    return tuple(tuple(g) for g in groups)


def fit_group(group: Sequence[RateSegment], number: int) -> ScaleGroup:
    """Least squares rate - Ω = b + k·Ω over one group's segments."""
    freq = float(np.mean([s.freq_hz for s in group]))
    x = np.array([s.input_rate_dph for s in group])
    y = np.array([s.rate_dph for s in group]) - x
    name = (f"temperature group {number} (mean frequency {freq:.10g} Hz, segments from "
            f"{min(s.start_s for s in group):g} s)")
    distinct = np.unique(x)
    if distinct.size < 2:
        raise InputError(f"{name} has {len(group)} segment(s) at one input rate "
                         f"({distinct[0] / 3600.0:g} °/s); the scale factor needs at least two "
                         "distinct input rates per temperature, ideally of both signs")
    if not (np.any(x > 0) and np.any(x < 0)):
        warnings.warn(f"{name} has input rates of one sign only; the scale factor then "
                      "absorbs any asymmetry: turn the table both ways", HrgtcWarning,
                      stacklevel=3)
    xm, ym = float(np.mean(x)), float(np.mean(y))
    dx = x - xm
    sxx = float(dx @ dx)
    slope = float(dx @ (y - ym)) / sxx
    intercept = ym - slope * xm
    resid = y - intercept - slope * x
    dof = x.size - 2
    se = math.sqrt(float(resid @ resid) / dof / sxx) if dof > 0 else math.nan
    return ScaleGroup(freq_hz=freq, k_ppm=slope * 1e6, k_se_ppm=se * 1e6, bias_dph=intercept,
                      n=len(group), rows=int(sum(s.rows for s in group)))


def fit_scale_factor(segments: Iterable[RateSegment], settings: FeatureSettings,
                     terms: Iterable[str] = SCALE_TERMS, penter: float = PENTER,
                     premove: float | None = None, *, tolerance_hz: float | None = None,
                     weighted: bool = True) -> ScaleFactorModel:
    """Fit the scale-factor error k_ppm(f) from rate-table segments at several temperatures.

    Parameters
    ----------
    segments
        Holds at known input rates (:func:`~hrgtc.drift.rate_segments.find_rate_segments`),
        from one or more runs.
    settings
        The drift model's feature settings: f_ref (``reference_freq_hz``) and the
        frequency scale (``scales["f"]``; default the largest |f| of the segments).
    terms
        Candidate terms in ``f`` (Eq. 21 grammar).
    penter, premove
        Stepwise thresholds (MATLAB ``stepwisefit`` semantics, Section 4.1 of [1]).
    tolerance_hz
        Largest frequency gap within one temperature group; default 2 % of the
        frequency scale. [Hz]
    weighted
        Weight the groups by 1/se² of their k (when every se is finite and positive).

    Returns
    -------
    ScaleFactorModel
    """
    segments = tuple(segments)
    if not segments:
        raise InputError("no rate-table segments given; find them with find_rate_segments")
    candidates = parse_terms(list(terms))
    foreign = [t.name for t in candidates if t.variables != ("f",)]
    if foreign:
        raise InputError(f"scale-factor terms may use only f, got {foreign}; "
                         f"use terms like {list(SCALE_TERMS)}")
    names = tuple(t.name for t in candidates)
    reference = float(settings.reference_freq_hz)
    f = np.array([s.freq_hz for s in segments]) - reference
    scale = float(settings.scales.get("f", 0.0)) or float(np.max(np.abs(f))) or 1.0
    tolerance = TOLERANCE_SHARE * scale if tolerance_hz is None else tolerance_hz
    fits = []
    for number, members in enumerate(group_segments(segments, tolerance), start=1):
        fits.append(fit_group(members, number))
    groups = tuple(fits)
    k = np.array([g.k_ppm for g in groups])
    se = np.array([g.k_se_ppm for g in groups])
    use_weights = bool(weighted and np.all(np.isfinite(se)) and np.all(se > 0))
    w = 1.0 / se ** 2 if use_weights else np.ones(k.size)
    x_f = (np.array([g.freq_hz for g in groups]) - reference) / scale
    factors = {t.name: t.scale_factor({"f": scale}) for t in candidates}
    history: tuple[Step, ...] = ()
    premove = max(penter, PREMOVE_FLOOR) if premove is None else premove
    if len(groups) >= 3:
        # n groups fit the constant and at most n - 2 terms with a residual left over: the
        # lowest powers first (a cubic needs five temperatures).
        usable = sorted(candidates, key=lambda t: sum(p for _, p in t.powers))[:len(groups) - 2]
        if len(usable) < len(candidates):
            dropped = [t.name for t in candidates if t not in usable]
            warnings.warn(f"{len(groups)} rate-table temperatures cannot select among "
                          f"{len(candidates)} scale-factor terms: {', '.join(dropped)} left out "
                          "(add temperatures)", HrgtcWarning, stacklevel=2)
            candidates = [t for t in candidates if t in usable]
            names = tuple(t.name for t in candidates)
        design = np.column_stack([t.evaluate({"f": x_f}, {}) for t in candidates])
        found = stepwise(design, k, names=names, rules=StepwiseRules(penter, premove),
                         weights=w if use_weights else None)
        result = found.result
        selected, history = found.selected, found.history
        params, bse, pvalues = (np.asarray(result.params), np.asarray(result.bse),
                                np.asarray(result.pvalues))
        covariance = np.asarray(result.cov_params)
    else:  # one or two temperatures: a constant k, the weighted mean of the groups
        selected = ()
        mean = float(np.sum(w * k) / np.sum(w))
        if use_weights:
            var = 1.0 / float(np.sum(w))
        elif k.size > 1:
            var = float(np.sum((k - mean) ** 2)) / (k.size - 1) / k.size
        else:
            var = float(se[0]) ** 2
        params, bse, pvalues = np.array([mean]), np.array([math.sqrt(var)]), np.array([math.nan])
        covariance = np.array([[var]])
    chosen = [t for t in candidates if t.name in selected]
    fitted = params[0] + sum((c * t.evaluate({"f": x_f}, {}) for c, t in
                              zip(params[1:], chosen, strict=True)), np.zeros(k.size))
    rates = np.abs([s.input_rate_dph for s in segments])
    freqs = [s.freq_hz for s in segments]
    return ScaleFactorModel(
        reference_hz=reference, scale_hz=scale, candidates=names, selected=tuple(selected),
        intercept_ppm=float(params[0]),
        coefficients_ppm={n: float(params[j + 1] / factors[n]) for j, n in enumerate(selected)},
        standard_errors_ppm={"const": float(bse[0]), **{
            n: float(bse[j + 1] / factors[n]) for j, n in enumerate(selected)}},
        pvalues={"const": float(pvalues[0]), **{
            n: float(pvalues[j + 1]) for j, n in enumerate(selected)}},
        scaled_coefficients=tuple(float(p) for p in params[1:]),
        covariance=tuple(tuple(float(v) for v in row) for row in covariance),
        freq_range_hz=(float(min(freqs)), float(max(freqs))),
        input_rate_range_dph=(float(rates.min()), float(rates.max())),
        residual_ppm=float(np.sqrt(np.mean((k - fitted) ** 2))),
        groups=groups, history=tuple(history), weighted=use_weights,
        penter=float(penter), premove=float(premove))


#: JSON Schema (Draft 2020-12) of :meth:`ScaleFactorModel.to_dict`, generated from
#: :class:`ScaleFactorRecord`.
SCALE_FACTOR_JSON_SCHEMA: dict[str, Any] = records.json_schema(
    ScaleFactorRecord, "hrgtc scale-factor model",
    "https://hrgtc.invalid/schema/scale-factor.json")
