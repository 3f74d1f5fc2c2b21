"""Validation of recordings against the recording contract of DESIGN.md.

One place checks every recording that enters hrgtc, whole or chunk by chunk:

* the required columns ``time_s``, ``freq_hz`` and ``rate_dph`` are present
  (a multi-axis recording: ``freq_hz_<axis>`` and ``rate_dph_<axis>`` of every
  axis, see :mod:`hrgtc.recording.axes`; every check below runs per axis);
* no value is NaN or infinite;
* ``time_s`` is strictly increasing (no duplicates, no steps back);
* no time step is longer than :data:`GAP_PERIODS` sample periods (a gap); gaps
  are listed, and the caller chooses to treat them as an error or to split the
  recording into segments (:func:`split_at_gaps`);
* the median time step agrees with the metadata's sample rate within
  :data:`SAMPLE_RATE_TOLERANCE`;
* the units look right (heuristics on the first :data:`HEURISTIC_ROWS` rows):

  - ``freq_hz``: the n = 2 mode of an HRG lies between a few hundred Hz and a few
    tens of kHz (≈ 4425 Hz for the unit of [1]); a median below
    :data:`KHZ_BELOW_HZ` means the column is in kHz, a median above
    :data:`FREQ_MAX_HZ` (or not positive) is implausible;
  - ``rate_dph``: a gyro on a bench recorded in °/h reads the Earth-rate component
    (up to ≈ 15 °/h) plus its bias (up to ±100 °/h), with white noise of
    ≈ 0.01–5 °/h per sample at 1–200 Hz. The same data in °/s are 3600 times
    smaller, in rad/s ≈ 206,265 times. The column is flagged when both its median
    magnitude is below :data:`RATE_LEVEL_DPH` (1 °/h) *and* either its per-sample
    noise, ``std(diff(rate)) / sqrt(2)``, is below :data:`RATE_NOISE_DPH` (1e-3 °/h)
    or the robust scale of its 1 s block means (MAD of their differences / √2,
    insensitive to slow drift and independent of the sample rate: 0.06–6 °/h for
    an HRG in °/h, 3600 times less in °/s) is below :data:`RATE_BLOCK_NOISE_DPH`
    (0.01 °/h). With a large known input rate (``|input_rate_dph| >= 3600``, a rate
    table) the column is also flagged when its median is the input rate divided by
    3600 or by 206,265 (within a factor of 2). Real °/h data (and the simulator's
    output at 1, 10 and 200 Hz, at rest or on a rate table) never trip these rules;
  - ``time_s``: without a sample rate in the metadata, steps that imply less than
    :data:`SLOW_SAMPLE_RATE_HZ` suggest milliseconds (``--time-unit ms``);

* every sample is plausible: ``freq_hz`` within :data:`FREQ_SAMPLE_RANGE_HZ` (or,
  given a model, within its calibrated span widened by 100 °C) and within
  :data:`FREQ_JUMP_FRACTION` of the median of the first rows; ``rate_dph`` and
  ``bias_dph`` within ±:data:`RATE_MAX_DPH`; temperatures within
  :data:`TEMPERATURE_RANGE_C`;
* the sample rate holds through the whole file: the mean step of every block of
  :data:`RATE_CHECK_ROWS` rows (gaps left out) agrees with the metadata.

With the sensor thermometer (``thermometer="sensor"``, a gyro without a frequency
output) ``freq_hz`` holds a temperature: it is checked against
:data:`TEMPERATURE_RANGE_C`, without the kHz heuristic or the 5 % jump rule. With
an ``input_rate_dph`` column the rate-unit heuristic runs on rate - input rate.

The single checks and heuristics are in :mod:`hrgtc.recording.checks`, the checks of
the time axis carried across chunks (order, gaps, the sample rate throughout) in
:mod:`hrgtc.recording.time_continuity`.

Rows are numbered from 0 (the first data row), over the whole file also when it
is validated chunk by chunk.

[1] X. Wang et al., "Temperature Drift Compensation for Hemispherical Resonator
    Gyro Based on Natural Frequency", Sensors 12(5), 6434-6446, 2012.
    doi:10.3390/s120506434
"""

from __future__ import annotations

from typing import Any, Self

import numpy as np

