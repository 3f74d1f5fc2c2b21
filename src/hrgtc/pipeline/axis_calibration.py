"""One axis of a calibration: Sections 3 and 4 of [1] run on files.

Soak recordings -> plateaus -> the axis's Table 1 -> thermometer (Eq. 18 form)
-> its Table 2; ramp recordings -> stepwise drift model (Eq. 22 form), gathered into
a one-axis :class:`~hrgtc.model.Model` with its evidence (:class:`AxisCalibration`).
:func:`hrgtc.pipeline.calibration.calibrate` runs :func:`fit_axis` on each axis's view of
the files, then fits the scale factors and evaluates the held-out runs.

Files are streamed chunk by chunk for the drift fit and the validation, so
memory stays bounded whatever their length; each soak file is read whole
(one soak at a time).

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import math
import os
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc import drift as drift_model
from hrgtc.core import forked, records
from hrgtc.core.errors import CalibrationError, ExtrapolationWarning, HrgtcWarning, InputError
from hrgtc.core.progress import StageProgress, for_stage
from hrgtc.core.summary import Summary
from hrgtc.drift.features import EQ21
from hrgtc.drift.fit_stages import TrainingReading, fit_warmup
from hrgtc.drift.rest import run_rest
from hrgtc.drift.training import (
    ChannelShape,
    TrainingStatistics,
    check_resonator_gyro,
    check_sensor_swap,
    check_setpoint_thermometer,
    implausible_for_any_gyro,
)
from hrgtc.evaluation import Evaluation
from hrgtc.evaluation.calibration_figures import calibration_summary, thermometer_tables
from hrgtc.model import AxisModel, Model, provenance
from hrgtc.pipeline.documents import CalibrationDriftRecord, CalibrationRecord
from hrgtc.pipeline.narrow_reading import PassPrints
from hrgtc.pipeline.soak_pass import SoakPass, SoakRests
from hrgtc.pipeline.terms import resolve_terms
from hrgtc.recording import ReadOptions
from hrgtc.recording.mapping import parse_columns, scales_temperature
from hrgtc.settings import to_dict
from hrgtc.settings.calibration import CalibrationSettings
from hrgtc.settings.drift import GRADIENT_TERMS, DriftSettings
from hrgtc.thermometry import fit as fit_thermometer
from hrgtc.thermometry import identity
from hrgtc.thermometry.plateaus import Plateau, plateau_table
from hrgtc.thermometry.prior import PriorFit, ThermometerPrior, fit_with_prior, load_prior

PathLike = str | os.PathLike[str]

#: Classical baseline: cubic in housing temperature.
HOUSING_TERMS = ("h", "h^2", "h^3")


@dataclass(frozen=True)
class SoakFit:
    """The thermometer of an axis and its evidence (:func:`fit_soaks`).

    Attributes
    ----------
    thermometer
        Frequency -> temperature (Eq. 18 form), or the identity of a gyro without a
        frequency output (its range that of the training runs).
    plateaus
        One per soak, in input order (none for a sensor thermometer).
    table
        The axis's Tables 1 and 2 (see :class:`AxisCalibration`).
    prior_fit
        The posterior when a population prior was given.
    order
        The thermometer polynomial's order (None for a sensor thermometer).
    sample_rates_hz
        Each soak file's sample rate (a soak joins the drift fit only at the drift
        runs' rate).
    """

    thermometer: Any
    plateaus: tuple[Plateau, ...] = ()
    table: tuple[dict[str, float], ...] = ()
    prior_fit: PriorFit | None = None
    order: int | None = None
    sample_rates_hz: tuple[float, ...] = ()


@dataclass(frozen=True)
class AxisCalibration:
    """One axis of a calibration: its model and its evidence (an axis of
    :class:`hrgtc.pipeline.calibration.Calibration`, from :func:`fit_axis`).

    Attributes
    ----------
    model
        The axis as a one-axis model (thermometer, drift model, housing baseline, scale
        factor; the calibration's unit, provenance and temperature map).
    plateaus
        One per soak, in input order.
    table
        The axis's Tables 1 and 2: chamber_c, freq_hz, temperature_from_freq_c,
        error_c (= temperature from frequency minus chamber temperature).
    validation
        One :class:`~hrgtc.evaluation.Evaluation` of this axis per held-out run.
    """

    model: Model
    plateaus: tuple[Plateau, ...]
    table: tuple[dict[str, float], ...]
    validation: tuple[Evaluation, ...] = field(default=())
    prior_fit: PriorFit | None = None
    #: The thermometer fit this calibration used (``fit_axis(soak_fit=...)`` reuses it).
    soak_fit: SoakFit | None = field(default=None, compare=False, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (:class:`CalibrationRecord`, the layout of ``hrgtc calibrate
        --json``; what is not finite as null)."""
        return records.dump(self, CalibrationRecord, **self.document_parts())

    def document_parts(self) -> dict[str, Any]:
        """The parts of :class:`CalibrationRecord` that are not attributes of the result
        (the thermometer, drift-model and housing sections, the held-out runs, the prior)."""
        thermometer, d, housing = self.model.thermometer, self.model.drift, self.model.housing
        return {
            "thermometer": {
                "coefficients_high_first": thermometer.coefficients_high_first,
                "standard_errors_high_first": list(reversed(thermometer.standard_errors)),
                "table": self.table},
            "drift": records.dump(
                d, CalibrationDriftRecord, selected_terms=d.selected,
                history=[s.to_dict() for s in d.history],
                cross_validation=None if d.cross_validation is None
                else d.cross_validation.to_dict(),
                accounting=None if d.accounting is None else d.accounting.to_dict()),
            "housing": None if housing is None else {"selected_terms": housing.selected,
                                                     "coefficients": housing.coefficients},
            "validation": [v.to_dict() for v in self.validation],
            "prior": None if self.prior_fit is None else self.prior_fit.to_dict(),
        }

    def summary(self, warnings: bool = True,
                temperature_map: Mapping[str, Any] | None = None) -> Summary:
        """The calibration's figures, each a value, a unit and an interval (±1σ of a
        coefficient, the confidence interval of a bias stability, the span of the data).

        Render it with ``.text()``, ``.rows()`` (a table) or ``.html()``; ``.to_dict()`` is
        plain JSON. ``warnings``: the held-out runs' range warnings among its notes (see
        :func:`hrgtc.evaluation.calibration_figures.calibration_summary`);
        ``temperature_map``: the instrument's map of a sensor's raw count, if any.
        """
        return calibration_summary(self.model, self.table, self.validation, self.prior_fit,
                                   warnings, temperature_map)

    def tables(self) -> Summary:
        """The unit's Table 1, Table 2, plateaus and Eq. 18 beside the paper's as table
        cells (:func:`hrgtc.evaluation.calibration_figures.thermometer_tables`), what
        ``hrgtc calibrate`` prints and the report shows; Table 2's figures are the places
        ``thermometer.table[k]`` of :meth:`to_dict`."""
        return thermometer_tables(self.model.thermometer, self.plateaus)


def fit_axis(
    soaks: Sequence[PathLike],
    drifts: Sequence[PathLike],
    *,
    settings: CalibrationSettings | None = None,
    aux: Mapping[str, str] | None = None,
    read_options: ReadOptions | None = None,
    progress: StageProgress | None = None,
    prior: ThermometerPrior | PathLike | None = None,
    soak_fit: SoakFit | None = None,
) -> AxisCalibration:
    """One axis: its thermometer from the soaks, its drift model from the ramps.

    The parameters are those of :func:`hrgtc.pipeline.calibration.calibrate`, which has
    refused compensated outputs among the files, reads this axis's view of them
    (``read_options.axis``) and evaluates the held-out runs, every axis at once. ``aux``:
    extra logged channels, name -> column (``--aux NAME=COLUMN``), each the variable
    ``a_NAME`` (the column minus its training mean) and a candidate term; ``soak_fit``:
    the thermometer already fitted on these soaks (and drift runs) with these settings
    (:attr:`AxisCalibration.soak_fit` of an earlier fit, or :func:`fit_soaks`), whose
    plateaus, Tables 1-2 and thermometer are reused, only the drift model being fitted
    (``--cross-axis`` refits it with more candidate terms on the same files). With two
    training runs or more (the soaks count) the drift fit reports each run's
    leave-one-run-out cross-validated bias stability, heating and cooling apart. The
    candidate terms default to :data:`GRADIENT_TERMS` when every training run logs
    ``housing_c``, else the nine of Eq. (21); soaks join the drift fit by default: a single
    cool-down covers one curve in the (temperature, rate) plane, along which the polynomial
    in f and the df/dt terms are confounded, and the soaks' warming and cooling transients
    add curves of both signs of df/dt. ``read_options.thermometer="sensor"``: a gyro
    without a frequency output, its temperature sensor (``temperature_c``, read in the
    place of ``freq_hz``) the thermometer (:func:`hrgtc.thermometry.identity`), the soaks
    optional training runs.
    """
    options = read_options or ReadOptions()
    settings = settings or CalibrationSettings()
    if not drifts:
        raise InputError("no drift recordings given; pass --drift FILE (a cool-down or warm-up)")
    thermometer = options.thermometer
    if thermometer == "sensor":
        return _calibrate_sensor(soaks, drifts, options, progress, settings, aux, soak_fit)
    if thermometer != "resonator":
        raise InputError(f"thermometer must be 'resonator' or 'sensor', got {thermometer!r}")
    # the drifts' heads first: a file's own reading problem (time in ms, a wrong unit) is
    # named before what is missing beside it
    heads = {str(path): options.head(path) for path in drifts}
    if not soaks:
        raise InputError("no soak recordings given; pass --soak FILE for each soak "
                         "(a gyro without a frequency output: --thermometer sensor)")
    for path in drifts:  # an HRG: a noise or bias only a MEMS gyro has is a unit mistake
        head = heads[str(path)]
        check_resonator_gyro(head.rate_dph, head.metadata.sample_rate_hz,
                             head.metadata.input_rate_dph or 0.0, str(path))
    # the soaks that join the drift fit are read once for the plateaus and its at-rest pass
    # (not with --motion error: a soak's motion is then the fit's error, said where it was)
    joins = settings.drift_from_soaks and options.motion != "error"
    soak_rests = SoakRests(options.motion,
                            _likely_warmups(settings.drift, aux) if joins else ())
    fitted = soak_fit or fit_soaks(soaks, settings=settings, prior=prior,
                                   read_options=options, progress=progress, rests=soak_rests)
    thermometer_fit, plateaus, table = fitted.thermometer, fitted.plateaus, fitted.table
    prior_fit, soak_rates = fitted.prior_fit, fitted.sample_rates_hz

    heads.update({str(path): options.head(path) for path in soaks if str(path) not in heads})
    training = [*drifts, *_soaks_for_drift(soaks, soak_rates, settings,
                                           heads[str(drifts[0])].metadata.sample_rate_hz)]
    training_heads = [heads[str(p)] for p in training]
    settings = _with_terms(settings, resolve_terms(settings.drift.terms, aux, training_heads))
    model, housing = _fit_drift(training, heads, thermometer_fit, options, progress,
                                len(drifts), settings.drift, aux, soak_rests)
    unit = heads[str(drifts[0])].metadata.unit
    record = _record(settings, aux, options, order=fitted.order)
    if prior_fit is not None:
        record["prior"] = {"units": prior_fit.prior.n_units,
                             "range_c": list(prior_fit.prior.temperature_range_c),
                             "max_temperature_std_c": prior_fit.max_temperature_std_c}
    unit_model = Model.single(
        AxisModel(thermometer=thermometer_fit, drift=model, housing=housing,
                  training=TrainingStatistics.from_runs(training_heads),
                  plateaus=tuple(p.to_dict() for p in plateaus)),
        unit=unit,
        provenance=provenance(
            {"soak": [str(p) for p in soaks], "drift": [str(p) for p in drifts]}, record),
    )
    return AxisCalibration(unit_model, tuple(plateaus), table, (), prior_fit, fitted)


def _baseline_settings(drift: DriftSettings) -> DriftSettings:
    """The housing baseline's fit: its own terms in h and dh/dt, with the default selection
    and the variables' default options (d2's filter)."""
    return dataclasses.replace(drift, terms=HOUSING_TERMS, select=DriftSettings.select,
                               **DriftSettings().variable_options())


def _likely_warmups(drift: DriftSettings, aux: Mapping[str, str] | None) -> tuple[float, ...]:
    """The warm-ups the drift fit and the housing baseline will likely take: their terms
    are resolved from the training files later (:func:`~hrgtc.pipeline.terms.resolve_terms`);
    a warm-up not among these only costs its fit a pass of its own."""
    terms = [drift.terms] if drift.terms is not None else [
        GRADIENT_TERMS, tuple(t.name for t in EQ21)]
    settings = [*(dataclasses.replace(drift, terms=t) for t in terms),
                _baseline_settings(drift)]
    found = []
    for each in settings:
        try:
            found.append(fit_warmup(each, aux))
        except (InputError, CalibrationError, TypeError, ValueError):
            continue  # the fit itself will say what is wrong
    return tuple(dict.fromkeys(found))


def _soaks_for_drift(soaks: Sequence[PathLike], soak_rates: Sequence[float],
                     settings: CalibrationSettings, drift_rate: float) -> list[PathLike]:
    """The soaks that join the drift fit: none unless ``settings.drift_from_soaks``, and
    only those at the drift runs' sample rate (the others are named in a warning)."""
    if not settings.drift_from_soaks:
        return []
    extra = [p for p, r in zip(soaks, soak_rates, strict=True) if math.isclose(r, drift_rate)]
    if len(extra) < len(soaks):
        warnings.warn(
            f"{len(soaks) - len(extra)} soak file(s) are not at the drift runs' "
            f"{drift_rate:g} Hz and are left out of the drift fit (its windows and settling "
            "time are counted in samples at one rate); they still calibrate the thermometer",
            HrgtcWarning, stacklevel=3)
    return extra


def fit_soaks(soaks: Sequence[PathLike], *, settings: CalibrationSettings | None = None,
              prior: ThermometerPrior | PathLike | None = None,
              read_options: ReadOptions | None = None,
              progress: StageProgress | None = None,
              rests: SoakRests | None = None) -> SoakFit:
    """The thermometer from the soaks: plateaus -> Table 1 -> Eq. 18 form -> Table 2.

    Parameters are those of :func:`fit_axis` (``settings.plateaus`` finds the plateaus,
    ``settings.thermometer.order`` is the polynomial's order unless a prior gives it);
    ``rests``: also run the at-rest detector of the drift fit on each soak's reading.
    """
    options = read_options or ReadOptions()
    settings = settings or CalibrationSettings()
    plateaus: list[Plateau] = []
    soak_rates: list[float] = []
    # the soaks are independent until their plateaus are combined: on every core
    # (hrgtc.core.forked), unless a reading held in memory serves them
    workers = (forked.processes(len(soaks), soaks)
               if type(options).read is ReadOptions.read else 1)
    each = SoakPass(options, settings, rests)
    for number, (rate, found, passed) in enumerate(forked.map_in_order(each, soaks, workers)):
        soak_rates.append(rate)
        plateaus.extend(found)
        if rests is not None:
            rests.keep(soaks[number], passed)
        if progress is not None:
            progress("soaks", number + 1, len(soaks))
    temperatures, frequencies = plateau_table(plateaus)
    prior_fit = None
    if prior is None:
        order = settings.thermometer.order
        thermometer = fit_thermometer(temperatures, frequencies, order=order)
    else:
        if not isinstance(prior, ThermometerPrior):
            prior = load_prior(prior)
        prior_fit = fit_with_prior(temperatures, frequencies, prior,
                                   [p.settled_freq_std_hz for p in plateaus])
        thermometer, order = prior_fit.thermometer, prior.order
    if not thermometer.is_monotonic:
        thermometer.temperature(frequencies)  # raises the explanatory CalibrationError
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ExtrapolationWarning)
        from_freq = thermometer.temperature(frequencies)
    table = tuple(
        {"chamber_c": float(t), "freq_hz": float(f), "temperature_from_freq_c": float(e),
         "error_c": float(e - t)}
        for t, f, e in zip(temperatures, frequencies, from_freq, strict=True)
    )
    return SoakFit(thermometer, tuple(plateaus), table, prior_fit, order, tuple(soak_rates))


