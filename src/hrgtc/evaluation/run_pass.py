"""How much better the gyro got: one pass over a run, raw vs compensated.

Section 4.2 of [1] reports the 1-sigma bias stability of a cool-down run before
(3.0143 °/h) and after (0.5848 °/h) compensation. :func:`run_pass` compensates
a run chunk by chunk once and measures it: the same figure at 1, 10 and 100 s,
the Allan deviation and noise terms before and after, the share of samples
outside the calibrated ranges, and, where the run has a housing thermistor and
the model keeps the classical baseline, the same figures for compensation by
housing temperature (so the frequency method can be compared with the
thermistor method). Simulated runs carry the true bias; the model's residual
against it is reported too. On request the pass also keeps block means for
plotting (the report's Fig. 6) and hands each compensated chunk to a writer. The
result, :class:`~hrgtc.evaluation.evaluation_result.Evaluation` (re-exported here), is
in :mod:`hrgtc.evaluation.evaluation_result`. :func:`hrgtc.evaluation.evaluate` reads a run
once for every axis of a model and runs a :class:`RunPass` per axis
(:mod:`hrgtc.evaluation.run_evaluation`).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.compensate import Compensator
from hrgtc.core.accounting import Accounting
from hrgtc.core.errors import HrgtcError, InputError
from hrgtc.core.progress import Progress
from hrgtc.core.timeline import RESTARTS_KEY
from hrgtc.drift.features import FeatureStream
from hrgtc.evaluation.allan import AllanResult
from hrgtc.evaluation.burst_allan import BurstAllanResult
from hrgtc.evaluation.deviation_curves import (
    DEVIATIONS,
    _deviation,
    segment_notes,
    stability_intervals,
)
from hrgtc.evaluation.evaluation_result import Evaluation
from hrgtc.evaluation.heating_cooling import DirectionSplit
from hrgtc.evaluation.noise import NoiseTerms, noise_terms
from hrgtc.evaluation.plot_blocks import BlockMeans
from hrgtc.evaluation.series_stats import SeriesStatistics
from hrgtc.evaluation.settling_cut import SettlingCut
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Recording
from hrgtc.settings.compensation import EvaluationSettings

#: Series measured by a pass: output minus input rate, compensated by the
#: frequency model, and by the housing-thermistor baseline.
SERIES = ("raw", "compensated", "housing")
#: Prefix of the model's variables among the plotting blocks (``var_f``, ``var_df``, ...).
VARIABLE_PREFIX = "var_"


@dataclass(frozen=True)
class RunPlan:
    """What a pass over a run knows before it reads the run.

    Attributes
    ----------
    name
        The run's name in the results.
    source
        Where the run came from (a path), kept in the result.
    total_rows
        Rows of the run, for the progress callback (0 when not known).
    gaps
        ``"split"``: the df/dt filter restarts after each gap (see
        :class:`~hrgtc.compensate.Compensator`) and settles again: the figures leave out
        the first ``warmup_s`` after every gap (an error when nothing is left);
        otherwise the filter carries across and only the run's first ``warmup_s`` is
        left out. The statistics run over the joined segments.
    block_rows
        Keep block means of this many rows for plotting (None: keep none).
    keep
        True for each sample of the run at rest (:func:`hrgtc.drift.rest.run_rest`): the
        others are compensated and written but left out of every figure, and counted
        (``n_not_at_rest``). None: every sample counts.
    """

    name: str
    source: str = ""
    total_rows: int = 0
    gaps: str = "ignore"
    block_rows: int | None = None
    keep: np.ndarray | None = field(default=None, repr=False)


def run_pass(
    model: AxisModel,
    chunks: Iterable[Recording],
    plan: RunPlan | str,
    settings: EvaluationSettings | None = None,
    *,
    on_output: Callable[[Recording], None] | None = None,
    progress: Progress | None = None,
) -> Evaluation:
    """Compensate one run given as consecutive chunks, once, and measure it.

    Memory stays bounded whatever the run's length: the statistics are streamed
    (:class:`~hrgtc.evaluation.series_stats.SeriesStatistics`), no series is held.

    Parameters
    ----------
    model
        The axis's parts (:class:`~hrgtc.model.AxisModel`; ``model.axis`` of a
        single-axis :class:`~hrgtc.model.Model`).
    chunks
        The run, as consecutive chunks (e.g. :func:`hrgtc.recording.iter_chunks`).
    plan
        What is known of the run before reading it (:class:`RunPlan`; a name alone: a
        plan with that name).
    settings
        What is measured (:class:`~hrgtc.settings.compensation.EvaluationSettings`): the
        bias stability's averaging times, the Allan deviations and noise terms or not,
        the deviation curve (``"oadev"``, ``"adev"``, ``"mdev"``, ``"hdev"``, ``"tdev"``;
        noise terms are read off the Allan deviations only; every curve is pooled within
        the segments, no difference across a gap, with its chi-squared interval from the
        pooled edf, :mod:`~hrgtc.evaluation.allan_segments`; τ beyond a burst comes from
        burst means with the dead time's bias stated, ``burst_allan``, or a note says why
        it is not estimable) and the two-sided level of the intervals.
    on_output
        Called with every compensated chunk (the input columns plus
        ``rate_comp_dph``, ``bias_model_dph``, ``resonator_c_est``, ``in_range``), e.g.
        a :class:`~hrgtc.recording.RecordingWriter`'s ``write``.
    progress
        ``progress(samples done, plan.total_rows)``.

    Raises
    ------
    InputError
        The run holds no samples, or is shorter than two 10 s blocks.
    """
    return RunPass(model, plan, settings, on_output=on_output, progress=progress).fit(chunks)


class RunPass:
    """The state of one pass over a run: :meth:`partial_fit` each consecutive chunk, then
    :meth:`finish`. :func:`run_pass` is "a new pass, then every chunk"; a pass per axis of a
    multi-axis recording lets one reading of the file feed every axis
    (:func:`hrgtc.evaluation.evaluate`). The parameters are those of
    :func:`run_pass`."""

    def __init__(self, model: AxisModel, plan: RunPlan | str,
                 settings: EvaluationSettings | None = None, *,
                 on_output: Callable[[Recording], None] | None = None,
                 progress: Progress | None = None) -> None:
        plan = RunPlan(plan) if isinstance(plan, str) else plan
        settings = settings or EvaluationSettings()
        deviation = settings.deviation
        if deviation not in DEVIATIONS:
            raise InputError(
                f"deviation={deviation!r} is not known; use one of {tuple(DEVIATIONS)}")
        self.model, self.name, self.source = model, plan.name, plan.source
        self.taus_s, self.allan, self.gaps = settings.taus_s, settings.allan, plan.gaps
        self.deviation, self.confidence, self.keep = deviation, settings.confidence, plan.keep
        self.on_output, self.progress, self.total_rows = on_output, progress, plan.total_rows
        gaps, block_rows = plan.gaps, plan.block_rows
        self.frequency = Compensator(Model.single(model), gaps=gaps)
        self.features = None
        if block_rows:
            self.features = FeatureStream(model.drift.settings, model.drift.variables,
                                          model.thermometer)
        self.housing: Compensator | None = None
        self.means = BlockMeans(block_rows) if block_rows else None
        self.full: dict[str, SeriesStatistics] = {}
        # only for deviations the streaming cannot give
        self.whole: dict[str, list[np.ndarray]] = {}
        self.squared_error = 0.0
        self.left_out = 0
        self.truth = False
        self.metadata: Any = None

    def fit(self, chunks: Iterable[Recording]) -> Evaluation:
        """Every chunk of the run, then the result."""
        for chunk in chunks:
            self.partial_fit(chunk)
        return self.finish()

    def partial_fit(self, chunk: Recording) -> RunPass:
        """Compensate and measure the next chunk of the run."""
        model, gaps, allan, deviation = self.model, self.gaps, self.allan, self.deviation
        if self.metadata is None:
            self.metadata = metadata = chunk.metadata
            self.truth = "bias_dph" in chunk
            if model.housing is not None and "housing_c" in chunk:
                self.housing = Compensator(Model.single(model), "housing", gaps=gaps)
            keys = SERIES if self.housing is not None else SERIES[:2]
            self.full = {key: SeriesStatistics(metadata.sample_rate_hz, self.taus_s, allan,
                                               expected_samples=self.total_rows)
                         for key in keys}
            self.cut = SettlingCut(self.full, model.drift.settings.warmup_s,
                                   1.0 / metadata.sample_rate_hz,
                                   2 * round(10.0 * metadata.sample_rate_hz),
                                   restart_at_gaps=gaps == "split",
                                   keep_mask=allan and deviation != "oadev", name=self.name)
            self.split = DirectionSplit(model, metadata.sample_rate_hz)
        metadata, frequency, housing = self.metadata, self.frequency, self.housing
        done = frequency.samples  # rows before this chunk; the at-rest mask of its own
        kept = None if self.keep is None else self.keep[done:done + len(chunk)]
        out = frequency.transform(chunk, kept)  # (moving samples are no unknown orientation)
        if self.on_output is not None:
            self.on_output(out)
        raw = chunk.rate_dph - metadata.input_rate_dph
        comp = out["rate_comp_dph"] - metadata.input_rate_dph
        pushed = {"raw": raw, "compensated": comp}
        columns = {"time_s": chunk.time_s, "raw_dph": raw, "model_dph": out["bias_model_dph"],
                   "comp_dph": comp, "temperature_c": out["resonator_c_est"],
                   "in_range": out["in_range"]}
        if housing is not None:
            comp_h = housing.transform(chunk)["rate_comp_dph"] - metadata.input_rate_dph
            pushed["housing"] = comp_h
            columns["comp_housing_dph"] = comp_h
        if kept is not None:
            self.left_out += int(np.count_nonzero(~kept))
            pushed = {key: values[kept] for key, values in pushed.items()}
        self.cut.partial_fit(pushed, chunk.time_s if kept is None else chunk.time_s[kept],
                      chunk.metadata.extra.get(RESTARTS_KEY))
        if allan and deviation != "oadev":
            for key, values in pushed.items():
                self.whole.setdefault(key, []).append(values)
        truth = self.truth
        self.split.partial_fit(chunk, raw, comp,
                        out["bias_model_dph"] - chunk["bias_dph"] if truth else None)
        if truth:
            columns["true_dph"] = chunk["bias_dph"]
            self.squared_error += float(np.sum((out["bias_model_dph"] - chunk["bias_dph"]) ** 2))
        if self.means is not None:
            columns.update({k: chunk[k] for k in ("resonator_c", "housing_c", "chamber_c")
                            if k in chunk})
            assert self.features is not None
            columns.update({VARIABLE_PREFIX + k: v
                            for k, v in self.features.transform(chunk).items()})
            self.means.partial_fit(columns)
        if self.progress is not None:
            self.progress(frequency.samples, self.total_rows)
        return self

    def finish(self) -> Evaluation:
        """The figures of the run so far (call once, after the last chunk)."""
        model, name, allan, deviation = self.model, self.name, self.allan, self.deviation
        confidence, frequency, means = self.confidence, self.frequency, self.means
        metadata, full, whole, truth = self.metadata, self.full, self.whole, self.truth
        if metadata is None:
            raise InputError(f"{name}: the run holds no samples")
        cut, split, left_out = self.cut, self.split, self.left_out
        fs = metadata.sample_rate_hz
        cut.finish()
        n = frequency.samples
        if n < 2 * round(10.0 * fs):
            raise InputError(f"{name}: {n / fs:.1f} s is too short for a 10 s bias stability "
                             "(it needs at least 20 s)")
        stability: dict[str, dict[float, float]] = {}
        intervals: dict[str, dict[float, tuple[float, float]]] = {}
        deviations: dict[str, AllanResult] = {}
        terms: dict[str, NoiseTerms] = {}
        notes: list[str] = []
        mean: dict[str, float] = {}
        rms: dict[str, float] = {}
        blocks: dict[str, dict[float, int]] = {}
        bursts: dict[str, BurstAllanResult] = {}
        for key, series in full.items():
            stability[key] = series.bias_stability()
            blocks[key] = series.blocks()
            mean[key], rms[key] = series.mean(), series.rms()
            notes.extend(segment_notes(key, series, stability[key], allan))
            intervals[key] = stability_intervals(stability[key], blocks[key], confidence)
            if not allan:
                continue
            if series.segments > 1:
                try:
                    bursts[key] = series.burst_allan(confidence)
                    notes.extend(f"{key}: {line}" if k == 0 else line
                                 for k, line in enumerate(bursts[key].lines()))
                except HrgtcError as exc:
                    notes.append(f"{key}: Allan deviation beyond a segment not estimable ({exc})")
            try:
                if deviation == "oadev":
                    deviations[key] = series.allan_deviation(confidence)
                else:  # the other deviations need the whole series (held in memory for them)
                    deviations[key] = _deviation(np.concatenate(whole[key])[cut.kept()], fs,
                                                 deviation, confidence, series.segment_starts())
                if deviations[key].kind == "allan":
                    terms[key] = noise_terms(deviations[key])
            except HrgtcError as exc:
                notes.append(f"{key}: no Allan noise terms ({exc})")
        unknown = frequency.axis.unknown_orientation
        if unknown:
            notes.append(f"{unknown} samples in an orientation the model was "
                         "not trained in: their offset is unknown (the training mean is used)")
        if allan and deviation not in ("adev", "oadev"):
            notes.append(f"noise terms are read off the Allan deviation; --deviation {deviation} "
                         "gives the curve only")
        kept = None if means is None else means.finish()
        if kept is not None and model.drift.terms:
            values_at = {k.removeprefix(VARIABLE_PREFIX): v for k, v in kept.items()
                         if k.startswith(VARIABLE_PREFIX)}
            kept["model_std_dph"] = model.drift.prediction_std(values_at)
        return Evaluation(
            name, n, float(fs), stability, deviations, terms, frequency.out_of_range_fraction,
            frequency.rate_out_of_range_fraction,
            math.sqrt(self.squared_error / n) if truth else None,
            source=self.source, unit=metadata.unit, input_rate_dph=metadata.input_rate_dph,
            block_s=None if means is None else means.rows / fs,
            blocks=kept, notes=tuple(notes), ranges=frequency.ranges(),
            bias_stability_interval_dph=intervals, confidence=float(confidence),
            deviation=deviation, directions=split.finish(), mean_dph=mean, rms_dph=rms,
            n_not_at_rest=left_out,
            accounting=_accounting(n, cut.cut, frequency, left_out),
            bias_stability_blocks=blocks, burst_allan=bursts,
        )


def _accounting(read: int, settling: int, frequency: Compensator,
                not_at_rest: int = 0) -> Accounting:
    """Samples read, left out of the figures (settling, motion) and flagged (out of range)."""
    accounting = Accounting(read=read)
    accounting.drop("warmup", settling)
    accounting.drop("motion", not_at_rest)
    accounting.flag("out_of_range", round(frequency.out_of_range_fraction * read))
    return accounting


def count_dropped(result: Evaluation, dropped: dict[str, int]) -> Evaluation:
    """``result`` with the rows the reading removed as spikes counted: read, then left out
    (the pass saw only the rows that reached it)."""
    if result.accounting is not None and dropped.get("spikes"):
        result.accounting.add_read(dropped["spikes"])
        result.accounting.drop("spikes", dropped["spikes"])
    return result