from hrgtc.core.errors import RecordingError
from hrgtc.recording.axes import axis_input_rate_dph, axis_names, base_name
from hrgtc.recording.checks import (
    _BOUNDS,
    DEG_PER_RAD_X3600,
    FREQ_JUMP_FRACTION,
    FREQ_MAX_HZ,
    FREQ_SAMPLE_RANGE_HZ,
    KHZ_BELOW_HZ,
    RATE_BLOCK_NOISE_DPH,
    RATE_CHECK_ROWS,
    RATE_LEVEL_DPH,
    RATE_MAX_DPH,
    RATE_NOISE_DPH,
    RATE_TABLE_DPH,
    SAMPLE_RATE_TOLERANCE,
    SLOW_SAMPLE_RATE_HZ,
    TEMPERATURE_RANGE_C,
    Problem,
    ValidationReport,
    _check_freq_unit,
    _check_rate_unit,
    _check_sample_rate,
    _check_swapped,
    _check_time_unit,
    check_thermometer,
    finite_extremes,
    measured_sample_rate,
    problems_message,
)
from hrgtc.recording.file_rows import FileRows
from hrgtc.recording.gaps import (
    GAP_PERIODS,
    GAP_POLICIES,
    Gap,
    GapPolicy,
    check_gap_policy,
    split_at_gaps,
)
from hrgtc.recording.schema import COLUMNS, Metadata, Recording
from hrgtc.recording.time_continuity import TimeContinuity
from hrgtc.settings.reading import ReadSettings

__all__ = [
    "DEG_PER_RAD_X3600", "FREQ_JUMP_FRACTION", "FREQ_MAX_HZ", "FREQ_SAMPLE_RANGE_HZ",
    "GAP_PERIODS", "GAP_POLICIES", "HEURISTIC_ROWS", "KHZ_BELOW_HZ", "RATE_BLOCK_NOISE_DPH",
    "RATE_CHECK_ROWS", "RATE_LEVEL_DPH", "RATE_MAX_DPH", "RATE_NOISE_DPH", "RATE_TABLE_DPH",
    "SAMPLE_RATE_TOLERANCE", "SLOW_SAMPLE_RATE_HZ", "TEMPERATURE_RANGE_C", "Gap", "GapPolicy",
    "Problem", "RecordingValidator", "ValidationReport", "check_gap_policy",
    "measured_sample_rate", "problems_message", "split_at_gaps", "validate",
]


HEURISTIC_ROWS = 100_000  # rows used for the sample-rate and unit heuristics