def _with_terms(settings: CalibrationSettings, terms: Iterable[str]) -> CalibrationSettings:
    """``settings`` with the drift fit's candidate terms resolved."""
    drift = dataclasses.replace(settings.drift, terms=tuple(terms))
    return dataclasses.replace(settings, drift=drift)


def _record(settings: CalibrationSettings, aux: Mapping[str, str] | None,
            options: ReadOptions, **extra: Any) -> dict[str, Any]:
    """What a model file's provenance records of the settings: every field of ``settings``
    (:func:`hrgtc.settings.to_dict`), the channels, the baseline and the reading."""
    return {**to_dict(settings), **extra, "aux": dict(aux or {}),
            "housing_terms": list(HOUSING_TERMS),
            "motion": options.motion,
            "columns": dict(options.columns or {}), "units": dict(options.units or {})}


class _CountedRun:
    """A training run's chunks, counting the rows the spike filters removed in the last
    pass over it (the fit reads a run several times); with ``prints``, a pass after a
    whole one reads only the columns the fit takes (:mod:`~hrgtc.pipeline.narrow_reading`)."""

    def __init__(self, options: ReadOptions, path: PathLike,
                 prints: PassPrints | None = None) -> None:
        self.options, self.path, self._dropped, self.prints = options, path, {}, prints

    def __call__(self) -> Any:
        self._dropped = {}
        if self.prints is not None:
            return self.prints.chunks(self.options, self.path, self._dropped)
        return self.options.chunks(self.path, dropped=self._dropped)

    @property
    def spikes(self) -> int:
        return int(self._dropped.get("spikes", 0))

    @property
    def worker_path(self) -> PathLike | None:
        """The file, when a worker process may read it (not a reading held in memory:
        :class:`~hrgtc.drift.run_windows.ForkableRun`)."""
        return self.path if type(self.options).read is ReadOptions.read else None

    def passed(self) -> dict[str, int]:
        """What the last pass counted (the rows the spike filters removed)."""
        return dict(self._dropped)

    def restore(self, state: dict[str, int]) -> None:
        """Take the count of a pass made in a worker process."""
        self._dropped = dict(state)


