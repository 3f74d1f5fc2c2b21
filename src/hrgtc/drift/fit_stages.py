"""The stages of :func:`hrgtc.drift.drift_model.fit`, in the order it runs them.

1. :func:`drift_settings`: the settings object, whole (``DriftSettings``), with the
   keyword overrides of a library call, and the candidate terms;
2. :func:`prepare`: the first look at the runs -- the variables' options, the warm-up,
   each run's samples at rest, the reference point, what the variables learn from a
   first pass (:class:`Training`);
3. :func:`design`: the window means, the excitation checks, the scales and the design
   matrix with the nuisance offsets projected off (:class:`Design`);
4. :func:`select`: the F-tests' autocorrelation correction, the stepwise regression and
   the guarded or cross-validated choice of terms (:class:`Selection`);
5. :func:`refit_rate_free`: a model with no rate term is trained from the run's start.

Each stage takes what the one before it made; ``fit`` assembles the model.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.progress import Progress
from hrgtc.drift.cross_validation import Windowed, guard_selection, select_terms
from hrgtc.drift.features import EQ21, FeatureSettings, Term, hierarchy, parse_terms, variables_for
from hrgtc.drift.fit_checks import check_excitation, given_options, registry_entries
from hrgtc.drift.offsets import offset_groups, project_off
from hrgtc.drift.regression import EXTENDED_PRECISION, newey_west_inflation
from hrgtc.drift.rest import check_policy, reference_point, run_rest
from hrgtc.drift.stepwise import StepwiseResult, StepwiseRules, stepwise
from hrgtc.drift.windows import (
    RunSource,
    Windowing,
    WindowJob,
    _iter_run,
    window_means_at,
    window_means_jointly,
)
from hrgtc.recording.motion import MotionSettings
from hrgtc.settings.drift import SELECTIONS, WARMUP_FACTOR, DriftSettings

__all__ = ["Design", "Selection", "Training", "TrainingReading", "design", "drift_settings",
           "fit_warmup", "prepare", "refit_rate_free", "rest_key", "select",
           "window_job"]


@dataclass(frozen=True)
class TrainingReading:
    """How the training runs are read for the fit.

    Attributes
    ----------
    motion, motion_settings
        ``"exclude"`` (default): samples not at rest (:mod:`hrgtc.recording.motion`) are
        left out of the windows and counted, so every trained range comes from the
        samples used; ``"keep"``: no check; ``"error"``: motion is an error.
    gaps, restart_each_segment
        How the time axis's gaps are treated (:func:`hrgtc.drift.windows.window_means`):
        ``"split"`` restarts the df/dt filter after every gap, ``"bridge"`` (default)
        carries it across; windows never span a gap; the warm-up counts from the run's
        start (from every segment's with ``restart_each_segment``).
    rest_cache
        A dict shared by fits on the same runs (the drift model and the housing
        baseline): each run's pass of the at-rest detector is kept there, by run, policy,
        settings and warm-up, and a later fit takes it instead of reading the run again.
    """

    motion: str = "exclude"
    motion_settings: MotionSettings | None = None
    gaps: str = "bridge"
    restart_each_segment: bool = False
    rest_cache: dict[Any, Any] | None = field(default=None, compare=False)


def drift_settings(settings: DriftSettings | None, overrides: Mapping[str, Any],
                   ) -> tuple[DriftSettings, tuple[Term, ...], dict[str, Any]]:
    """``settings`` (default: the defaults) with ``overrides`` (its fields by name;
    ``options``: the drift variables' options, by name), the candidate terms (``terms``:
    names or :class:`Term` s; default Eq. 21's nine) and the variables' options."""
    drift = settings or DriftSettings()
    given = dict(overrides)
    terms = given.pop("terms", None)
    options = dict(given.pop("options", None) or {})
    fields = {f.name for f in dataclasses.fields(drift)}
    unknown = sorted(set(given) - fields)
    if unknown:
        raise TypeError(f"fit() got unexpected keyword argument(s) {unknown}")
    drift = dataclasses.replace(drift, **given) if given else drift
    terms = drift.terms if terms is None else terms
    candidates = tuple(t if isinstance(t, Term) else parse_terms([t])[0]
                       for t in (EQ21 if terms is None else terms))
    names = tuple(t.name for t in candidates)
    if len(set(names)) != len(names):
        raise InputError(f"candidate terms listed twice: {names}")
    return drift, candidates, {**drift.variable_options(), **options}


@dataclass
class Training:
    """What the fit knows of its runs before the window means: the runs, the candidates,
    the variables' settings, the warm-up and each run's samples at rest."""

    runs: list[RunSource]
    candidates: tuple[Term, ...]
    variables: tuple[str, ...]
    features: FeatureSettings
    warmup_s: float
    keep: list[np.ndarray] | None
    reference_c: float
    reading: TrainingReading

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(t.name for t in self.candidates)

    def windows(self, drift: DriftSettings, terms: Sequence[Term], progress: Progress | None = None,
                thermometer: Any = None, tracked: Sequence[str] = (),
                warmups_s: Sequence[float] | None = None) -> tuple[Any, ...]:
        """The window means of ``terms`` over the runs (at rest, after the warm-up), one
        result per warm-up of ``warmups_s`` from one reading (default: the settings')."""
        windowing = Windowing(drift.window_s, tuple(tracked), self.reading.gaps,
                              self.reading.restart_each_segment)
        return window_means_at(self.runs, self.features, terms, windowing, progress,
                               thermometer, self.keep, warmups_s)


def prepare(runs: Sequence[RunSource], thermometer: Any, drift: DriftSettings,
            candidates: tuple[Term, ...], options: Mapping[str, Any],
            reading: TrainingReading, aux_columns: Mapping[str, str] | None) -> Training:
    """The first look at the runs (stage 2 of the module docstring)."""
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
    warmup, derived, used = _warmup(drift, candidates, options, aux_columns)
    rests = _rests(runs, reading, float(warmup))
    keep = None if reading.motion == "keep" else [r.keep for r in rests]
    reference_freq, reference_c = reference_point(rests, thermometer, drift.reference_c, warmup)
    features = FeatureSettings(reference_freq_hz=float(reference_freq),
                               sample_rate_hz=first.metadata.sample_rate_hz,
                               reference_c=float(reference_c), rate_tau_s=drift.rate_tau_s,
                               warmup_s=warmup, **derived)
    training = Training(runs, candidates, variables, features, warmup, keep,
                        float(reference_c), reading)
    passes = [(e.first_pass, own) for e, own in used if e.first_pass is not None]
    if passes:  # what the variables learn from the runs (dpos's switch, the channels' centres)
        reads = tuple(dict.fromkeys(v for p, own in passes for v in p.reads(own)))
        means = training.windows(drift, parse_terms(reads))[0].variables
        update: dict[str, Any] = {}
        for first_pass, own in passes:
            update.update(first_pass.derive(own, means))
        training.features = FeatureSettings(**{**features.to_dict(), **update})
    return training


def _warmup(drift: DriftSettings, candidates: tuple[Term, ...], options: Mapping[str, Any],
            aux_columns: Mapping[str, str] | None) -> tuple[float, dict[str, Any], Any]:
    """The fit's warm-up [s], the settings the variables derive from the options, and the
    registry entries of the variables."""
    given = given_options(options, drift.rate_tau_s, aux_columns)
    used = registry_entries(variables_for(candidates))
    derived: dict[str, Any] = {}
    for entry, own in used:  # the settings each variable takes from the options
        if entry.derive is not None:
            derived.update(entry.derive(own, given))
    taus = [derived[e.rate_of[1]] for e, _ in used if e.rate_of and e.rate_of[1] in derived]
    warmup = (WARMUP_FACTOR * max([drift.rate_tau_s, *taus]) if drift.warmup_s is None
              else drift.warmup_s)
    return warmup, derived, used


def fit_warmup(settings: DriftSettings, aux_columns: Mapping[str, str] | None = None) -> float:
    """The warm-up [s] a fit with ``settings`` leaves out (the df/dt filters' settling)."""
    drift, candidates, options = drift_settings(settings, {})
    return float(_warmup(drift, candidates, options, aux_columns)[0])


def rest_key(number: int, reading: TrainingReading, warmup: float) -> tuple[Any, ...]:
    """The key of run ``number``'s at-rest pass in ``reading.rest_cache`` for a fit whose
    warm-up is ``warmup`` (:func:`fit_warmup`): a caller that met the run's rows before the
    fit (``calibrate``'s soak plateaus) puts its :func:`~hrgtc.drift.rest.run_rest` there,
    and the fit reads the run once fewer."""
    return (number, reading.motion, reading.motion_settings, float(warmup))


def _rests(runs: list[RunSource], reading: TrainingReading, warmup: float) -> list[Any]:
    """Each run's samples at rest (from ``reading.rest_cache`` where a fit saw them)."""
    check_policy(reading.motion)
    rests = []
    for number, run in enumerate(runs):
        key = rest_key(number, reading, warmup)
        cache = reading.rest_cache
        if cache is not None and key in cache:
            rests.append(cache[key])
            continue
        rests.append(run_rest(_iter_run(run), reading.motion, reading.motion_settings, warmup))
        if cache is not None:
            cache[key] = rests[-1]
    return rests


@dataclass
class Design:
    """The window means and the regression's design (stage 3)."""

    windows: Any
    scales: dict[str, float]
    factors: np.ndarray
    groups: Any
    x_full: np.ndarray
    x_scaled: np.ndarray
    bias: np.ndarray
    #: The windows with no warm-up (for stage 5), from the same reading; None: not needed.
    rate_free: Any = None


def design_matrix(windows: Any, offsets: str, factors: np.ndarray) -> tuple[
        Any, np.ndarray, np.ndarray, np.ndarray]:
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


def window_job(training: Training, drift: DriftSettings, thermometer: Any,
               progress: Progress | None) -> WindowJob:
    """Stage 3's window means as a job of one pass over the runs
    (:func:`~hrgtc.drift.windows.window_means_jointly`: fits on the same runs share it)."""
    # df/dt's training range is kept for the range warnings even when no candidate uses it
    tracked = ("df",) if "f" in training.variables else ()
    # the rate-free refit's windows (warm-up 0, stage 5) come from the same reading
    refit = drift.warmup_s is None and training.features.warmup_s > 0
    windowing = Windowing(drift.window_s, tracked, training.reading.gaps,
                          training.reading.restart_each_segment)
    return WindowJob(training.features, training.candidates, windowing, progress, thermometer,
                     training.keep, (training.features.warmup_s, 0.0) if refit else None)


def design(training: Training, drift: DriftSettings, thermometer: Any,
           progress: Progress | None, excitation_runs: int,
           read: tuple[Any, ...] | None = None) -> Design:
    """Stage 3: window means, excitation checks, scales and the design matrix (``read``:
    the window means of :func:`window_job`, already read; None: read them here)."""
    variables = training.variables
    if read is None:
        read = window_means_jointly(training.runs,
                                    [window_job(training, drift, thermometer, progress)])[0]
    windows, *rate_free = read
    for run in range(min(excitation_runs, len(windows.sources))):
        check_excitation(windows, thermometer, variables, run)
    check_excitation(windows, thermometer, variables)
    scales = {}
    for v in variables:
        magnitude = float(np.max(np.abs(windows.variables[v])))
        scales[v] = magnitude if magnitude > 0 else 1.0
    training.features = FeatureSettings(**{**training.features.to_dict(), "scales": scales})
    factors = np.array([t.scale_factor(scales) for t in training.candidates])
    return Design(windows, scales, factors, *design_matrix(windows, drift.offsets, factors),
                  rate_free=rate_free[0] if rate_free else None)


@dataclass
class Selection:
    """The stepwise regression and the terms chosen (stage 4)."""

    result: StepwiseResult
    pruning: dict[str, Any] | None
    inflation: float
    bandwidth: int
    slope_sign: float
    rate: np.ndarray


def select(training: Training, made: Design, drift: DriftSettings, thermometer: Any,
           initial: Sequence[str] | None) -> Selection:
    """Stage 4: the F-tests (Newey-West corrected), then the guarded or cross-validated
    choice; the chosen terms refitted."""
    x_scaled, bias, windows, names = made.x_scaled, made.bias, made.windows, training.names
    if drift.autocorrelation == "newey-west":
        matrix = np.column_stack([np.ones(x_scaled.shape[0]), x_scaled])
        solution = np.linalg.lstsq(matrix, bias, rcond=None)[0]
        inflation, bandwidth = newey_west_inflation(bias - matrix @ solution)
    elif drift.autocorrelation == "none":
        inflation, bandwidth = 1.0, 0
    else:
        raise InputError(
            f"autocorrelation must be 'newey-west' or 'none', got {drift.autocorrelation!r}")
    if drift.select not in SELECTIONS:
        raise InputError(f"select must be one of {', '.join(SELECTIONS)}, got {drift.select!r}")
    if drift.select == "cv" and len(windows.sources) < 2:
        raise InputError("select='cv' needs two training runs or more (leave-one-run-out)")
    slope_sign = 1.0 if thermometer.slope_hz_per_c(training.reference_c) >= 0 else -1.0
    rate = windows.variables.get("df", np.zeros(windows.bias_dph.size))
    parents = hierarchy(training.candidates) if drift.hierarchical else None
    rules = StepwiseRules(penter=drift.penter, premove=drift.premove, initial=initial,
                          variance_inflation=inflation, parents=parents)
    result = stepwise(x_scaled, bias, names=names, rules=rules,
                      refine=EXTENDED_PRECISION)  # quietly unrefined without long double
    chosen, pruning = None, None
    data = Windowed(x_scaled, bias, windows.run, names, tuple(windows.sources), rate,
                    windows.time_s, windows.variables.get("f"), windows.variables, made.scales)
    if drift.select == "cv":  # from the stepwise terms, one-term changes that cross-validate
        chosen = select_terms(data, slope_sign, parents=parents, initial=result.selected)
    elif drift.select == "guarded" and (result.selected or np.unique(windows.run).size == 1):
        chosen, pruning = guard_selection(
            data, result.selected, parents=hierarchy(training.candidates),
            keep=[parse_terms([t])[0].name for t in initial or ()],
            line_test=(drift.penter, drift.premove))
    if chosen is not None:
        history = result.history
        rules = StepwiseRules(penter=drift.penter, premove=drift.premove, initial=chosen,
                              variance_inflation=inflation, max_steps=0)
        result = stepwise(x_scaled, bias, names=names, rules=rules, refine=EXTENDED_PRECISION)
        if drift.select == "guarded":  # the F-test steps stay on record; pruning apart
            result = dataclasses.replace(result, history=history)
    return Selection(result, pruning, inflation, bandwidth, slope_sign, rate)


def refit_rate_free(training: Training, made: Design, chosen: Selection,
                    drift: DriftSettings) -> Design:
    """Stage 5: with no rate term chosen nothing waits for the df/dt filter to settle, so
    the run's first ``warmup_s`` (at rest, and often its most extreme temperature) is
    trained on too and the compensation flags no settling (docs/real-loggers/corpus.md);
    df/dt's range, kept for the warnings, then spans the filter's start too (the model's
    own file stays inside it). Its windows came from stage 3's reading
    (:attr:`Design.rate_free`); ``made`` unchanged when a rate term is chosen, the warm-up
    was given, or it is zero."""
    chosen_terms = [t for t in training.candidates if t.name in chosen.result.selected]
    if made.rate_free is None or any(
            entry.rate_of for entry, _ in registry_entries(variables_for(chosen_terms))):
        return made
    training.features = FeatureSettings(**{**training.features.to_dict(), "warmup_s": 0.0})
    windows = made.rate_free
    history = chosen.result.history
    refit = Design(windows, made.scales, made.factors,
                   *design_matrix(windows, drift.offsets, made.factors))
    chosen.result = dataclasses.replace(
        stepwise(refit.x_scaled, refit.bias, names=training.names,
                 rules=StepwiseRules(penter=drift.penter, premove=drift.premove,
                                     initial=chosen.result.selected,
                                     variance_inflation=chosen.inflation, max_steps=0),
                 refine=EXTENDED_PRECISION), history=history)
    return refit