class RecordingValidator:
    """Validate a recording chunk by chunk, carrying state across chunks.

    Time continuity and row numbers run over the whole recording; the unit and
    sample-rate heuristics look at its first :data:`HEURISTIC_ROWS` rows.
    ``validate(recording)`` is "a new validator, one partial_fit, finish".

    Parameters
    ----------
    gaps
        ``"error"``: gaps are problems; ``"split"`` / ``"ignore"``: gaps are only
        listed (split the recording with :func:`split_at_gaps`).
    """

    def __init__(self, gaps: GapPolicy | str = "error",
                 freq_band_hz: tuple[float, float] | None = None,
                 freq_span_hz: tuple[float, float] | None = None,
                 thermometer: str = ReadSettings.thermometer,
                 dropout_s: float = ReadSettings.dropout_s) -> None:
        self.gaps = check_gap_policy(gaps)
        self.dropout_s = float(dropout_s)
        self.freq_band_hz = freq_band_hz
        self.freq_span_hz = freq_span_hz
        self.thermometer = check_thermometer(thermometer)
        self._bounds = dict(_BOUNDS)
        if freq_band_hz is not None:
            unit = "°C" if self.thermometer == "sensor" else "Hz"
            self._bounds["freq_hz"] = (float(freq_band_hz[0]), float(freq_band_hz[1]), unit)
        elif self.thermometer == "sensor":  # freq_hz holds the sensor's temperature
            self._bounds["freq_hz"] = (*TEMPERATURE_RANGE_C, "°C")
        self._out_of_bounds: dict[str, list[Any]] = {}  # column -> [row, value, count]
        self.temperature_counts = False  # see count_temperatures
        self._freq_reference: dict[str, float] = {}  # frequency column -> median of first rows
        self._jump: dict[str, list[Any]] = {}  # frequency column -> [row, value, count]
        self.axes: tuple[str, ...] = ()
        self._suffixes: tuple[str, ...] = ("",)
        self.rows = 0
        self._file_rows = FileRows()  # rows seen -> rows of the file
        self.source: str | None = None
        self.metadata: Metadata | None = None
        self._missing: tuple[str, ...] = ()
        self._not_finite: dict[str, list[Any]] = {}  # column -> [row, value, count]
        self._sample: dict[str, list[np.ndarray]] = {}
        self._sample_rows = 0
        self._heuristics: list[Problem] | None = None
        self.measured_sample_rate_hz: float | None = None
        self._names: tuple[str, ...] = ()
        #: Order, gaps and the sample rate of the time axis, over the whole recording.
        self.time_axis = TimeContinuity()

    def count_temperatures(self) -> None:
        """The temperature columns hold a raw count, not yet mapped to °C (``--temp-unit
        count`` alone, or a count a ``--temp-ref`` log maps later): no °C bounds judge them
        (a map's result is judged where it is applied)."""
        self.temperature_counts = True
        self._bounds.pop("temperature_c", None)
        if self.thermometer == "sensor":
            self._bounds.pop("freq_hz", None)

    # -- feeding -------------------------------------------------------------
    def partial_fit(self, chunk: Recording, file_rows: np.ndarray | None = None) -> Self:
        """Check the next chunk (rows continue from the previous chunk); ``file_rows``: the
        file row of each of its rows when the reader left rows out (messages name those)."""
        if file_rows is not None:
            self._file_rows.partial_fit(self.rows, file_rows)
        if self.metadata is None:
            self.metadata = chunk.metadata
            self.source = chunk.source
            self.axes = axis_names(chunk.names)
            self._suffixes = tuple(f"_{axis}" for axis in self.axes) or ("",)
            required = ("time_s", *(f"{name}{suffix}" for suffix in self._suffixes
                                    for name in ("freq_hz", "rate_dph")))
            self._missing = tuple(c for c in required if c not in chunk)
            self._names = tuple(chunk.names)
            sampled = (*required, *(f"input_rate_dph{suffix}" for suffix in self._suffixes))
            self._sample = {name: [] for name in sampled if name in chunk}
        offset, n = self.rows, len(chunk)
        for name in chunk.names:
            if self._sensor_copy(name, chunk):
                continue  # the temperature column it copies is checked (and named) itself
            if base_name(name, self.axes) not in COLUMNS:
                continue  # a column of the file's own (a status word, a magnetometer): carried
                # along, read by nothing, so a blank in it refuses nothing
            values = chunk[name]
            low, high, _ = self._bounds.get(base_name(name, self.axes), (-np.inf, np.inf, ""))
            extremes = finite_extremes(values)
            if name in self._freq_reference:
                self._check_jumps(name, values, offset, extremes)
            if extremes is not None and low <= extremes[0] and extremes[1] <= high:
                continue  # every value finite and within bounds: nothing to report
            bad = ~np.isfinite(values)
            if bad.any():
                state = self._not_finite.get(name)
                if state is None:
                    first = int(np.argmax(bad))
                    self._not_finite[name] = [offset + first, values[first], int(bad.sum())]
                else:
                    state[2] += int(bad.sum())
            if base_name(name, self.axes) in self._bounds:
                self._check_bounds(name, values, offset)
        if "time_s" in chunk and n:
            self.time_axis.partial_fit(chunk.time_s, offset, self.metadata, chunk, file_rows)
        if self._heuristics is None:
            self._collect_sample(chunk)
        self.rows += n
        return self

    def _sensor_copy(self, name: str, chunk: Recording) -> bool:
        """True for ``freq_hz*`` of the sensor thermometer: a copy of a temperature column."""
        if self.thermometer != "sensor":
            return False
        base, axis = base_name(name, self.axes), name[len("freq_hz_"):]
        return base == "freq_hz" and (f"temperature_c_{axis}" in chunk
                                      or "temperature_c" in chunk)

    def _check_bounds(self, name: str, values: np.ndarray, offset: int) -> None:
        low, high, _ = self._bounds[base_name(name, self.axes)]
        with np.errstate(invalid="ignore"):
            bad = ((values < low) | (values > high)) & np.isfinite(values)
        if bad.any():
            state = self._out_of_bounds.get(name)
            if state is None:
                first = int(np.argmax(bad))
                self._out_of_bounds[name] = [offset + first, float(values[first]),
                                             int(bad.sum())]
            else:
                state[2] += int(bad.sum())

    def _check_jumps(self, name: str, freq: np.ndarray, offset: int,
                     extremes: tuple[float, float] | None = None) -> None:
        """Frequencies too far from the run's median; ``extremes``: min and max of ``freq``."""
        reference = self._freq_reference[name]
        band = FREQ_JUMP_FRACTION * reference * (1.0 - 1e-9)  # margin for rounding
        if extremes is not None and reference - band < extremes[0] and extremes[1] < (
                reference + band):
            return  # no sample near the limit, let alone beyond it
        with np.errstate(invalid="ignore"):
            bad = (np.abs(freq - reference) > FREQ_JUMP_FRACTION * reference) & np.isfinite(freq)
        if bad.any():
            state = self._jump.get(name)
            if state is None:
                first = int(np.argmax(bad))
                self._jump[name] = [offset + first, float(freq[first]), int(bad.sum())]
            else:
                state[2] += int(bad.sum())

    def _collect_sample(self, chunk: Recording) -> None:
        take = min(len(chunk), HEURISTIC_ROWS - self._sample_rows)
        for name, parts in self._sample.items():
            parts.append(np.array(chunk[name][:take]))
        self._sample_rows += take
        if self._sample_rows >= HEURISTIC_ROWS:
            self._run_heuristics()

    @property
    def heuristics_done(self) -> bool:
        """True once the unit and sample-rate heuristics have run."""
        return self._heuristics is not None

    # -- results -------------------------------------------------------------
    @property
    def problems(self) -> list[Problem]:
        """Problems found so far (heuristic ones once :attr:`heuristics_done`)."""
        problems: list[Problem] = []
        if self.metadata is not None and self.rows == 0:
            problems.append(Problem("empty", "the recording has no rows"))
        if self._missing:
            columns = "', '".join(self._missing)
            headless = bool(self._names) and all(n.startswith("column_") for n in self._names)
            found = (f"the file has no header line, so its columns are {list(self._names)}"
                     if headless else f"the recording's columns are {list(self._names)}")
            problems.append(
                Problem(
                    "missing_column",
                    f"required column(s) '{columns}' missing ({found}); map your names with "
                    f"--col {self._missing[0]}=<your column name> "
                    f"(columns={{'{self._missing[0]}': ...}})",
                    column=self._missing[0],
                )
            )
        for name, (row, value, count) in self._not_finite.items():
            problems.append(
                Problem(
                    "not_finite",
                    f"column '{name}', row {row}: value {value} is not finite "
                    f"(first of {count} such rows); remove or interpolate those rows",
                    column=name,
                    row=row,
                    value=str(value),
                    count=count,
                )
            )
        unit_problem = any(p.kind in ("freq_unit", "swapped_columns")
                           for p in self._heuristics or [])
        for name, (row, value, count) in self._out_of_bounds.items():
            is_freq = base_name(name, self.axes) == "freq_hz"
            if is_freq and (self._heuristics is None or unit_problem):
                continue  # the unit heuristic (e.g. "looks like kHz") says it better
            problems.append(self._bounds_problem(name, row, value, count))
        for name, (row, value, count) in self._jump.items():
            problems.append(Problem(
                "implausible",
                f"column '{name}', row {row}: {value:.6g} Hz is more than "
                f"{FREQ_JUMP_FRACTION:.0%} away from the run's median "
                f"{self._freq_reference[name]:.6g} Hz (a resonator moves ≈ 0.01 %/°C; first of "
                f"{count} such rows): a glitch or two files joined; remove those rows "
                "(--spikes drop)",
                column=name, row=row, value=f"{value:.6g}", count=count))
        # a time unit or sample rate wrong for the whole file: its gaps and "rate changes"
        # are consequences, not news (one diagnosis, see hrgtc.core.time_steps)
        # (until the heuristics have run, a wrong unit cannot be ruled out: the gaps and
        # rate changes wait for them, as the reader holds its chunks back until then)
        whole_file = self._heuristics is None or any(
            p.kind in ("sample_rate", "time_unit") and p.row is None
            for p in self._heuristics)
        problems += self.time_axis.problems(self.gaps, whole_file, self.dropout_s)
        problems += self._heuristics or []
        return [self._file_rows.problem(p) for p in problems]

    def _bounds_problem(self, name: str, row: int, value: float, count: int) -> Problem:
        base = base_name(name, self.axes)
        low, high, unit = self._bounds[base]
        if base == "freq_hz" and self.thermometer == "sensor":
            why = f"outside {low:g} to {high:g} °C (the sensor thermometer's temperature)"
            fix = ("a glitch or not a temperature in °C: remove the row (--spikes drop) or "
                   "check --col temperature_c=... and --temp-scale/--temp-offset")
        elif base == "freq_hz" and self.freq_band_hz is not None:
            span = self.freq_span_hz or self.freq_band_hz
            why = (f"far outside the model's calibrated span {span[0]:.6g} to {span[1]:.6g} Hz "
                   f"(more than the frequency of 100 °C beyond it: {low:.6g} to {high:.6g} Hz)")
            fix = ("a glitch, another unit's recording, or the wrong column? remove the row or "
                   "check --col freq_hz=... and --freq-unit")
        elif base == "freq_hz":
            why = (f"outside {low:g} to {high:g} Hz, where the resonator frequency of any HRG "
                   "lies")
            fix = "a glitch or the wrong column: remove the row or check --col/--freq-unit"
        elif base in ("rate_dph", "bias_dph", "input_rate_dph"):
            why = f"beyond ±{high:g} °/h (1000 °/s), more than any " + (
                "gyro in a test" if self.thermometer == "sensor" else "HRG") + " measures"
            fix = ("a glitch or the wrong column: remove the row (--spikes drop) or check "
                   "--col/--rate-unit")
        else:
            why = f"outside {low:g} to {high:g} °C"
            fix = "a glitch or not a temperature in °C: remove the row (--spikes drop) or check "
            fix += ("--temp-scale/--temp-offset (a raw sensor count? calibrate --temp-ref LOG "
                    "fits its map to a reference log)" if base == "temperature_c"
                    else "the mapping")
        return Problem(
            "implausible",
            f"column '{name}', row {row}: {value:.6g} {unit} is {why} (first of {count} such "
            f"rows); {fix}",
            column=name, row=row, value=f"{value:.6g}", count=count)

    def raise_for_problems(self) -> None:
        """Raise :class:`~hrgtc.core.errors.RecordingError` if a problem was found so far."""
        problems = self.problems
        if problems:
            raise RecordingError(problems_message(self.source, problems))

    def finish(self) -> ValidationReport:
        """Run the heuristics if still pending and return the report."""
        if self._heuristics is None:
            self._run_heuristics()
        problems = tuple(self.problems)
        if self.metadata is None:
            problems = (Problem("empty", "the recording has no rows"),)
        return ValidationReport(
            ok=not problems,
            problems=problems,
            gaps=tuple(self.time_axis.gaps),
            n_gaps=self.time_axis.n_gaps,
            rows=self.rows,
            source=self.source,
            measured_sample_rate_hz=self.measured_sample_rate_hz,
            gap_policy=self.gaps,
            n_dropouts=self.time_axis.dropouts(self.dropout_s)[0],
            dropout_s=self.dropout_s,
            duty_cycled=self.time_axis.duty_cycled(self.dropout_s),
        )

    # -- heuristics ----------------------------------------------------------
    def _run_heuristics(self) -> None:
        sample = {name: np.concatenate(parts) for name, parts in self._sample.items() if parts}
        self._sample = {}
        problems: list[Problem] = []
        if "time_s" in sample and self.metadata is not None:
            self.measured_sample_rate_hz = measured_sample_rate(sample["time_s"])
            problem = _check_sample_rate(self.metadata.sample_rate_hz, self.measured_sample_rate_hz)
            # clock times carry their unit: a slow logger of clock times is just slow
            clock = bool(self.metadata.extra.get("time_origin"))
            if (problem is None and self.metadata.extra.get("sample_rate_inferred")
                    and not clock):
                problem = _check_time_unit(self.measured_sample_rate_hz, sample["time_s"])
            if problem:
                problems.append(problem)
        for axis, suffix in zip(self.axes or (None,), self._suffixes, strict=True):
            problems += self._axis_heuristics(sample, axis, suffix)
        self._heuristics = problems


    def _axis_heuristics(self, sample: dict[str, np.ndarray], axis: str | None,
                         suffix: str) -> list[Problem]:
        """Unit heuristics of one axis's frequency and rate (on rate - input rate)."""
        problems: list[Problem] = []
        freq_name, rate_name = f"freq_hz{suffix}", f"rate_dph{suffix}"
        if freq_name in sample and self.thermometer != "sensor":
            freq = sample[freq_name]
            problem = _check_freq_unit(freq, freq_name)
            finite = freq[np.isfinite(freq)]
            if problem and rate_name in sample:
                swapped = _check_swapped(freq, sample[rate_name], freq_name, rate_name)
                if swapped is not None:
                    problems.append(swapped)
                    return problems  # the rate's unit check would only add noise
            if problem:
                problems.append(problem)
            elif finite.size:
                self._freq_reference[freq_name] = float(np.median(finite))
                self._check_jumps(freq_name, freq, 0)
        if rate_name in sample and self.metadata is not None:
            rate, sample_rate = sample[rate_name], self.metadata.sample_rate_hz
            inputs = sample.get(f"input_rate_dph{suffix}")
            if inputs is None:
                problem = _check_rate_unit(rate, axis_input_rate_dph(self.metadata, axis),
                                           sample_rate, rate_name)
            else:  # rate-table steps are not the gyro's signal: check rate - input rate
                problem = _check_rate_unit(rate - inputs, 0.0, sample_rate, rate_name)
                finite = inputs[np.isfinite(inputs)]
                level = float(np.median(finite)) if finite.size else 0.0
                if problem is None and abs(level) >= RATE_TABLE_DPH:
                    problem = _check_rate_unit(rate, level, sample_rate, rate_name)
            if problem:
                problems.append(problem)
        return problems