def _fit_drift(training: Sequence[PathLike], heads: Mapping[str, Any], thermometer: Any,
               options: ReadOptions, progress: StageProgress | None, excitation_runs: int,
               drift: DriftSettings, aux: Mapping[str, str] | None,
               soaks: SoakRests | None = None) -> tuple[Any, Any]:
    """The drift model on ``training`` and the housing baseline (:data:`HOUSING_TERMS`)
    when every run has ``housing_c`` (None otherwise, or when its fit fails: the baseline
    is optional). ``soaks``: the soaks' passes met before (their at-rest passes and
    fingerprints, :class:`SoakRests`); an extra channel (``aux``) reads every column."""
    prints = None if aux else soaks.prints if soaks is not None else PassPrints()
    runs = [_CountedRun(options, path, prints) for path in training]
    # one at-rest pass per run
    rest_cache = {} if soaks is None else soaks.cache(training, excitation_runs, options)
    reading = TrainingReading(motion=options.motion, gaps=options.gaps, rest_cache=rest_cache)
    requests = [drift_model.FitRequest(drift, aux, excitation_runs,
                                       for_stage(progress, "drift"))]
    if all("housing_c" in heads[str(p)] for p in training):
        # its windows from the drift fit's pass
        requests.append(drift_model.FitRequest(_baseline_settings(drift),
                                               progress=for_stage(progress, "housing baseline")))
    model, *rest = drift_model.fit_jointly(runs, thermometer, requests, reading=reading)
    assert isinstance(model, drift_model.DriftModel)
    spikes = sum(run.spikes for run in runs)
    if spikes and model.accounting is not None:  # the accounting starts from the file's rows
        model.accounting.add_read(spikes)
        model.accounting.drop("spikes", spikes)
    housing = None
    if rest and isinstance(rest[0], CalibrationError):  # the baseline is optional: say why
        warnings.warn(f"no housing-thermistor baseline: {rest[0]}", HrgtcWarning, stacklevel=2)
    elif rest and isinstance(rest[0], Exception):
        raise rest[0]
    elif rest:
        housing = rest[0]
    return model, housing


