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

import dataclasses
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Annotated, Any, Literal

import numpy as np
from msgspec import Meta

from hrgtc.core import records
from hrgtc.core.accounting import Accounting
from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.drift.cross_validation import (
    CrossValidation,
    CrossValidationRecord,
    cross_validate,
    guard_selection,
    select_terms,
)
from hrgtc.drift.drift_text import drift_equation, drift_summary
from hrgtc.drift.features import (
    EQ21,
    FeatureSettings,
    FeatureSettingsRecord,
    FeatureStream,
    ParsedTerms,
    Term,
    TermName,
    hierarchy,
    linear_combination,
    parse_terms,
    tangent_extension,
    variables_for,
)
from hrgtc.drift.fit_checks import (
    check_excitation,
    given_options,
    registry_entries,
    training_accounting,
)
from hrgtc.drift.offsets import fit_offsets, offset_groups, orientation_offset, project_off
from hrgtc.drift.regression import EXTENDED_PRECISION, newey_west_inflation
from hrgtc.drift.rest import check_policy, reference_point, run_rest
from hrgtc.drift.stepwise import StepwiseRecord, StepwiseResult, stepwise
from hrgtc.drift.windows import RunSource, _iter_run, window_means, window_means_at
from hrgtc.recording import Recording
from hrgtc.recording.motion import MotionSettings
from hrgtc.settings.drift import SELECTIONS, WARMUP_FACTOR, DriftSettings
from hrgtc.thermometry import Thermometer

_DRIFT = DriftSettings



