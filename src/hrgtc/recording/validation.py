"""Validation of recordings against the recording contract of DESIGN.md.

One place checks every recording that enters hrgtc, whole or chunk by chunk:

* the required columns ``time_s``, ``freq_hz`` and ``rate_dph`` are present;
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

The single checks and heuristics are in :mod:`hrgtc.recording.checks`.

Rows are numbered from 0 (the first data row), over the whole file also when it
is validated chunk by chunk.

[1] X. Wang et al., "Temperature Drift Compensation for Hemispherical Resonator
    Gyro Based on Natural Frequency", Sensors 12(5), 6434-6446, 2012.
    doi:10.3390/s120506434
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from hrgtc.errors import RecordingError
from hrgtc.recording.checks import (
    DEG_PER_RAD_X3600,
    FREQ_MAX_HZ,
    KHZ_BELOW_HZ,
    RATE_BLOCK_NOISE_DPH,
    RATE_LEVEL_DPH,
    RATE_NOISE_DPH,
    RATE_TABLE_DPH,
    SAMPLE_RATE_TOLERANCE,
    SLOW_SAMPLE_RATE_HZ,
    Problem,
    _check_freq_unit,
    _check_rate_unit,
    _check_sample_rate,
    _check_time_unit,
    finite_extremes,
    measured_sample_rate,
)
from hrgtc.recording.gaps import (
    GAP_PERIODS,
    GAP_POLICIES,
    MAX_LISTED_GAPS,
    Gap,
    GapPolicy,
    check_gap_policy,
    split_at_gaps,
)
from hrgtc.recording.schema import REQUIRED_COLUMNS, Metadata, Recording

__all__ = [
    "DEG_PER_RAD_X3600", "FREQ_MAX_HZ", "GAP_PERIODS", "GAP_POLICIES", "HEURISTIC_ROWS",
    "KHZ_BELOW_HZ", "RATE_BLOCK_NOISE_DPH", "RATE_LEVEL_DPH", "RATE_NOISE_DPH",
    "RATE_TABLE_DPH", "SAMPLE_RATE_TOLERANCE", "SLOW_SAMPLE_RATE_HZ", "Gap", "GapPolicy",
    "Problem", "RecordingValidator", "ValidationReport", "check_gap_policy",
    "measured_sample_rate", "problems_message", "split_at_gaps", "validate",
]


HEURISTIC_ROWS = 100_000  # rows used for the sample-rate and unit heuristics
#: Physical bounds of every sample (outside: an error naming the first row).
FREQ_SAMPLE_RANGE_HZ = (100.0, 1e5)  # n = 2 mode of any HRG: a few 100 Hz .. tens of kHz
FREQ_JUMP_FRACTION = 0.05  # 84 ppm/°C over 300 °C is 2.5 %: more than 5 % off is a glitch
RATE_MAX_DPH = 3.6e6  # 1000 °/s: beyond any rate table and the rebalance loop of an HRG
TEMPERATURE_RANGE_C = (-200.0, 500.0)  # chambers, housings, resonators
#: Rows per block of the sample-rate check that runs through the whole file.
RATE_CHECK_ROWS = 1000
_BOUNDS: dict[str, tuple[float, float, str]] = {
    "freq_hz": (*FREQ_SAMPLE_RANGE_HZ, "Hz"),
    "rate_dph": (-RATE_MAX_DPH, RATE_MAX_DPH, "°/h"),
    "bias_dph": (-RATE_MAX_DPH, RATE_MAX_DPH, "°/h"),
    "chamber_c": (*TEMPERATURE_RANGE_C, "°C"),
    "housing_c": (*TEMPERATURE_RANGE_C, "°C"),
    "resonator_c": (*TEMPERATURE_RANGE_C, "°C"),
}


@dataclass(frozen=True)
class ValidationReport:
    """Outcome of validating a recording.

    Parameters
    ----------
    ok
        True when there is no problem.
    problems
        The problems found, in the order of the checks.
    gaps
        Gaps found (at most :data:`MAX_LISTED_GAPS` listed), whatever the policy.
    n_gaps
        Number of gaps found.
    rows
        Rows checked.
    source
        File the recording came from.
    measured_sample_rate_hz
        Reciprocal of the median time step of the first :data:`HEURISTIC_ROWS`
        rows, None with fewer than 2 rows. [Hz]
    gap_policy
        ``"error"``, ``"split"`` or ``"ignore"``.
    """

    ok: bool
    problems: tuple[Problem, ...]
    gaps: tuple[Gap, ...]
    n_gaps: int
    rows: int
    source: str | None
    measured_sample_rate_hz: float | None
    gap_policy: str = "error"

    @property
    def message(self) -> str:
        """All problems as one message that names the file ("" when ok)."""
        return problems_message(self.source, self.problems)

    def raise_for_problems(self) -> None:
        """Raise :class:`~hrgtc.errors.RecordingError` with :attr:`message` unless ok."""
        if self.problems:
            raise RecordingError(self.message)

    def summary(self) -> str:
        """Human-readable text (does not print)."""
        where = self.source or "recording"
        lines = [f"validation of {where}: {'ok' if self.ok else 'FAILED'} ({self.rows} rows)"]
        if self.measured_sample_rate_hz is not None:
            lines.append(f"  measured sample rate: {self.measured_sample_rate_hz:.6g} Hz")
        lines += [f"  problem: {p.message}" for p in self.problems]
        if self.n_gaps:
            lines.append(f"  gaps: {self.n_gaps} (policy {self.gap_policy})")
            lines += [
                f"    row {g.row}: {g.duration_s:.6g} s without samples after t = "
                f"{g.start_time_s:.6g} s"
                for g in self.gaps[:10]
            ]
            if self.n_gaps > 10:
                lines.append(f"    ... {self.n_gaps - 10} more")
        return "\n".join(lines)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types."""
        data = asdict(self)
        return {**data, "problems": list(data["problems"]), "gaps": list(data["gaps"])}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ValidationReport:
        """Inverse of :meth:`to_dict`."""
        problems = tuple(Problem.from_dict(p) for p in data["problems"])
        gaps = tuple(Gap.from_dict(g) for g in data["gaps"])
        return cls(**{**data, "problems": problems, "gaps": gaps})