def _sensor_columns(path: PathLike, options: ReadOptions) -> tuple[str, str]:
    """The file's names of the sensor thermometer and of the rate (of ``options.axis``)."""
    from hrgtc.recording import open_source
    from hrgtc.recording.mapping import parse_columns

    axis = options.axis
    mapping = parse_columns(options.columns)
    rate = f"rate_dph_{axis}" if axis else "rate_dph"
    ours = [f"temperature_c_{axis}", "temperature_c"] if axis else ["temperature_c"]
    try:
        with open_source(path) as source:
            names = set(source.names)
    except (OSError, ValueError):
        names = set()
    temperature = next((mapping.get(n, n) for n in ours if n in mapping or n in names),
                       "temperature_c")
    return temperature, mapping.get(rate, rate)


def _calibrate_sensor(soaks: Sequence[PathLike], drifts: Sequence[PathLike],
                      options: ReadOptions, progress: StageProgress | None,
                      settings: CalibrationSettings, aux: Mapping[str, str] | None,
                      soak_fit: SoakFit | None = None) -> AxisCalibration:
    """A gyro without a frequency output: its temperature sensor is the thermometer.

    Every run (soaks included) trains the drift model in (T, dT/dt); the identity
    thermometer's range is that of the training runs' temperatures.
    """
    options = dataclasses.replace(options, thermometer="sensor")
    if (dict(options.units or {}).get("temp") == "count"
            and not scales_temperature(options.temp_scale, options.temp_offset_c)):
        raise InputError(
            f"{drifts[0] if drifts else soaks[0]}: the temperature is a raw count "
            "(--temp-unit count) with no map to °C, and a model's thermometer, ranges and "
            "exports are in °C: give the datasheet's --temp-scale K --temp-offset C, or "
            "fit the map to a reference log written beside the run with --temp-ref LOG")
    training = [*drifts, *soaks]
    fitted = soak_fit or _sensor_thermometer(training, options)
    thermometer = fitted.thermometer
    heads = {str(path): options.head(path) for path in training}
    for path in drifts:  # any gyro: only a density beyond every gyro's can be told
        head = heads[str(path)]
        _check_logged_resonator(path, head, options)
        chamber = head["chamber_c"] if "chamber_c" in head else None
        check_setpoint_thermometer(head.freq_hz, chamber, str(path),
                                   *_sensor_columns(path, options)[:1],
                                   parse_columns(options.columns).get("chamber_c",
                                                                      "chamber_c"))
        message = implausible_for_any_gyro(head.rate_dph, head.metadata.sample_rate_hz)
        if message is not None:
            warnings.warn(f"{path}: column 'rate_dph': {message}", HrgtcWarning, stacklevel=3)
    settings = _with_terms(settings, resolve_terms(settings.drift.terms, aux,
                                                   [heads[str(p)] for p in training]))
    model, housing = _fit_drift(training, heads, thermometer, options, progress, len(drifts),
                                settings.drift, aux)
    unit_model = Model.single(
        AxisModel(thermometer=thermometer, drift=model, housing=housing,
                  training=TrainingStatistics.from_runs([heads[str(p)] for p in training])),
        unit=heads[str(drifts[0])].metadata.unit,
        provenance=provenance(
            {"soak": [str(p) for p in soaks], "drift": [str(p) for p in drifts]},
            _record(settings, aux, options, thermometer="sensor"),
        ),
    )
    return AxisCalibration(unit_model, (), (), (), None, fitted)