@dataclass(frozen=True)
class DriftModel(ParsedTerms):
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

    settings: FeatureSettings
    candidates: tuple[str, ...]
    selected: tuple[str, ...]
    intercept_dph: float
    coefficients: dict[str, float]
    standard_errors: dict[str, float]
    pvalues: dict[str, float]
    scaled_coefficients: tuple[float, ...]
    stepwise: StepwiseResult
    ranges: dict[str, tuple[float, float]]
    window_s: float
    n_windows: int
    n_samples: int
    residual_std_dph: float
    rsquared: float
    variance_inflation: float = 1.0
    bandwidth_windows: int = 0
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

    def summary(self, sensor: bool = False) -> str:
        """Stepwise history, coefficient table and fit statistics as text.

        ``sensor``: the equation's units are those of a temperature sensor (see
        :meth:`equation`).
        """
        return drift_summary(self, sensor)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types, as :class:`DriftModelRecord` writes them (NaN -> None)."""
        return records.dump(self, DriftModelRecord)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> DriftModel:
        """Inverse of :meth:`to_dict` (checked against :class:`DriftModelRecord`)."""
        values = records.load(data, DriftModelRecord, "drift-model")
        values.pop("kind")
        validation = values["cross_validation"]
        try:
            return cls(**{**values, "settings": FeatureSettings(**values["settings"]),
                          "stepwise": StepwiseResult.from_dict(values["stepwise"]),
                          "cross_validation": None if validation is None
                          else CrossValidation(sources=tuple(validation["per_run_dph"]),
                                               **validation),
                          "pruning": None if values["pruning"] is None
                          else dict(values["pruning"])})
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise InputError(f"not a valid drift-model record: {exc!r}") from exc


class DriftModelRecord(records.Record, kw_only=True):
    """A :class:`DriftModel` in a file (the model file's ``drift`` and ``housing``)."""

    kind: Literal["hrgtc.DriftModel"] = "hrgtc.DriftModel"
    settings: FeatureSettingsRecord
    candidates: Annotated[tuple[TermName, ...], Meta(min_length=1)]
    selected: tuple[TermName, ...]
    intercept_dph: float
    coefficients: dict[str, float]
    standard_errors: dict[str, records.Statistic]
    pvalues: dict[str, records.Statistic]
    scaled_coefficients: tuple[float, ...]
    stepwise: StepwiseRecord
    ranges: dict[str, records.Range]
    window_s: records.Positive
    n_windows: records.Count
    n_samples: records.Count
    residual_std_dph: records.Statistic
    rsquared: records.Statistic
    variance_inflation: records.Statistic = 1.0
    bandwidth_windows: records.Count = 0
    selection: str = "stepwise"
    cross_validation: CrossValidationRecord | None = None
    n_not_at_rest: int = 0
    offset_mode: str = "none"
    offsets_dph: dict[str, float] = records.empty()
    orientations: tuple[tuple[float, ...], ...] = ()
    pruning: dict[str, Any] | None = None


def _design(windows: Any, offsets: str, factors: np.ndarray) -> tuple[Any, np.ndarray,
                                                                        np.ndarray, np.ndarray]:
    """The offset groups, the scaled design matrix and, with the offsets projected off
    (Frisch-Waugh-Lovell: they are always in), the design and bias the selection sees."""
    powered = windows.power_run is not None  # a logger restart starts a run of its own
    groups = offset_groups(offsets, windows.power_run if powered else windows.run,
                           windows.power_runs if powered else windows.sources,
                           windows.accel, windows.orientation)
    x_full = windows.terms / factors
    x_scaled, bias = x_full, windows.bias_dph
    if groups.mode != "none":
        x_scaled, bias = project_off(groups, x_full, windows.bias_dph)
    return groups, x_full, x_scaled, bias


def fit(
    runs: Sequence[RunSource],
    thermometer: Thermometer,
    terms: Iterable[str | Term] = EQ21,
    window_s: float = _DRIFT.window_s,
    penter: float = _DRIFT.penter,
    premove: float | None = None,
    *,
    initial: Iterable[str] | None = None,
    reference_c: float | None = None,
    rate_tau_s: float = _DRIFT.rate_tau_s,
    options: Mapping[str, Any] | None = None,
    aux_columns: Mapping[str, str] | None = None,
    warmup_s: float | None = None,
    autocorrelation: str = _DRIFT.autocorrelation,
    hierarchical: bool = _DRIFT.hierarchical,
    excitation_runs: int = 0,
    select: str = _DRIFT.select,
    progress: Progress | None = None,
    motion: str = "exclude",
    motion_settings: MotionSettings | None = None,
    offsets: str = _DRIFT.offsets,
    gaps: str = "bridge",
    restart_each_segment: bool = False,
    rest_cache: dict[tuple[int, str, Any, float], Any] | None = None,
) -> DriftModel:
    """Fit the drift model of Eq. (21)-(22) of [1] by stepwise regression on window means.

    Parameters
    ----------
    runs
        Training runs: :class:`Recording` objects or callables yielding chunks
        of one run each (for files larger than memory).
    thermometer
        The unit's thermometer; gives f_ref = f(reference_c).
    terms
        Candidate terms (Eq. 21's nine by default).
    window_s
        Length of the averaging windows the regression runs on. [s]
    penter, premove
        Stepwise thresholds (MATLAB ``stepwisefit`` semantics).
    initial
        Terms in the starting model.
    reference_c
        Reference temperature of f. [°C] Default None: f is centred on the training
        data (the mean frequency of the still samples used), so the model does not
        depend on an arbitrary temperature offset or reference; its temperature is
        stored as ``settings.reference_c``.
    rate_tau_s
        Time constant of each stage of the causal df/dt filter. [s]
    options
        The options the drift variables declare (the fields of
        :data:`~hrgtc.settings.drift.DriftSettings` from their modules' ``Options``), by
        name: ``{"rate_tau2_s": 120.0}`` for the second df/dt filter of ``d2`` (default
        ``TAU2_FACTOR`` × ``rate_tau_s``); an option not given takes its default. Each
        variable the candidates use takes its settings from them (its ``derive``).
    aux_columns
        Extra channel name -> recording column, for candidates in ``a_NAME``; each is
        centred on its training mean (stored in the settings).
    warmup_s
        Start of each run left out while the filters settle; default 5 × the
        longest time constant. [s]
    excitation_runs
        How many leading runs must each show a temperature change and df/dt
        variation on their own (the user's drift runs, when soaks follow them);
        the runs together are always checked.
    autocorrelation
        ``"newey-west"`` (default): divide the stepwise F statistics by the
        long-run/plain variance ratio of the full candidate model's window
        residuals (bandwidth n^(1/3) windows), because bias instability and rate
        random walk keep 10 s means correlated and plain F-tests then admit terms
        that fit noise and extrapolate badly. ``"none"``: plain ``stepwisefit``.
    hierarchical
        Marginality (default): a term enters only after its lower-order parents and
        leaves only after its children; False gives MATLAB's plain ``stepwisefit``.
    select
        ``"guarded"`` (default): the stepwise F-tests, then every selected term that does
        not carry over to held-out data is dropped (:func:`~hrgtc.drift.cross_validation.
        prune_terms`; folds are the runs, or five contiguous time blocks of a single
        run): a cubic fitted on the temperatures of the training part does not survive
        the held-out block beyond them. On a single run a term beyond the line in ``f``
        must also beat the slow noise (random walk) of the training windows
        (:mod:`hrgtc.drift.slow_noise`). ``"stepwise"``: the F-tests alone. ``"cv"``:
        forward selection by leave-one-run-out cross-validated bias stability
        (:mod:`hrgtc.drift.cross_validation`; needs two runs or more). Either way the
        selected model is cross-validated when there are two runs or more.
    motion, motion_settings
        ``"exclude"`` (default): samples not at rest (:mod:`hrgtc.recording.motion`)
        are left out of the windows and counted, so every trained range comes from the
        samples used; ``"keep"``: no check; ``"error"``: motion is an error.
    offsets
        Nuisance offsets (:mod:`hrgtc.drift.offsets`): ``"auto"`` (default: one per
        orientation when the runs log accelerometer axes or an ``orientation`` label,
        else none), ``"none"``, ``"run"``, ``"orientation"``, ``"run+orientation"``.
    progress
        Optional ``callback(samples_done, 0)``.
    gaps, restart_each_segment
        How the time axis's gaps are treated (see
        :func:`hrgtc.drift.windows.window_means`): ``"split"`` restarts the df/dt
        filter after every gap, ``"bridge"`` (default) carries it across; windows never
        span a gap; the warm-up counts from the run's start (from every segment's with
        ``restart_each_segment``).
    rest_cache
        A dict shared by fits on the same ``runs`` (the drift model and the housing
        baseline): each run's pass of the at-rest detector is kept there, by run, policy,
        settings and warm-up, and a later fit takes it instead of reading the run again.

    Returns
    -------
    DriftModel
    """
    candidates = tuple(t if isinstance(t, Term) else parse_terms([t])[0] for t in terms)
    names = tuple(t.name for t in candidates)
    if len(set(names)) != len(names):
        raise InputError(f"candidate terms listed twice: {names}")
    runs = list(runs)
    if not runs:
        raise InputError("no drift runs given; pass at least one ramp recording")
    head = _iter_run(runs[0])
    try:
        first = next(head)
    except StopIteration:
        raise InputError("the first drift run holds no samples") from None
    finally:
        head.close()
    variables = variables_for(candidates)
    given = given_options(options, rate_tau_s, aux_columns)
    used = registry_entries(variables)
    derived: dict[str, Any] = {}
    for entry, own in used:  # the settings each variable takes from the options
        if entry.derive is not None:
            derived.update(entry.derive(own, given))
    taus = [derived[e.rate_of[1]] for e, _ in used if e.rate_of and e.rate_of[1] in derived]
    warmup = WARMUP_FACTOR * max([rate_tau_s, *taus]) if warmup_s is None else warmup_s
    check_policy(motion)
    rests = []
    for number, run in enumerate(runs):
        key = (number, motion, motion_settings, float(warmup))
        if rest_cache is not None and key in rest_cache:
            rests.append(rest_cache[key])
            continue
        rests.append(run_rest(_iter_run(run), motion, motion_settings, warmup))
        if rest_cache is not None:
            rest_cache[key] = rests[-1]
    keep = None if motion == "keep" else [r.keep for r in rests]
    reference_freq, reference_c = reference_point(rests, thermometer, reference_c, warmup)
    settings = FeatureSettings(
        reference_freq_hz=float(reference_freq),
        sample_rate_hz=first.metadata.sample_rate_hz,
        reference_c=float(reference_c),
        rate_tau_s=rate_tau_s,
        warmup_s=warmup,
        **derived,
    )
    passes = [(e.first_pass, own) for e, own in used if e.first_pass is not None]
    if passes:  # what the variables learn from the runs (dpos's switch, the channels' centres)
        reads = tuple(dict.fromkeys(v for p, own in passes for v in p.reads(own)))
        means = window_means(runs, settings, parse_terms(reads), window_s,
                             keep=keep, gaps=gaps,
                             restart_each_segment=restart_each_segment).variables
        update: dict[str, Any] = {}
        for first_pass, own in passes:
            update.update(first_pass.derive(own, means))
        settings = FeatureSettings(**{**settings.to_dict(), **update})
    # df/dt's training range is kept for the range warnings even when no candidate uses it
    tracked = ("df",) if "f" in variables else ()
    # the rate-free refit's windows (warm-up 0, below) come from the same reading
    refit = warmup_s is None and settings.warmup_s > 0
    windows, *rate_free = window_means_at(
        runs, settings, candidates, window_s, progress, thermometer, tracked, keep=keep,
        gaps=gaps, restart_each_segment=restart_each_segment,
        warmups_s=(settings.warmup_s, 0.0) if refit else None)
    for run in range(min(excitation_runs, len(windows.sources))):
        check_excitation(windows, thermometer, variables, run)
    check_excitation(windows, thermometer, variables)
    scales = {}
    for v in variables:
        magnitude = float(np.max(np.abs(windows.variables[v])))
        scales[v] = magnitude if magnitude > 0 else 1.0
    settings = FeatureSettings(**{**settings.to_dict(), "scales": scales})
    factors = np.array([t.scale_factor(scales) for t in candidates])
    groups, x_full, x_scaled, bias = _design(windows, offsets, factors)
    if autocorrelation == "newey-west":
        design = np.column_stack([np.ones(x_scaled.shape[0]), x_scaled])
        solution = np.linalg.lstsq(design, bias, rcond=None)[0]
        inflation, bandwidth = newey_west_inflation(bias - design @ solution)
    elif autocorrelation == "none":
        inflation, bandwidth = 1.0, 0
    else:
        raise InputError(
            f"autocorrelation must be 'newey-west' or 'none', got {autocorrelation!r}"
        )
    if select not in SELECTIONS:
        raise InputError(f"select must be one of {', '.join(SELECTIONS)}, got {select!r}")
    n_runs = len(windows.sources)
    if select == "cv" and n_runs < 2:
        raise InputError("select='cv' needs two training runs or more (leave-one-run-out)")
    slope_sign = 1.0 if thermometer.slope_hz_per_c(reference_c) >= 0 else -1.0
    rate = windows.variables.get("df", np.zeros(windows.bias_dph.size))
    cv_args = (x_scaled, bias, windows.run, names)
    parents = hierarchy(candidates) if hierarchical else None
    result = stepwise(x_scaled, bias, names=names, penter=penter, premove=premove,
                      initial=initial, variance_inflation=inflation, parents=parents,
                      refine=EXTENDED_PRECISION)  # quietly unrefined without long double
    chosen = None
    pruning = None
    if select == "cv":  # from the stepwise terms, one-term changes that cross-validate better
        chosen = select_terms(*cv_args, windows.sources, rate, slope_sign, parents=parents,
                              initial=result.selected)
    elif select == "guarded" and (result.selected or np.unique(windows.run).size == 1):
        chosen, pruning = guard_selection(
            x_scaled, bias, windows.run, windows.time_s, names, result.selected,
            parents=hierarchy(candidates), keep=[parse_terms([t])[0].name for t in initial or ()],
            temperature=windows.variables.get("f"), line_test=(penter, premove))
    if chosen is not None:
        history = result.history
        result = stepwise(x_scaled, bias, names=names, penter=penter,
                          premove=premove, initial=chosen, variance_inflation=inflation,
                          max_steps=0, refine=EXTENDED_PRECISION)
        if select == "guarded":  # the F-test steps stay on record; the pruning is in `pruning`
            result = dataclasses.replace(result, history=history)
    chosen_terms = [t for t in candidates if t.name in result.selected]
    if refit and not any(
            entry.rate_of for entry, _ in registry_entries(variables_for(chosen_terms))):
        # no rate term chosen: nothing waits for the df/dt filter to settle, so the run's
        # first warmup_s (at rest, and often its most extreme temperature) is trained on
        # too, and the compensation flags no settling (docs/real-loggers/corpus.md)
        # (df/dt's range, kept for the warnings, then spans the filter's start too: the
        # model's own file stays inside it)
        settings = FeatureSettings(**{**settings.to_dict(), "warmup_s": 0.0})
        windows = rate_free[0]
        groups, x_full, x_scaled, bias = _design(windows, offsets, factors)
        history = result.history
        result = dataclasses.replace(
            stepwise(x_scaled, bias, names=names, penter=penter, premove=premove,
                     initial=result.selected, variance_inflation=inflation, max_steps=0,
                     refine=EXTENDED_PRECISION), history=history)
    ols = result.result
    selected = result.selected
    selected_factor = {t.name: t.scale_factor(scales) for t in candidates}
    params = np.asarray(ols.params)
    bse = np.asarray(ols.bse)
    pvalues = np.asarray(ols.pvalues)
    coefficients = {n: float(params[k + 1] / selected_factor[n]) for k, n in enumerate(selected)}
    errors = {"const": float(bse[0])}
    errors.update({n: float(bse[k + 1] / selected_factor[n]) for k, n in enumerate(selected)})
    pv = {"const": float(pvalues[0])}
    pv.update({n: float(pvalues[k + 1]) for k, n in enumerate(selected)})
    # the extremes of the samples used (not of the window means, which are narrower):
    # the model's own training file is inside its ranges by construction
    ranges = {v: windows.extremes[v] for v in windows.variables}
    intercept, group_offsets = fit_offsets(groups, windows.bias_dph, x_full, names, selected,
                                           params, float(params[0]))
    return DriftModel(
        settings=settings,
        candidates=names,
        selected=tuple(selected),
        intercept_dph=intercept,
        coefficients=coefficients,
        standard_errors=errors,
        pvalues=pv,
        scaled_coefficients=tuple(float(p) for p in params[1:]),
        stepwise=result,
        ranges=ranges,
        window_s=float(window_s),
        n_windows=int(windows.bias_dph.size),
        n_samples=windows.n_samples,
        residual_std_dph=float(ols.residual_std),
        rsquared=float(ols.rsquared) if math.isfinite(ols.rsquared) else float("nan"),
        variance_inflation=float(inflation),
        bandwidth_windows=int(bandwidth),
        selection=select,
        cross_validation=cross_validate(*cv_args, selected, windows.sources, rate, slope_sign)
        if n_runs >= 2 else None,
        n_not_at_rest=windows.n_not_at_rest,
        offset_mode=groups.mode,
        offsets_dph=group_offsets,
        orientations=groups.orientations,
        pruning=pruning,
        accounting=training_accounting(windows),
    )

