"""Does a recording fit a model? The checks made before a run is compensated with it: the
kind of thermometer, the rate noise against the training data's (a unit mistake), and
the band of plausible frequencies the reader enforces.

A layer of its own, just above :mod:`hrgtc.model`: the compensator
(:mod:`hrgtc.compensate.file_pass`, ``multi_axis``) and the evaluation
(:mod:`hrgtc.evaluation.run_evaluation`), the report and the calibration
chain all ask it, and none of them may import another's stage."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from hrgtc import recording as rec_io
from hrgtc.core.errors import InputError
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Recording


def check_recording_noise(model: Model, chunk: Recording, source: str = "",
                          axis: str | None = None) -> None:
    """Refuse a recording whose rate noise is a unit factor off the model's training data
    (:func:`hrgtc.drift.training.check_noise`), every axis of an instrument's.

    Every axis of ``model`` is checked (a single-axis model's on the plain columns); axes
    the chunk lacks are left to the compensator's own error. ``axis``: the file's axis
    a single-axis ``chunk`` (an axis view) was read from, named in the message.
    """
    from hrgtc.drift.training import check_noise
    from hrgtc.recording import axis_names, axis_view

    axis_of_view = axis
    units = dict(model.axes)
    found = axis_names(chunk.names)
    fs = chunk.metadata.sample_rate_hz
    for axis, unit in units.items():
        if axis and axis in found:
            view = axis_view(chunk, axis)
            column = f"rate_dph_{axis}"
            ratio = check_noise(unit.training, view.rate_dph, fs, source, column)
        elif not axis and "rate_dph" in chunk:
            column = "rate_dph" if axis_of_view is None else f"rate_dph_{axis_of_view}"
            ratio = check_noise(unit.training, chunk.rate_dph, fs, source, column)
        else:
            continue
        check_swapped_rate(unit.training, chunk, column, ratio, source)


#: A gyro's rate is never this much quieter than its training data's: the noise floor is
#: the sensor's own (a noisier recording, under vibration, is legitimate).
QUIETER_THAN_TRAINING = 10.0
#: A column whose noise is within this factor of the training rate's has the rate's noise.
SAME_NOISE = 2.5


def check_swapped_rate(statistics: Any, chunk: Recording, column: str, ratio: float,
                       source: str = "") -> None:
    """Refuse a rate column as quiet as a temperature while another column has the rate's
    noise: swapped headers (``rate_dph`` and ``temperature_c``, issue 21's audit).

    ``ratio`` is the rate column's noise over the training rate's
    (:func:`hrgtc.drift.training.check_noise`, NaN for a constant or quantised column).
    A temperature's sample-to-sample noise is some 1e-4 of a gyro rate's; alone, a quiet
    rate is not refused (an older or synthetic model may have another noise), only when
    another column of the recording has the rate's noise in its place.

    Raises
    ------
    InputError
        Names the file, both columns and their noise ratios.
    """
    from hrgtc.drift.training import rate_noise_dph

    if statistics is None or not statistics.rate_noise_dph > 0.0:
        return
    values = chunk[column] if column in chunk else chunk.rate_dph
    quiet = (ratio < 1.0 / QUIETER_THAN_TRAINING if math.isfinite(ratio)
             else rate_noise_dph(values) == 0.0)
    if not quiet:
        return
    fs = chunk.metadata.sample_rate_hz
    for name in chunk.names:
        if name == "time_s" or name.startswith(("rate_dph", "freq_hz")):
            continue
        other = statistics.noise_ratio(chunk[name], fs)
        if math.isfinite(other) and 1.0 / SAME_NOISE <= other <= SAME_NOISE:
            where = f"{source}: " if source else ""
            shown = f"{ratio:.3g}×" if math.isfinite(ratio) else "none of"
            raise InputError(
                f"{where}the headers {column} and {name} look swapped: column {column!r} "
                f"has {shown} the noise of the model's training rate (a temperature's, "
                f"not a gyro's) and column {name!r} {other:.3g}× (the rate's); fix the "
                f"header line of the file, or map the columns with --col {column}={name} "
                f"--col {name}={column}")


#: Frequencies farther than this beyond the calibrated span are errors, not extrapolation. [°C]
PLAUSIBLE_MARGIN_C = 100.0


def frequency_span(model: AxisModel | Model) -> tuple[float, float]:
    """The frequencies the model was calibrated on: thermometer and drift training ranges. [Hz]"""
    low, high = model.thermometer.frequency_range_hz
    if "f" in model.drift.ranges:
        reference = model.drift.settings.reference_freq_hz
        f_low, f_high = model.drift.ranges["f"]
        low, high = min(low, reference + f_low), max(high, reference + f_high)
    return float(low), float(high)


def plausible_frequency_band(model: AxisModel | Model,
                             margin_c: float = PLAUSIBLE_MARGIN_C) -> tuple[float, float]:
    """The calibrated span widened by ``margin_c`` of temperature at the steepest slope. [Hz]

    A sample outside it is no temperature this unit can reach in a test: a glitch,
    another unit's file or a wrong column, reported as an error on reading.
    """
    low, high = frequency_span(model)
    t_low, t_high = model.thermometer.temperature_range_c
    slope = float(np.max(np.abs(model.thermometer.slope_hz_per_c(np.array([t_low, t_high])))))
    margin = margin_c * max(slope, 1e-6 * high)
    return low - margin, high + margin


def check_thermometer_kind(options: rec_io.ReadOptions, model: Model,
                           model_file: object = None) -> None:
    """Refuse to read a recording as the other kind of thermometer than the model's (any axis's).

    A sensor-thermometer model (``calibrate --thermometer sensor``) reads the gyro's
    temperature sensor [°C] in the place of the frequency; applied to a frequency
    recording, every sample would be "far outside the calibrated span" with no word of
    why. The reverse (a resonator model on a sensor reading) likewise.

    Raises
    ------
    InputError
        The kinds differ: says which the model is (naming ``model_file`` when given)
        and which option to pass.
    """
    reading = options.thermometer
    other = [part for part in model.axes.values() if part.thermometer.source != reading]
    if not other:
        return
    model_kind = other[0].thermometer.source
    low, high = other[0].thermometer.temperature_range_c
    named = f"{model_file}: " if model_file is not None else ""
    if model_kind == "sensor":
        raise InputError(
            f"{named}the model of unit {model.unit!r} is a sensor-thermometer model "
            f"(calibrated with --thermometer sensor on the gyro's temperature sensor, {low:g} "
            f"to {high:g} °C), but the recording is read as a resonator frequency (freq_hz); "
            "pass --thermometer sensor (and --col temperature_c=... for the sensor's column), "
            "or use a model calibrated on the resonator frequency")
    raise InputError(
        f"{named}the model of unit {model.unit!r} is a resonator-thermometer model (its "
        "thermometer turns the resonator frequency into temperature), but the recording is "
        "read with --thermometer sensor (a temperature sensor in the place of freq_hz); drop "
        "--thermometer sensor for this model, or calibrate one with --thermometer sensor")


def with_model_band(options: rec_io.ReadOptions, model: Model) -> rec_io.ReadOptions:
    """``options`` that check every frequency against a single-axis model's plausible band.

    Raises
    ------
    InputError
        The model's thermometer is not the kind the recording is read as
        (:func:`check_thermometer_kind`).
    """
    check_thermometer_kind(options, model)
    return dataclasses.replace(options, freq_band_hz=plausible_frequency_band(model),
                               freq_span_hz=frequency_span(model))