def _check_logged_resonator(path: PathLike, head: Any, options: ReadOptions) -> None:
    """A file that logs a resonator frequency beside the temperature sensor is an HRG's:
    its rate must have an HRG's noise and bias (a rate ×3600, ×1000 or ×57.3 has a MEMS
    gyro's, issue 27), and its frequency and rate columns must not be swapped."""
    from hrgtc.recording.checks import FREQ_SAMPLE_RANGE_HZ, _check_swapped

    logged = options.logged_frequency(path)
    if logged is None:
        return
    name, freq = logged
    rate = f"rate_dph_{options.axis}" if options.axis else "rate_dph"
    rate = dict(_sensor_rate_mapping(options)).get(rate, rate)
    swapped = _check_swapped(freq, np.asarray(head.rate_dph), name, rate)
    if swapped is not None:
        raise InputError(f"{path}: {swapped.message}")
    finite = freq[np.isfinite(freq)]
    median = float(np.median(finite)) if finite.size else math.nan
    if not FREQ_SAMPLE_RANGE_HZ[0] <= median <= FREQ_SAMPLE_RANGE_HZ[1]:
        return
    check_resonator_gyro(
        head.rate_dph, head.metadata.sample_rate_hz, head.metadata.input_rate_dph or 0.0,
        str(path), rate,
        hrg=(f"the file logs a resonator frequency (column {name!r}, median {median:.6g} Hz: "
             "an HRG)", f"if {name!r} is not this gyro's resonator, rename that column"),
        levels=False)