def validate(
    recording: Recording, gaps: GapPolicy | str = "error", *, raise_errors: bool = True,
    freq_band_hz: tuple[float, float] | None = None,
    freq_span_hz: tuple[float, float] | None = None,
    thermometer: str = ReadSettings.thermometer,
    file_rows: np.ndarray | None = None,
    dropout_s: float = ReadSettings.dropout_s,
    temperature_counts: bool = False,
) -> ValidationReport:
    """Check a recording against the recording contract (see the module docstring).

    Parameters
    ----------
    recording
        The recording to check.
    gaps
        ``"error"``: gaps longer than :data:`GAP_PERIODS` sample periods are
        problems; ``"split"``: they are listed and the caller splits the recording
        with :func:`split_at_gaps`; ``"ignore"``: they are only listed.
    raise_errors
        Raise :class:`~hrgtc.core.errors.RecordingError` on a problem (default) rather
        than return a report with ``ok=False``.
    freq_band_hz, freq_span_hz
        Plausible frequencies given a model (every sample must lie in the band;
        without a model :data:`FREQ_SAMPLE_RANGE_HZ`) and its calibrated span.
    thermometer
        ``"resonator"`` (default) or ``"sensor"``: ``freq_hz`` holds a temperature
        sensor's reading [°C], checked as a temperature.
    file_rows
        The file row of each row when the reader left rows out before (spikes,
        duplicates, a slice): the messages name rows of the file.
    dropout_s
        Gaps no longer than this are dropouts, bridged and counted whatever ``gaps``
        says (they change no result). [s]
    temperature_counts
        The temperature columns hold a raw count not yet mapped to °C: no °C bounds.

    Returns
    -------
    ValidationReport

    Raises
    ------
    RecordingError
        Message names the file, column, first bad row, the bad value and the fix.
    """
    validator = RecordingValidator(gaps, freq_band_hz, freq_span_hz, thermometer, dropout_s)
    if temperature_counts:
        validator.count_temperatures()
    validator.partial_fit(recording, file_rows)
    report = validator.finish()
    if raise_errors:
        report.raise_for_problems()
    return report