def problems_message(source: str | None, problems: tuple[Problem, ...] | list[Problem]) -> str:
    """One message for ``problems`` that starts with the file name."""
    where = source or "recording"
    if not problems:
        return ""
    if len(problems) == 1:
        return f"{where}: {problems[0].message}"
    items = "\n".join(f"  - {p.message}" for p in problems)
    return f"{where}: {len(problems)} problems:\n{items}"


class RecordingValidator:
    """Validate a recording chunk by chunk, carrying state across chunks.

    Time continuity and row numbers run over the whole recording; the unit and
    sample-rate heuristics look at its first :data:`HEURISTIC_ROWS` rows.
    ``validate(recording)`` is "a new validator, one update, finish".

    Parameters
    ----------
    gaps
        ``"error"``: gaps are problems; ``"split"`` / ``"ignore"``: gaps are only
        listed (split the recording with :func:`split_at_gaps`).
    """

    def __init__(self, gaps: GapPolicy | str = "error",
                 freq_band_hz: tuple[float, float] | None = None,
                 freq_span_hz: tuple[float, float] | None = None) -> None:
        self.gaps = check_gap_policy(gaps)
        self.freq_band_hz = freq_band_hz
        self.freq_span_hz = freq_span_hz
        self._bounds = dict(_BOUNDS)
        if freq_band_hz is not None:
            self._bounds["freq_hz"] = (float(freq_band_hz[0]), float(freq_band_hz[1]), "Hz")
        self._out_of_bounds: dict[str, list[Any]] = {}  # column -> [row, value, count]
        self._freq_reference: float | None = None
        self._jump: list[Any] | None = None  # [row, value, count]
        self._steps = np.empty(0)
        self._steps_start = 0
        self._rate_change: tuple[int, float] | None = None
        self.rows = 0
        self.source: str | None = None
        self.metadata: Metadata | None = None
        self._missing: tuple[str, ...] = ()
        self._last_time: float | None = None
        self._not_finite: dict[str, list[Any]] = {}  # column -> [row, value, count]
        self._time_order: tuple[int, float, float] | None = None
        self._time_order_count = 0
        self._gaps: list[Gap] = []
        self._n_gaps = 0
        self._sample: dict[str, list[np.ndarray]] = {name: [] for name in REQUIRED_COLUMNS}
        self._sample_rows = 0
        self._heuristics: list[Problem] | None = None
        self.measured_sample_rate_hz: float | None = None

    # -- feeding -------------------------------------------------------------
    def update(self, chunk: Recording) -> None:
        """Check the next chunk (rows continue from the previous chunk)."""
        if self.metadata is None:
            self.metadata = chunk.metadata
            self.source = chunk.source
            self._missing = tuple(c for c in REQUIRED_COLUMNS if c not in chunk)
        offset, n = self.rows, len(chunk)
        freq_extremes = None
        for name in chunk.names:
            values = chunk[name]
            low, high, _ = self._bounds.get(name, (-np.inf, np.inf, ""))
            extremes = finite_extremes(values)
            if name == "freq_hz":
                freq_extremes = extremes
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
            if name in self._bounds:
                self._check_bounds(name, values, offset)
        if "freq_hz" in chunk and self._freq_reference is not None:
            self._check_jumps(chunk.freq_hz, offset, freq_extremes)
        if "time_s" in chunk and n:
            self._check_time(chunk.time_s, offset)
        if self._heuristics is None:
            self._collect_sample(chunk)
        self.rows += n

    def _check_bounds(self, name: str, values: np.ndarray, offset: int) -> None:
        low, high, _ = self._bounds[name]
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

    def _check_jumps(self, freq: np.ndarray, offset: int,
                     extremes: tuple[float, float] | None = None) -> None:
        """Frequencies too far from the run's median; ``extremes``: min and max of ``freq``."""
        reference = self._freq_reference
        band = FREQ_JUMP_FRACTION * reference * (1.0 - 1e-9)  # margin for rounding
        if extremes is not None and reference - band < extremes[0] and extremes[1] < (
                reference + band):
            return  # no sample near the limit, let alone beyond it
        with np.errstate(invalid="ignore"):
            bad = (np.abs(freq - reference) > FREQ_JUMP_FRACTION * reference) & np.isfinite(freq)
        if bad.any():
            if self._jump is None:
                first = int(np.argmax(bad))
                self._jump = [offset + first, float(freq[first]), int(bad.sum())]
            else:
                self._jump[2] += int(bad.sum())

    def _check_rate_throughout(self, step: np.ndarray, offset: int,
                               all_usable: bool = False) -> None:
        """Mean time step of each block of :data:`RATE_CHECK_ROWS` rows (gaps left out; none
        if ``all_usable``: every step known finite, positive and no gap)."""
        if self._rate_change is not None:
            return
        if self._steps.size:
            step = np.concatenate([self._steps, step])
            offset = self._steps_start
            all_usable = False
        blocks = step.size // RATE_CHECK_ROWS
        period = 1.0 / self.metadata.sample_rate_hz
        if blocks:  # every block at once: the mean step of its usable steps
            part = step[:blocks * RATE_CHECK_ROWS].reshape(blocks, RATE_CHECK_ROWS)
            if all_usable:
                counts = np.full(blocks, RATE_CHECK_ROWS)
                sums = part.sum(axis=1)
            else:
                with np.errstate(invalid="ignore"):
                    usable = np.isfinite(part) & (part > 0) & (part <= GAP_PERIODS * period)
                counts = usable.sum(axis=1)
                sums = np.where(usable, part, 0.0).sum(axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):
                measured = 1.0 / (sums / counts)
                # mostly gaps or disorder: left to those checks
                changed = (counts >= RATE_CHECK_ROWS // 2) & (
                    np.abs(measured * period - 1.0) > SAMPLE_RATE_TOLERANCE)
            if changed.any():
                k = int(np.argmax(changed))
                self._rate_change = (offset + k * RATE_CHECK_ROWS, float(measured[k]))
                self._steps = np.empty(0)
                return
        self._steps = step[blocks * RATE_CHECK_ROWS:].copy()
        self._steps_start = offset + blocks * RATE_CHECK_ROWS

    def _check_time(self, time: np.ndarray, offset: int) -> None:
        period = 1.0 / self.metadata.sample_rate_hz
        if self._last_time is not None:  # fast path: steps all positive and no gap
            step = np.empty_like(time)
            step[0] = time[0] - self._last_time
            np.subtract(time[1:], time[:-1], out=step[1:])
            extremes = finite_extremes(step)
            if extremes is not None and extremes[0] > 0.0 and (
                    extremes[1] <= GAP_PERIODS * period):
                self._last_time = float(time[-1])
                self._check_rate_throughout(step, offset, all_usable=True)
                return
        previous = np.empty_like(time)
        previous[0] = np.nan if self._last_time is None else self._last_time
        previous[1:] = time[:-1]
        self._last_time = float(time[-1])
        with np.errstate(invalid="ignore"):
            step = time - previous
            backwards = step <= 0
        if backwards.any():
            self._time_order_count += int(backwards.sum())
            if self._time_order is None:
                i = int(np.argmax(backwards))
                self._time_order = (offset + i, float(time[i]), float(previous[i]))
        with np.errstate(invalid="ignore"):
            long = np.flatnonzero((step > GAP_PERIODS * period) & np.isfinite(step))
        self._n_gaps += long.size
        self._check_rate_throughout(step, offset)
        room = MAX_LISTED_GAPS - len(self._gaps)
        self._gaps += [
            Gap(float(previous[i]), float(step[i]), offset + int(i)) for i in long[:room]
        ]

    def _collect_sample(self, chunk: Recording) -> None:
        take = min(len(chunk), HEURISTIC_ROWS - self._sample_rows)
        for name in REQUIRED_COLUMNS:
            if name in chunk:
                self._sample[name].append(np.array(chunk[name][:take]))
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
            problems.append(
                Problem(
                    "missing_column",
                    f"required column(s) '{columns}' missing; map your names with "
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
        unit_problem = any(p.kind == "freq_unit" for p in self._heuristics or [])
        for name, (row, value, count) in self._out_of_bounds.items():
            if name == "freq_hz" and (self._heuristics is None or unit_problem):
                continue  # the unit heuristic (e.g. "looks like kHz") says it better
            problems.append(self._bounds_problem(name, row, value, count))
        if self._jump is not None:
            row, value, count = self._jump
            problems.append(Problem(
                "implausible",
                f"column 'freq_hz', row {row}: {value:.6g} Hz is more than "
                f"{FREQ_JUMP_FRACTION:.0%} away from the run's median "
                f"{self._freq_reference:.6g} Hz (a resonator moves ≈ 0.01 %/°C; first of "
                f"{count} such rows): a glitch or two files joined; remove those rows",
                column="freq_hz", row=row, value=f"{value:.6g}", count=count))
        if self._rate_change is not None:
            row, measured = self._rate_change
            nominal = self.metadata.sample_rate_hz
            problems.append(Problem(
                "sample_rate",
                f"column 'time_s', rows {row} to {row + RATE_CHECK_ROWS - 1}: the time step "
                f"means {measured:.6g} Hz but the metadata (and the start of the file) say "
                f"{nominal:g} Hz; the sample rate changes within the file: split it at row "
                f"{row} and process the parts separately (or resample)",
                column="time_s", row=row, value=f"{measured:.6g}"))
        if self._time_order is not None:
            row, now, before = self._time_order
            what = "a duplicate time" if now == before else "a step back in time"
            problems.append(
                Problem(
                    "time_order",
                    f"column 'time_s', row {row}: {now!r} s after {before!r} s is {what} "
                    f"(time must increase strictly; {self._time_order_count} bad step(s)); "
                    "sort the file by time and drop duplicate rows",
                    column="time_s",
                    row=row,
                    value=repr(now),
                    count=self._time_order_count,
                )
            )
        if self._n_gaps and self.gaps == "error":
            first = self._gaps[0]
            period = 1.0 / self.metadata.sample_rate_hz
            problems.append(
                Problem(
                    "gap",
                    f"column 'time_s', row {first.row}: {self._n_gaps} gap(s) longer than "
                    f"{GAP_PERIODS:g} sample periods ({GAP_PERIODS * period:.6g} s), the first "
                    f"{first.duration_s:.6g} s after t = {first.start_time_s:.6g} s; "
                    "pass --gaps split to process the segments separately (or --gaps ignore)",
                    column="time_s",
                    row=first.row,
                    value=f"{first.duration_s:.6g}",
                    count=self._n_gaps,
                )
            )
        problems += self._heuristics or []
        return problems

    def _bounds_problem(self, name: str, row: int, value: float, count: int) -> Problem:
        low, high, unit = self._bounds[name]
        if name == "freq_hz" and self.freq_band_hz is not None:
            span = self.freq_span_hz or self.freq_band_hz
            why = (f"far outside the model's calibrated span {span[0]:.6g} to {span[1]:.6g} Hz "
                   f"(more than the frequency of 100 °C beyond it: {low:.6g} to {high:.6g} Hz)")
            fix = ("a glitch, another unit's recording, or the wrong column? remove the row or "
                   "check --col freq_hz=... and --freq-unit")
        elif name == "freq_hz":
            why = (f"outside {low:g} to {high:g} Hz, where the resonator frequency of any HRG "
                   "lies")
            fix = "a glitch or the wrong column: remove the row or check --col/--freq-unit"
        elif name in ("rate_dph", "bias_dph"):
            why = f"beyond ±{high:g} °/h (1000 °/s), more than any HRG measures"
            fix = "a glitch or the wrong column: remove the row or check --col/--rate-unit"
        else:
            why = f"outside {low:g} to {high:g} °C"
            fix = "a glitch or not a temperature in °C: remove the row or check the mapping"
        return Problem(
            "implausible",
            f"column '{name}', row {row}: {value:.6g} {unit} is {why} (first of {count} such "
            f"rows); {fix}",
            column=name, row=row, value=f"{value:.6g}", count=count)

    def raise_for_problems(self) -> None:
        """Raise :class:`~hrgtc.errors.RecordingError` if a problem was found so far."""
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
            gaps=tuple(self._gaps),
            n_gaps=self._n_gaps,
            rows=self.rows,
            source=self.source,
            measured_sample_rate_hz=self.measured_sample_rate_hz,
            gap_policy=self.gaps,
        )

    # -- heuristics ----------------------------------------------------------
    def _run_heuristics(self) -> None:
        sample = {name: np.concatenate(parts) for name, parts in self._sample.items() if parts}
        self._sample = {}
        problems: list[Problem] = []
        if "time_s" in sample and self.metadata is not None:
            self.measured_sample_rate_hz = measured_sample_rate(sample["time_s"])
            problem = _check_sample_rate(self.metadata.sample_rate_hz, self.measured_sample_rate_hz)
            if problem is None and self.metadata.extra.get("sample_rate_inferred"):
                problem = _check_time_unit(self.measured_sample_rate_hz, sample["time_s"])
            if problem:
                problems.append(problem)
        if "freq_hz" in sample:
            problem = _check_freq_unit(sample["freq_hz"])
            if problem:
                problems.append(problem)
            else:
                finite = sample["freq_hz"][np.isfinite(sample["freq_hz"])]
                if finite.size:
                    self._freq_reference = float(np.median(finite))
                    self._check_jumps(sample["freq_hz"], 0)
        if "rate_dph" in sample and self.metadata is not None:
            problem = _check_rate_unit(sample["rate_dph"], self.metadata.input_rate_dph,
                                       self.metadata.sample_rate_hz)
            if problem:
                problems.append(problem)
        self._heuristics = problems


def validate(
    recording: Recording, gaps: GapPolicy | str = "error", *, raise_errors: bool = True,
    freq_band_hz: tuple[float, float] | None = None,
    freq_span_hz: tuple[float, float] | None = None,
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
        Raise :class:`~hrgtc.errors.RecordingError` on a problem (default) rather
        than return a report with ``ok=False``.
    freq_band_hz, freq_span_hz
        Plausible frequencies given a model (every sample must lie in the band;
        without a model :data:`FREQ_SAMPLE_RANGE_HZ`) and its calibrated span.

    Returns
    -------
    ValidationReport

    Raises
    ------
    RecordingError
        Message names the file, column, first bad row, the bad value and the fix.
    """
    validator = RecordingValidator(gaps, freq_band_hz, freq_span_hz)
    validator.update(recording)
    report = validator.finish()
    if raise_errors:
        report.raise_for_problems()
    return report
