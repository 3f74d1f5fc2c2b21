"""An in-field update of a fitted model from the still periods of new recordings (issue 29).

:func:`update_model` (what :meth:`hrgtc.model.Model.update` calls) reads the recordings,
refuses another unit's file and an output compensated by another model, finds the still
periods (the motion detector, or given intervals), cuts them into blocks
(:mod:`hrgtc.update.observations`) and runs the Kalman filter (:mod:`hrgtc.update.kalman`)
on the drift model's offset B0 (only with a known input rate) and slope (the term ``f``,
only over ``min_span_c``), the calibration's coefficient covariance
(:meth:`hrgtc.drift.DriftModel.coefficient_prior`) plus an ageing allowance as the prior;
a triad's three offsets without a known input rate come from the magnitude of the Earth
rate (:mod:`hrgtc.update.triad`) when its still periods hold enough orientations.

It never applies an update that is refused (:class:`~hrgtc.core.errors.UpdateRefusedError`,
naming the file and the reason): thermally unsettled still data (a ramp posing as
ageing), a step within a run (a jump), a step further from the prior than
``max_step_sigma``, no gain on the recording's own held-out still blocks. A recording
without still periods, or with nothing observable, changes nothing and says so.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError, UpdateRefusedError
from hrgtc.recording import Recording
from hrgtc.settings import to_dict
from hrgtc.settings.reading import DROPOUT_S
from hrgtc.settings.update import EARTH_RATE_BOUND_DPH, UpdateSettings
from hrgtc.update.kalman import (
    Walk,
    bootstrap_rms,
    heldout_rms,
    jump_statistic,
    mahalanobis,
    run_filter,
    split_heldout,
    walk_rate,
)
from hrgtc.update.lineage import AxisChange, Lineage, LineageData, pack
from hrgtc.update.observations import (
    StillBlock,
    block_noise_dph,
    describe_blocks,
    index_periods,
    still_blocks,
    stretches,
)
from hrgtc.update.result import AxisUpdate, FilterProblem, UpdateResult
from hrgtc.update.triad import TRIAD_CHANGE, TriadUpdate, by_orientation, triad_axes, triad_offsets

__all__ = ["update_model"]


def update_model(model: Any, recordings: Any, settings: UpdateSettings | None = None, *,
                 still_s: Sequence[tuple[float, float]] | None = None,
                 parent_bytes: bytes, parent_path: str = "<model>",
                 read_options: Any = None) -> UpdateResult:
    """Update ``model`` (a :class:`hrgtc.model.Model`, each axis in turn) from ``recordings``.

    Parameters
    ----------
    model
        The parent model (its drift model's coefficients and covariance are the prior).
    recordings
        A recording file, a :class:`~hrgtc.recording.Recording`, or a sequence of them
        (each its own run: its own turn-on shift).
    settings
        :class:`~hrgtc.settings.update.UpdateSettings` (its defaults when None).
    still_s
        Still intervals ``(start, end)`` in each recording's time, instead of the motion
        detector's still periods. [s]
    parent_bytes, parent_path
        The parent file's bytes and name, kept in the lineage for a rollback.
    read_options
        How to read the files (:class:`~hrgtc.recording.ReadOptions`).

    Raises
    ------
    UpdateRefusedError
        Another unit's file, a ramp, a jump, a step too far, no held-out gain.
    """
    settings = settings or UpdateSettings()
    if settings.input_rate_dph is not None and "" not in model.axes:
        raise InputError(f"the model of {model.unit!r} has axes {', '.join(model.axes)}: one "
                         "known input rate cannot hold for every axis; update without "
                         "input_rate_dph (each axis's slope, and a triad's offsets from the "
                         "Earth rate's magnitude, triad_rate_norm_dph)")
    runs = [_read(item, read_options, model) for item in _items(recordings)]
    labels = [label for label, _, _ in runs]
    used = {d.sha256: d.path for d in (model.lineage.data if model.lineage else ())}
    for label, digest, _ in runs:
        if digest in used:
            raise UpdateRefusedError(
                f"{label}: already used by the update that made this model (as {used[digest]}, "
                "same SHA-256): a recording counts once")
    dropout_s = getattr(read_options, "dropout_s", DROPOUT_S)
    found = [_periods(recording, model.axes, settings, still_s, label, dropout_s)
             for label, _, recording in runs]
    data = tuple(LineageData(label, digest, intervals, source) for (label, digest, _),
                 (_, intervals, source) in zip(runs, found, strict=True))
    if not any(d.intervals_s for d in data):
        return UpdateResult(None, False, f"{', '.join(labels)}: no still period of a block "
                            f"(block_s {settings.block_s:g} s) or longer: the unit moved "
                            "throughout, or was still only for shorter times; nothing changed")
    settled = {name: _settled([b for index, ((_, _, recording), (periods, _, _)) in enumerate(
                   zip(runs, found, strict=True)) for b in _axis_blocks(
                       index, _view(recording, name), part, periods, settings)],
                   settings, labels) for name, part in model.axes.items()}
    axes, notes, parts, grouped, groups = {}, [], dict(model.axes), settled, labels
    is_triad = triad_axes(model, settings) is not None
    if is_triad:  # a nuisance constant per orientation, not per run
        grouped, groups = by_orientation(settled, labels)
    for name, part in model.axes.items():
        terms, said = _observable(part, grouped[name], settings, is_triad) \
            if grouped[name] else ((), [f"every still period is shorter than a block "
                                         f"({settings.block_s:g} s)"])
        notes += [f"{name}: {n}" if name else n for n in said]
        if terms:
            axes[name] = _filter_axis(model, name, grouped[name], terms, settings, groups)
            parts[name] = replace(part, drift=_updated_drift(part.drift, terms,
                                                             axes[name].after))
    triad, said = _triad(model, _slope_removed(settled, axes), settings, labels)
    notes = said + notes
    if triad is not None:
        for k, name in enumerate(triad.axes):
            parts[name] = replace(parts[name], drift=_updated_drift(
                parts[name].drift, ("const",), (triad.after[k],)))
    if not axes and triad is None:
        return UpdateResult(None, False, f"{', '.join(labels)}: nothing observable ("
                            f"{'; '.join(notes)}): nothing changed", notes=tuple(notes))
    lineage = _lineage(model, parent_bytes, parent_path, data, axes, triad, settings)
    updated = replace(model, axes=parts, lineage=lineage)
    return UpdateResult(updated, True, "", axes, lineage, tuple(notes), triad)


def _triad(model: Any, settled: dict[str, list[StillBlock]], settings: UpdateSettings,
           labels: list[str]) -> tuple[TriadUpdate | None, list[str]]:
    """The triad's offsets from |Ω| (:mod:`hrgtc.update.triad`) when the model is a triad
    and no input rate is given, and the note of why not."""
    if triad_axes(model, settings) is None or not all(settled.values()):
        return None, []
    triad, why = triad_offsets(model, settled, settings, labels)
    return triad, [why] if why else []


def _slope_removed(blocks: dict[str, list[StillBlock]], axes: dict[str, AxisUpdate]
                   ) -> dict[str, list[StillBlock]]:
    """The blocks' residuals with each axis's slope update taken out (the triad's offsets
    are then those of the updated slopes)."""
    out = {}
    for name, items in blocks.items():
        update = axes.get(name)
        if update is None or "f" not in update.terms:
            out[name] = items
            continue
        k = update.terms.index("f")
        step = update.after[k] - update.before[k]
        out[name] = [replace(b, residual_dph=b.residual_dph - step * b.f) for b in items]
    return out


def _lineage(model: Any, parent_bytes: bytes, parent_path: str, data: tuple[LineageData, ...],
             axes: dict[str, AxisUpdate], triad: TriadUpdate | None,
             settings: UpdateSettings) -> Lineage:
    """The lineage of the updated model: parent, data, every change and its figures."""
    changes = [AxisChange(name, a.terms, a.before, a.after, _matrix(a.covariance_before),
                          _matrix(a.covariance_after)) for name, a in axes.items()]
    steps = [(a.mahalanobis, a.heldout_before_dph, a.heldout_after_dph) for a in axes.values()]
    if triad is not None:
        changes.append(AxisChange(TRIAD_CHANGE, tuple(f"const.{a}" for a in triad.axes),
                                  triad.before, triad.after, _matrix(triad.covariance_before),
                                  _matrix(triad.covariance_after)))
        steps.append((triad.mahalanobis, triad.heldout_before_dph, triad.heldout_after_dph))
    return Lineage(
        parent_sha256=hashlib.sha256(parent_bytes).hexdigest(),
        parent_parameters_sha256=model.sha256, parent_path=parent_path,
        parent_unit=model.unit, parent_content=pack(parent_bytes), data=data,
        changes=tuple(changes), settings=to_dict(settings),
        mahalanobis=max(s[0] for s in steps), heldout_rms_before_dph=max(s[1] for s in steps),
        heldout_rms_after_dph=max(s[2] for s in steps),
        hrgtc_version=_version(), created_utc=datetime.now(UTC).isoformat(timespec="seconds"))


def _view(recording: Recording, axis: str) -> Recording:
    """The recording of one axis of a model (``""``: the recording itself)."""
    from hrgtc.recording import axis_view

    return axis_view(recording, axis) if axis else recording


def _settled(blocks: list[StillBlock], settings: UpdateSettings,
             labels: list[str]) -> list[StillBlock]:
    """The blocks at a settled temperature; refuses a recording whose still data are
    (nearly) all on a ramp."""
    settled = [b for b in blocks
               if abs(b.temperature_rate_c_per_h) <= settings.max_temperature_rate_c_per_h]
    if len(settled) < min(len(blocks), 2 * settings.holdout_every):
        fastest = describe_blocks(blocks)["max_rate_c_per_h"]
        raise UpdateRefusedError(
            f"{', '.join(labels)}: {len(blocks) - len(settled)} of {len(blocks)} still blocks "
            f"are on a temperature ramp (up to {fastest:.3g} °C/h, limit "
            f"{settings.max_temperature_rate_c_per_h:g} °C/h) and too few are settled: their "
            "residual is the model's thermal transient, not ageing (a ramp posing as "
            "ageing); update from still periods at a settled temperature")
    return settled


def _items(recordings: Any) -> list[Any]:
    if isinstance(recordings, str | Path | Recording):
        return [recordings]
    items = list(recordings)
    if not items:
        raise InputError("no recording given: pass a field recording with still periods")
    return items


def _read(item: Any, read_options: Any, model: Any) -> tuple[str, str, Recording]:
    """(name, SHA-256, recording) of a file or an in-memory recording, its unit checked."""
    from hrgtc.core.files import file_sha256
    from hrgtc.recording import read
    from hrgtc.recording.marks import compensation_mark

    if isinstance(item, Recording):
        label, recording = "<recording>", item
        digest = hashlib.sha256(b"".join(
            name.encode("utf-8") + np.ascontiguousarray(item[name]).tobytes()
            for name in item.names)).hexdigest()
    else:
        from hrgtc.thermometry.reference import options_with_map

        label = str(item)  # a raw count read through the model's map to °C, as compensate
        recording = read(item, options_with_map(read_options, model.temperature_map))
        digest = file_sha256(item)
    unit = recording.metadata.unit
    if unit not in ("", "unknown", None) and model.unit not in ("", "unknown") \
            and unit != model.unit:
        raise UpdateRefusedError(
            f"{label}: recorded by unit {unit!r}, but the model is of {model.unit!r}: "
            "another unit's file is refused (an update applies to the unit it was "
            "calibrated for)")
    found = compensation_mark(recording.metadata.extra, recording.names)
    if found is not None and found.get("model_sha256") not in (None, model.sha256):
        raise UpdateRefusedError(
            f"{label}: compensated with another model (parameters_sha256 "
            f"{found.get('model_sha256')}, unit {found.get('model_unit')!r}), not the parent "
            f"{model.sha256}: parent model hash mismatch; update from the raw recording")
    return label, digest, recording


def _periods(recording: Recording, axes: Any, settings: UpdateSettings,
             still_s: Sequence[tuple[float, float]] | None, label: str, dropout_s: float
             ) -> tuple[list[tuple[int, int]], tuple[tuple[float, float], ...], str]:
    """The still periods of one recording (index ranges, shared by every axis: motion on
    any axis is motion), their times [s] and where they came from."""
    from hrgtc.recording.motion import ACCEL_COLUMNS, detect_motion

    time_s = np.asarray(recording.time_s, dtype=np.float64)
    if still_s:
        periods, source = index_periods(time_s, still_s, label), "given"
    else:
        views = {name: _view(recording, name) for name in axes}
        rates = {f"rate_dph{'_' + name if name else ''}": view.rate_dph - (
            view["input_rate_dph"] if "input_rate_dph" in view.names
            else view.metadata.input_rate_dph) for name, view in views.items()}
        accel = {c: recording[c] for c in ACCEL_COLUMNS if c in recording.names}
        mask = detect_motion(time_s, rates, accel=accel or None)
        # a dropout (a late record) does not end a still period
        periods, source = mask.still_periods(settings.block_s, time_s, dropout_s), "motion"
    return periods, tuple((float(time_s[a]), float(time_s[b - 1])) for a, b in periods), source


def _axis_blocks(index: int, recording: Recording, part: Any, periods: list[tuple[int, int]],
                 settings: UpdateSettings) -> list[StillBlock]:
    """The still blocks of one axis of one recording (its view)."""
    if not periods:
        return []
    drift, thermometer = part.drift, part.thermometer
    bias = drift.predict_recording(recording, thermometer)
    rate = recording.rate_dph - (settings.input_rate_dph or 0.0)
    f = recording.freq_hz - drift.settings.reference_freq_hz
    temperature = thermometer.temperature(recording.freq_hz, warn=False)
    return still_blocks(index, np.asarray(recording.time_s, dtype=np.float64), rate, bias, f,
                        temperature, periods, settings)


def _observable(part: Any, blocks: list[StillBlock], settings: UpdateSettings,
                triad: bool = False) -> tuple[tuple[str, ...], list[str]]:
    """The terms the blocks can update, and what the reader should know of the others."""
    terms, notes = [], []
    if settings.input_rate_dph is not None:
        terms.append("const")
    elif not triad:
        notes.append("offset B0 not updated: the input rate is unknown (a still mean is "
                     "bias + Earth-rate projection + turn-on shift); give input_rate_dph")
    span = describe_blocks(blocks)["span_c"]
    if triad:  # a nuisance per orientation: only the temperatures within one tell the slope
        span = max(describe_blocks([b for b in blocks if b.run == run])["span_c"]
                   for run in {b.run for b in blocks})
    if "f" not in part.drift.selected:
        notes.append("slope not updated: the model has no term f")
    elif span < settings.min_span_c:
        notes.append(f"slope not updated: the still blocks span {span:.3g} °C"
                     f"{' within one orientation' if triad else ''}, less than "
                     f"min_span_c {settings.min_span_c:g} °C")
    else:
        terms.append("f")
    return tuple(terms), notes


def _prior(model: Any, name: str, terms: tuple[str, ...],
           settings: UpdateSettings) -> tuple[np.ndarray, np.ndarray]:
    """The updated terms' values and covariance before the update: the calibration's (or the
    last update's posterior) plus the ageing allowance."""
    part = model.axes[name]
    drift = part.drift
    names, _, covariance = drift.coefficient_prior()
    index = [names.index(t) for t in terms]
    prior = covariance[np.ix_(index, index)]
    kept = [c for c in (model.lineage.changes if model.lineage else ())
            if c.axis == name and c.terms == terms]
    if kept:
        prior = np.array(kept[0].covariance_after, dtype=np.float64)
    values = np.array([drift.intercept_dph if t == "const" else drift.coefficients[t]
                       for t in terms])
    slope_hz_per_c = abs(float(np.asarray(part.thermometer.slope_hz_per_c(
        drift.settings.reference_c))))
    ageing = {"const": settings.ageing_offset_dph ** 2,
              "f": (settings.ageing_slope_dph_per_c / slope_hz_per_c) ** 2}
    return values, prior + np.diag([ageing[t] for t in terms])


def _filter_axis(model: Any, name: str, blocks: list[StillBlock], terms: tuple[str, ...],
                 settings: UpdateSettings, labels: list[str]) -> AxisUpdate:
    """The filter over the blocks of axis ``name``, its guards, and the axis's figures."""
    on = f" (axis {name})" if name else ""
    where = ", ".join(dict.fromkeys(labels)) + on  # a recording's orientations share its name
    values, prior = _prior(model, name, terms, settings)
    problem = _problem(model.axes[name], blocks, terms, prior, settings)
    n_model, runs = problem.n_model, np.array([b.run for b in blocks])
    fit, held = split_heldout(len(blocks), settings.holdout_every)
    if held.size < 2 or fit.size < 2:
        raise UpdateRefusedError(
            f"{where}: {len(blocks)} still block(s) of {settings.block_s:g} s are "
            "too few to judge an update on held-out blocks (at least "
            f"{2 * settings.holdout_every}); record longer still periods")
    whole = _solve(problem, slice(None))
    sigma = math.sqrt(float(np.median(problem.r)))
    jump, at = jump_statistic(problem.z - problem.rows @ whole.mean,
                              stretches(blocks, settings.block_s), sigma)
    if jump > settings.jump_sigma:
        block = blocks[at]
        raise UpdateRefusedError(
            f"{labels[block.run]}{on}: the still residual steps by {jump:.3g} standard errors "
            f"within the run near t = {block.start_s:g} s (limit {settings.jump_sigma:g}): a "
            "jump is not ageing; update from a recording without it")
    step = mahalanobis(whole.mean[:n_model], prior)
    if step > settings.max_step_sigma:
        raise UpdateRefusedError(
            f"{where}: the update would move {', '.join(terms)} by {step:.3g} σ "
            f"of the prior (limit max_step_sigma {settings.max_step_sigma:g}): further than "
            "ageing goes; check the unit and the input rate, or recalibrate")
    trained = _solve(problem, fit)
    centred = "const" not in terms
    before = problem.z[held]
    after = before - problem.rows[held, :n_model] @ trained.mean[:n_model]
    rms_before = heldout_rms(before, runs[held], centred)
    rms_after = heldout_rms(after, runs[held], centred)
    if not rms_after < rms_before:
        raise UpdateRefusedError(
            f"{where}: no gain on the held-out still blocks (rms {rms_before:.4g} "
            f"°/h before, {rms_after:.4g} °/h after): the update is not applied")
    return AxisUpdate(
        terms, tuple(float(v) for v in values), tuple(float(v) for v in values
                                                      + whole.mean[:n_model]),
        prior, whole.covariance[:n_model, :n_model], len(blocks), int(fit.size),
        int(held.size), rms_before, rms_after, bootstrap_rms(before, runs[held], centred),
        bootstrap_rms(after, runs[held], centred), step, jump,
        describe_blocks(blocks)["span_c"], sigma, problem, whole.traces)


def _problem(part: Any, blocks: list[StillBlock], terms: tuple[str, ...], prior: np.ndarray,
             settings: UpdateSettings) -> FilterProblem:
    """The filter's prior, rows, residuals, variances and times of ``blocks``."""
    n_model, n_runs = len(terms), max(b.run for b in blocks) + 1
    drift = part.drift
    fallback = drift.residual_std_dph * math.sqrt(drift.window_s / settings.block_s)
    noise = block_noise_dph(blocks, fallback if math.isfinite(fallback) else 0.0)
    nuisance = settings.turn_on_dph ** 2
    if "const" not in terms:  # the constant holds the Earth rate and the offset's change
        nuisance += EARTH_RATE_BOUND_DPH ** 2 + settings.ageing_offset_dph ** 2
    n_state = n_model + 2 * n_runs  # the corrections, each run's constant and its walk
    covariance = np.zeros((n_state, n_state))
    covariance[:n_model, :n_model] = prior
    covariance[n_model:n_model + n_runs, n_model:n_model + n_runs] = np.eye(n_runs) * nuisance
    rows = np.zeros((len(blocks), n_state))
    for k, block in enumerate(blocks):
        rows[k, :n_model] = [1.0 if t == "const" else block.f for t in terms]
        rows[k, n_model + block.run] = rows[k, n_model + n_runs + block.run] = 1.0
    ends = np.zeros(n_runs)
    for block in blocks:  # each run's times after the runs before it
        ends[block.run] = max(ends[block.run], block.time_h)
    starts = np.concatenate([[0.0], np.cumsum(ends)[:-1]])
    times_h = np.array([starts[b.run] + b.time_h for b in blocks])
    start_h = np.zeros(n_state)  # each walk from 0 at its run's first still block
    for block in reversed(blocks):
        start_h[n_model + n_runs + block.run] = starts[block.run] + block.start_s / 3600.0
    walk = Walk(np.array([n_model + n_runs + b.run for b in blocks]), start_h, 0.0)
    problem = FilterProblem(
        np.zeros(n_state), covariance, rows, np.array([b.residual_dph for b in blocks]),
        np.array([max(noise, b.white_sigma_dph) ** 2 for b in blocks]), times_h, n_model,
        settings.ageing_tau_h, walk)
    rate = walk_rate(lambda q: _solve(replace(problem, walk=walk._replace(q_per_h=q)),
                                      slice(None)))
    return replace(problem, walk=walk._replace(q_per_h=rate))


def _solve(problem: FilterProblem, which: Any) -> Any:
    walk = None if problem.walk is None else problem.walk.subset(which)
    return run_filter(problem.mean, problem.covariance, problem.rows[which], problem.z[which],
                      problem.r[which], problem.times_h[which], problem.n_model, problem.tau_h,
                      walk)


def _updated_drift(drift: Any, terms: tuple[str, ...], after: tuple[float, ...]) -> Any:
    """``drift`` with the updated intercept and slope (the scaled coefficient the model
    predicts with, and the user-unit one derived from it)."""
    values = dict(zip(terms, after, strict=True))
    intercept = values.get("const", drift.intercept_dph)
    scaled = list(drift.scaled_coefficients)
    coefficients = dict(drift.coefficients)
    if "f" in values:
        term = drift.selected.index("f")
        factor = drift.terms[term].scale_factor(drift.settings.scales)
        scaled[term] = values["f"] * factor
        coefficients["f"] = scaled[term] / factor
    return replace(drift, intercept_dph=float(intercept), scaled_coefficients=tuple(scaled),
                   coefficients=coefficients)


def _matrix(covariance: np.ndarray) -> tuple[tuple[float, ...], ...]:
    return tuple(tuple(float(v) for v in row) for row in np.asarray(covariance))


def _version() -> str:
    from hrgtc.core.meta import __version__

    return __version__