def _sensor_rate_mapping(options: ReadOptions) -> dict[str, str]:
    return parse_columns(options.columns)


def _sensor_thermometer(training: Sequence[PathLike], options: ReadOptions) -> SoakFit:
    """The identity thermometer over the training runs' temperatures at rest (each run's
    sensor and rate columns checked for a swap on the way)."""
    low, high = math.inf, -math.inf
    why = []
    for path in training:  # the range of the samples the fit uses: those at rest
        rest = run_rest(options.chunks(path), options.motion)
        keep = rest.keep
        if rest.mask is not None and not keep.any():
            why.append(f"{path}: {rest.mask.summary()}")
        row = 0
        temperature, rate = ChannelShape(), ChannelShape()
        for chunk in options.chunks(path):
            used = chunk.freq_hz[keep[row:row + len(chunk)]]
            row += len(chunk)
            temperature.partial_fit(chunk.freq_hz)
            rate.partial_fit(chunk.rate_dph)
            if used.size:
                low = min(low, float(np.min(used)))
                high = max(high, float(np.max(used)))
        check_sensor_swap(temperature, rate, str(path), *_sensor_columns(path, options))
    if why and not math.isfinite(low):
        raise CalibrationError(
            "no sample of the training runs is at rest, so there is nothing to train on ("
            + "; ".join(why) + "); if the gyro was still, its rate may be too coarse for the "
            "motion detector (a few LSB of noise): check --rate-unit, or pass --motion keep")
    return SoakFit(identity((low, high)))
