"""The drift model: bias from frequency change and its rate by stepwise regression.

Eq. (21)-(22) of [1]: B = B0 + sum_k k_i term_i(f, df/dt), the terms chosen
from candidates by stepwise linear regression (Section 4.1).

Fitting works run by run and chunk by chunk: each chunk's variables are
computed by a causal :class:`~hrgtc.drift.features.FeatureStream` that keeps its
state across chunks, the candidate terms and the measured bias are averaged
into non-overlapping windows (10 s by default), and the regression runs on the
window means. Raw 200 Hz residuals are strongly autocorrelated, so F-tests on
samples would call every term significant; on 10 s means they are much closer
to independent. Memory is bounded by one chunk plus the window means
(1/2000 of the samples at 200 Hz and 10 s). The window means are in memory,
so the selected model's coefficients are refined in extended precision
(:func:`hrgtc.drift.regression.refine`) where ``numpy.longdouble`` is wider than float64.

Variables are scaled internally (f by its largest training magnitude, df/dt
likewise) so every candidate column is of order one; coefficients are
reported in the user's units.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.accounting import Accounting
from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.core.summary import Summary
from hrgtc.drift.cross_validation import (
    CrossValidation,
    cross_validate,
)
from hrgtc.drift.drift_text import drift_equation, drift_summary
from hrgtc.drift.features import (
    FeatureSettings,
    FeatureStream,
    ParsedTerms,
    Term,
    TermName,
    linear_combination,
    tangent_extension,
    variables_for,
)
from hrgtc.drift.fit_checks import (
    training_accounting,
)
from hrgtc.drift.fit_stages import (
    TrainingReading,
    design,
    drift_settings,
    prepare,
    refit_rate_free,
    select,
    window_job,
)
from hrgtc.drift.offsets import fit_offsets, orientation_offset
from hrgtc.drift.stepwise import StepwiseResult
from hrgtc.drift.windows import RunSource, window_means_jointly
from hrgtc.recording import Recording
from hrgtc.settings.drift import DriftSettings
from hrgtc.thermometry import Thermometer

_DRIFT = DriftSettings


@dataclass(frozen=True)
class DriftModel(ParsedTerms, records.Written):
    """A fitted bias model B = B0 + sum k_i term_i (Eq. 22 of [1]).

    Attributes
    ----------
    settings
        How the variables are computed (reference, rate filter, scales).
    candidates
        All candidate terms considered (Eq. 21 by default).
    selected
        Terms kept by the stepwise regression, in candidate order.
    intercept_dph
        B0. [°/h]
    coefficients
        Term name -> coefficient in user units (°/h per term unit).
    standard_errors, pvalues
        Term name -> standard error (user units) and p-value, intercept under ``"const"``.
    scaled_coefficients
        Coefficients on scaled variables, in ``selected`` order (what predict uses).
    stepwise
        The stepwise regression on scaled window means (steps, final fit).
    ranges
        Variable -> (min, max) of the training samples used (after the warm-up, at
        rest); models fitted before issue 20 stored the extremes of the window means.
    window_s
        Window length of the fit. [s]
    n_windows, n_samples
        Size of the training set.
    residual_std_dph, rsquared
        Fit quality on window means. [°/h]
    variance_inflation, bandwidth_windows
        Newey-West correction of the F-tests for autocorrelated window residuals
        (1 and 0 when switched off).
    selection
        How the terms were chosen: ``"stepwise"`` (F-tests) or ``"cv"``.
    cross_validation
        Leave-one-run-out cross-validation of the selected terms (None with one run).
    n_not_at_rest
        Training samples left out because they were not at rest (handling, motion).
    offset_mode, offsets_dph
        The nuisance offsets of the fit (:mod:`hrgtc.drift.offsets`): ``"none"``,
        ``"run"``, ``"orientation"`` or ``"run+orientation"``, and each group's offset
        from ``intercept_dph`` (the windows' mean offset). [°/h]
    orientations
        Unit accelerometer vectors of the trained orientations (empty without them).
    pruning
        The guarded selection's held-out check (folds, terms dropped, scores), or None.
    """

    #: Its record (the model file's ``drift`` and ``housing``) is generated from these
    #: fields; the parsed terms and the training's accounting are not in the file.
    constants = (("kind", "hrgtc.DriftModel"),)
    not_written = ("_terms", "accounting")

    settings: FeatureSettings
    candidates: Annotated[tuple[TermName, ...], Meta(min_length=1)]
    selected: tuple[TermName, ...]
    intercept_dph: float
    coefficients: dict[str, float]
    standard_errors: dict[str, records.Statistic]
    pvalues: dict[str, records.Statistic]
    scaled_coefficients: tuple[float, ...]
    stepwise: StepwiseResult
    ranges: dict[str, records.Range]
    window_s: records.Positive
    n_windows: records.Count
    n_samples: records.Count
    residual_std_dph: records.Statistic
    rsquared: records.Statistic
    variance_inflation: records.Statistic = 1.0
    bandwidth_windows: records.Count = 0
    selection: str = "stepwise"
    cross_validation: CrossValidation | None = None
    n_not_at_rest: int = 0
    offset_mode: str = "none"
    offsets_dph: dict[str, float] = field(default_factory=dict)
    orientations: tuple[tuple[float, ...], ...] = ()
    pruning: dict[str, Any] | None = None
    _terms: tuple[Term, ...] = field(default=(), repr=False, compare=False)
    #: Samples read, used and left out by reason in training (not kept in the model file).
    accounting: Accounting | None = field(default=None, repr=False, compare=False)

    @property
    def history(self) -> tuple[Any, ...]:
        """Steps of the stepwise regression."""
        return self.stepwise.history

    @property
    def variables(self) -> tuple[str, ...]:
        """Variables the selected terms need (at least f and df for compensation)."""
        return variables_for(self._terms) if self._terms else ("f",)

    def predict(self, values: Mapping[str, np.ndarray],
                extrapolation: str = "tangent") -> np.ndarray:
        """Bias from variable arrays (f [Hz], df [Hz/s], ...), Eq. (22) of [1]. [°/h]

        Inside the training ranges this is the fitted polynomial. Beyond them,
        ``extrapolation="tangent"`` (default) continues it along its tangent at the
        edge of the range: a law linear in df/dt stays exact, while the cubic terms of
        a model fitted on a cool-down do not run away on a faster warm-up.
        ``"polynomial"`` evaluates the polynomial anyway; ``"clamp"`` holds each
        variable at the edge (as PX4's thermal calibration holds temperature).
        Samples beyond the ranges are counted by the compensator.
        """
        if not self._terms:
            n = next(iter(values.values())).shape[0]
            return np.full(n, self.intercept_dph)
        args = (self._terms, self.scaled_coefficients)
        if extrapolation == "tangent":
            return tangent_extension(*args, values, self.settings.scales, self.ranges,
                                     self.intercept_dph)
        if extrapolation == "clamp":
            values = {v: (np.clip(x, *self.ranges[v]) if v in self.ranges else x)
                      for v, x in values.items()}
        elif extrapolation != "polynomial":
            raise InputError(f"extrapolation must be 'tangent', 'polynomial' or 'clamp', "
                             f"got {extrapolation!r}")
        return linear_combination(*args, values, self.settings.scales, self.intercept_dph)

    def prediction_std(self, values: Mapping[str, np.ndarray]) -> np.ndarray:
        """1σ uncertainty of :meth:`predict` from the coefficients' covariance. [°/h]

        The model is linear in its coefficients, also where it is continued along its
        tangent, so ``B(x) = J(x)·β`` with ``J`` the intercept's 1 and each term's
        value (tangent-extended, on the scaled variables) and the variance of the
        prediction is ``J Σ Jᵀ``, Σ the covariance of the scaled coefficients of the
        final fit (``stepwise.result.cov_params``, which already carries the
        Newey-West ``variance_inflation`` of the window residuals). It is the
        uncertainty of the fitted line, not of the gyro's noise around it.
        """
        cov = np.asarray(self.stepwise.result.cov_params, dtype=np.float64)
        n = next(iter(values.values())).shape[0]
        columns = [np.ones(n)]
        for k in range(len(self._terms)):
            unit = np.zeros(len(self._terms))
            unit[k] = 1.0
            columns.append(tangent_extension(self._terms, unit, values, self.settings.scales,
                                             self.ranges, 0.0))
        jacobian = np.column_stack(columns)
        variance = np.einsum("ij,jk,ik->i", jacobian, cov, jacobian)
        return np.sqrt(np.maximum(variance, 0.0))

    def coefficient_prior(self) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
        """What an update of the model starts from (issue 29's ``update``, a method of the
        fitted model): the names (``"const"`` and the selected terms), the fit's
        coefficients in user units (B0 before the nuisance offsets, then each term's °/h per
        term unit) and their covariance in user units, the final fit's scaled covariance
        (with its Newey-West inflation) unscaled by each term's factor: Σ = D⁻¹ Σₛ D⁻¹,
        D = diag(1, the scale factors of :attr:`settings`)."""
        factors = np.array([1.0, *(t.scale_factor(self.settings.scales) for t in self._terms)])
        ols = self.stepwise.result
        mean = np.asarray(ols.params, dtype=np.float64) / factors
        covariance = np.asarray(ols.cov_params, dtype=np.float64) / np.outer(factors, factors)
        return ("const", *self.selected), mean, covariance

    def predict_recording(self, recording: Recording, thermometer: Any = None) -> np.ndarray:
        """Bias of a whole recording, filter started at its first sample. [°/h]

        ``thermometer`` (the unit's) is needed when the terms use the gradient ``g``.
        """
        stream = FeatureStream(self.settings, self.variables, thermometer)
        return self.predict(stream.transform(recording))

    def orientation_offset(self, accel: Any) -> float | None:
        """Offset from ``intercept_dph`` of the orientation of a mean accelerometer vector;
        None when it matches no trained orientation (unknown, not guessed). [°/h]"""
        return orientation_offset(self.offsets_dph, self.orientations, accel)

    def equation(self, sensor: bool = False) -> str:
        """The model in Eq. (22) form with numbers, e.g. ``B = 1.2 + 0.3·f - ...``.

        ``sensor``: the thermometer is a temperature sensor (no frequency output),
        so f is its temperature T in °C and df its rate dT/dt in °C/s, not Hz.
        """
        return drift_equation(self, sensor)

    def summary(self, sensor: bool = False) -> Summary:
        """Stepwise history, coefficient table and fit statistics
        (:class:`~hrgtc.core.summary.Summary`; ``.text()`` the plain text).

        ``sensor``: the equation's units are those of a temperature sensor (see
        :meth:`equation`).
        """
        return drift_summary(self, sensor)


#: :class:`DriftModel` in a file, generated from its fields.
DriftModelRecord = records.record_of(
    DriftModel, doc="A :class:`DriftModel` in a file (the model file's ``drift`` and "
    "``housing``).")


def fit(
    runs: Sequence[RunSource],
    thermometer: Thermometer,
    settings: DriftSettings | None = None,
    *,
    reading: TrainingReading | None = None,
    aux_columns: Mapping[str, str] | None = None,
    excitation_runs: int = 0,
    initial: Iterable[str] | None = None,
    progress: Progress | None = None,
    **overrides: Any,
) -> DriftModel:
    """Fit the drift model of Eq. (21)-(22) of [1] by stepwise regression on window means.

    Parameters
    ----------
    runs
        Training runs: :class:`Recording` objects or callables yielding chunks
        of one run each (for files larger than memory).
    thermometer
        The unit's thermometer; gives f_ref = f(reference_c).
    settings
        The fit's settings, whole (:class:`~hrgtc.settings.drift.DriftSettings`: candidate
        terms, window, stepwise thresholds, reference, df/dt filter, warm-up, selection,
        offsets, autocorrelation, hierarchy and the variables' options; each field's help
        says what it does). Default: the defaults.
    reading
        How the runs are read (:class:`~hrgtc.drift.fit_stages.TrainingReading`: motion,
        gaps, the at-rest passes shared between fits).
    aux_columns
        Extra channel name -> recording column, for candidates in ``a_NAME``; each is
        centred on its training mean (stored in the settings).
    excitation_runs
        How many leading runs must each show a temperature change and df/dt
        variation on their own (the user's drift runs, when soaks follow them);
        the runs together are always checked.
    initial
        Terms in the starting model.
    progress
        Optional ``callback(samples_done, 0)``.
    **overrides
        Fields of ``settings`` by name (``terms=("f", "df")``, ``premove=0.2``; ``terms``
        may hold :class:`Term` s; ``options``: the variables' options by name, e.g.
        ``{"rate_tau2_s": 120.0}``).

    Returns
    -------
    DriftModel
    """
    drift, candidates, options = drift_settings(settings, overrides)
    training = prepare(runs, thermometer, drift, candidates, options,
                       reading or TrainingReading(), aux_columns)
    first = design(training, drift, thermometer, progress, excitation_runs)
    chosen = select(training, first, drift, thermometer, initial)
    return _model(training, first, refit_rate_free(training, first, chosen, drift), chosen,
                  drift)


@dataclass(frozen=True)
class FitRequest:
    """One fit of :func:`fit_jointly`: the arguments of :func:`fit` that differ between fits
    on the same runs."""

    settings: DriftSettings
    aux_columns: Mapping[str, str] | None = None
    excitation_runs: int = 0
    progress: Progress | None = None


def fit_jointly(runs: Sequence[RunSource], thermometer: Thermometer,
                requests: Sequence[FitRequest], *, reading: TrainingReading | None = None,
                ) -> list[DriftModel | Exception]:
    """:func:`fit` of each request on the same runs, their window means from one reading of
    the runs (the drift model and the housing baseline of a calibration: one pass, not one
    per fit). Each model is the one its own :func:`fit` gives; a fit after the first that
    fails gives its error in its place (the first fit's error is raised)."""
    reading = reading or TrainingReading()
    staged: list[Any] = []
    for k, request in enumerate(requests):  # the runs' first look, each fit's own
        try:
            drift, candidates, options = drift_settings(request.settings, {})
            training = prepare(runs, thermometer, drift, candidates, options, reading,
                               request.aux_columns)
            staged.append((drift, training, window_job(training, drift, thermometer,
                                                       request.progress)))
        except Exception as exc:  # a later fit's own failure, given back
            if k == 0:
                raise
            staged.append(exc)
    ready = [s for s in staged if not isinstance(s, Exception)]
    read = iter(window_means_jointly(runs, [job for _, _, job in ready]))
    out: list[DriftModel | Exception] = []
    for k, (request, stage) in enumerate(zip(requests, staged, strict=True)):
        if isinstance(stage, Exception):
            out.append(stage)
            continue
        windows = next(read)
        try:
            if isinstance(windows, Exception):
                raise windows
            drift, training, _ = stage
            first = design(training, drift, thermometer, request.progress,
                           request.excitation_runs, windows)
            chosen = select(training, first, drift, thermometer, None)
            out.append(_model(training, first, refit_rate_free(training, first, chosen, drift),
                              chosen, drift))
        except Exception as exc:  # a later fit's own failure, given back
            if k == 0:
                raise
            out.append(exc)
    return out


def _model(training: Any, first: Any, made: Any, chosen: Any, drift: DriftSettings,
           ) -> DriftModel:
    """The fitted model from the stages of :func:`fit` (``first``: the F-tests' design,
    ``made``: the final one, the rate-free refit's when there was one)."""
    result, windows, names = chosen.result, made.windows, training.names
    ols = result.result
    selected = result.selected
    selected_factor = {t.name: t.scale_factor(made.scales) for t in training.candidates}
    params = np.asarray(ols.params)
    bse = np.asarray(ols.bse)
    pvalues = np.asarray(ols.pvalues)
    coefficients = {n: float(params[k + 1] / selected_factor[n]) for k, n in enumerate(selected)}
    errors = {"const": float(bse[0])}
    errors.update({n: float(bse[k + 1] / selected_factor[n]) for k, n in enumerate(selected)})
    pv = {"const": float(pvalues[0])}
    pv.update({n: float(pvalues[k + 1]) for k, n in enumerate(selected)})
    intercept, group_offsets = fit_offsets(made.groups, windows.bias_dph, made.x_full, names,
                                           selected, params, float(params[0]))
    validated = len(first.windows.sources) >= 2  # leave-one-run-out on the F-tests' windows
    return DriftModel(
        settings=training.features, candidates=names, selected=tuple(selected),
        intercept_dph=intercept, coefficients=coefficients, standard_errors=errors,
        pvalues=pv, scaled_coefficients=tuple(float(p) for p in params[1:]),
        stepwise=result,
        # the extremes of the samples used (not of the window means, which are narrower):
        # the model's own training file is inside its ranges by construction
        ranges={v: windows.extremes[v] for v in windows.variables},
        window_s=float(drift.window_s), n_windows=int(windows.bias_dph.size),
        n_samples=windows.n_samples, residual_std_dph=float(ols.residual_std),
        rsquared=float(ols.rsquared) if math.isfinite(ols.rsquared) else float("nan"),
        variance_inflation=float(chosen.inflation), bandwidth_windows=int(chosen.bandwidth),
        selection=drift.select,
        cross_validation=cross_validate(first.x_scaled, first.bias, first.windows.run, names,
                                        selected, windows.sources, chosen.rate,
                                        chosen.slope_sign) if validated else None,
        n_not_at_rest=windows.n_not_at_rest, offset_mode=made.groups.mode,
        offsets_dph=group_offsets, orientations=made.groups.orientations,
        pruning=chosen.pruning, accounting=training_accounting(windows),
    )
