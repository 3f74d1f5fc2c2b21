"""The single checks of a recording: the :class:`Problem` they report, the :class:`ValidationReport`
of them all, and the unit heuristics.

:mod:`hrgtc.recording.validation` runs them (see its docstring for the rules);
they live here so that each stays a small function of arrays: the measured
sample rate, the time unit implied by it, the frequency unit from the median,
and the rate unit from the median magnitude and the noise of 1 s block means.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import GapWarning, InputError, RecordingError
from hrgtc.core.records import Count
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.recording.gaps import Gap, GapPolicy

SAMPLE_RATE_TOLERANCE = 0.01  # relative disagreement of measured and nominal rate
KHZ_BELOW_HZ = 100.0
FREQ_MAX_HZ = 1e6
RATE_LEVEL_DPH = 1.0
RATE_NOISE_DPH = 1e-3
RATE_TABLE_DPH = 3600.0
DEG_PER_RAD_X3600 = 180.0 / math.pi * 3600.0  # °/h per rad/s
#: Scale of 1 s block means below which a rate column is not in °/h (see validation's docstring).
RATE_BLOCK_NOISE_DPH = 1e-2
#: Below this inferred sample rate the time column is suspected to be in milliseconds.
SLOW_SAMPLE_RATE_HZ = 0.5

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
    "input_rate_dph": (-RATE_MAX_DPH, RATE_MAX_DPH, "°/h"),
    "temperature_c": (*TEMPERATURE_RANGE_C, "°C"),
    "chamber_c": (*TEMPERATURE_RANGE_C, "°C"),
    "housing_c": (*TEMPERATURE_RANGE_C, "°C"),
    "resonator_c": (*TEMPERATURE_RANGE_C, "°C"),
}


@dataclass(frozen=True)
class Problem(records.Written):
    """One way in which a recording breaks the contract.

    Parameters
    ----------
    kind
        One of ``"empty"``, ``"missing_column"``, ``"not_finite"``, ``"time_order"``,
        ``"gap"``, ``"sample_rate"``, ``"freq_unit"``, ``"rate_unit"``, ``"time_unit"``,
        ``"swapped_columns"``,
        ``"implausible"``.
    message
        Full sentence naming column, row, value and the fix.
    column
        Column concerned, if any.
    row
        First bad row (0 = first data row), if any.
    value
        The bad value as text, if any.
    count
        Number of rows (or gaps) with this problem found.
    """

    kind: str
    message: str
    column: str | None = None
    row: Count | None = None
    value: str | None = None
    count: Count = 1


@dataclass(frozen=True)
class ValidationReport(records.Written):
    """Outcome of validating a recording.

    Parameters
    ----------
    ok
        True when there is no problem.
    problems
        The problems found, in the order of the checks.
    gaps
        Gaps found (at most ``MAX_LISTED_GAPS`` listed), whatever the policy.
    n_gaps
        Number of gaps found.
    rows
        Rows checked.
    source
        File the recording came from.
    measured_sample_rate_hz
        Reciprocal of the median time step of the first ``HEURISTIC_ROWS``
        rows, None with fewer than 2 rows. [Hz]
    gap_policy
        ``"error"``, ``"split"`` or ``"ignore"``.
    n_dropouts, dropout_s
        Gaps no longer than ``dropout_s`` (bridged and counted whatever the policy) and
        that limit. [s]
    duty_cycled
        The gaps are a duty-cycled logger's: bridged by default (policy ``"error"``).
    """

    ok: bool
    problems: tuple[Problem, ...]
    gaps: tuple[Gap, ...]
    n_gaps: Count
    rows: Count
    source: str | None
    measured_sample_rate_hz: float | None
    gap_policy: GapPolicy = "error"
    n_dropouts: Count = 0
    dropout_s: float = 0.0
    duty_cycled: bool = False

    @property
    def message(self) -> str:
        """All problems as one message that names the file ("" when ok)."""
        return problems_message(self.source, self.problems)

    def raise_for_problems(self) -> None:
        """Raise :class:`~hrgtc.core.errors.RecordingError` with :attr:`message` unless ok."""
        if self.problems:
            raise RecordingError(self.message)

    def warn_bridged(self) -> None:
        """Say, once, that short dropouts or a duty-cycled logger's gaps were bridged by
        default (the result goes on; the user is told what was mended)."""
        if self.n_dropouts and not self.problems:
            warnings.warn(GapWarning(
                f"{self.source or 'recording'}: {self.n_dropouts} dropout(s) no longer than "
                f"{self.dropout_s:g} s (--dropout-s) bridged: the filters carry across each "
                "with its duration"), stacklevel=3)
        if self.duty_cycled and self.gap_policy == "error" and not self.problems:
            warnings.warn(GapWarning(
                f"{self.source or 'recording'}: a duty-cycled logger (bursts much shorter "
                f"than their period, {self.n_gaps - self.n_dropouts} gaps): the filters carry "
                "across each gap with its duration (--gaps bridge, the default for such a "
                "logger: after a gap the df/dt filter reads the gap's mean rate); pass --gaps "
                "split only if the temperature does not move in a straight line across the "
                "gaps (a unit powered off between bursts)"), stacklevel=3)

    def summary(self) -> Summary:
        """Rows, measured rate, problems, dropouts and gaps (the first ten); its text the
        report ``hrgtc info`` prints."""
        where = escape(self.source or "recording")
        figures = [Figure("ok", "validation", "ok" if self.ok else "FAILED"),
                   Figure("rows", "rows", self.rows)]
        lines = [f"validation of {where}: {{ok}} ({{rows}} rows)"]
        if self.measured_sample_rate_hz is not None:
            figures.append(Figure("measured_sample_rate_hz", "measured sample rate",
                                  self.measured_sample_rate_hz, "Hz",
                                  definition="1 / the median time step."))
            lines.append("  measured sample rate: {measured_sample_rate_hz:.6g} Hz")
        for p in self.problems:  # a message of several lines stays several lines
            first, *rest = escape(p.message).split("\n")
            lines += [f"  problem: {first}", *rest]
        gaps: list[Figure] = []
        if self.n_dropouts:
            figures.append(Figure("n_dropouts", "dropouts", self.n_dropouts,
                                  definition=f"Gaps no longer than {self.dropout_s:g} s, "
                                  "bridged."))
            lines.append("  dropouts: {n_dropouts} gap(s) no longer than "
                         f"{self.dropout_s:g} s, bridged (they change no result)")
        if self.n_gaps:
            longer = self.n_gaps - self.n_dropouts
            figures.append(Figure("n_gaps", "gaps", self.n_gaps,
                                  definition="Time steps longer than a gap."))
            if self.duty_cycled and self.gap_policy == "error":
                lines.append("  a duty-cycled logger (bursts much shorter than their period): "
                             "its gaps are bridged, the filters carry across each with its "
                             "duration (--gaps split restarts them)")
            lines.append("  gaps: {n_gaps} " + (
                "(all dropouts)" if not longer else
                f"(policy {self.gap_policy} for the {longer} longer than {self.dropout_s:g} s)"
                if self.n_dropouts else f"(policy {self.gap_policy})"))
            for k, g in enumerate(self.gaps[:10]):
                gaps += [Figure(f"gaps[{k}].row", f"gap {k + 1}: row", g.row, row=str(k),
                                column="row"),
                         Figure(f"gaps[{k}].duration_s", f"gap {k + 1}: duration",
                                g.duration_s, "s", row=str(k), column="duration"),
                         Figure(f"gaps[{k}].start_time_s", f"gap {k + 1}: after t",
                                g.start_time_s, "s", row=str(k), column="after t")]
                lines.append(f"    row {{gaps[{k}].row}}: {{gaps[{k}].duration_s:.6g}} s "
                             f"without samples after t = {{gaps[{k}].start_time_s:.6g}} s")
            if self.n_gaps > 10:
                lines.append(f"    ... {self.n_gaps - 10} more")
        return Summary(f"validation of {self.source or 'recording'}",
                       (("validation", tuple(figures)), ("gaps", tuple(gaps))),
                       tuple(p.message for p in self.problems), tuple(lines))


def problems_message(source: str | None, problems: tuple[Problem, ...] | list[Problem]) -> str:
    """One message for ``problems`` that starts with the file name."""
    where = source or "recording"
    if not problems:
        return ""
    if len(problems) == 1:
        return f"{where}: {problems[0].message}"
    items = "\n".join(f"  - {p.message}" for p in problems)
    return f"{where}: {len(problems)} problems:\n{items}"


def finite_extremes(values: np.ndarray) -> tuple[float, float] | None:
    """Smallest and largest value when all are finite, else None (two reductions, no copy).

    The fast path of validation: a NaN makes both NaN, an infinity shows as one.
    """
    if not values.size:
        return None
    low, high = float(np.min(values)), float(np.max(values))
    if not (math.isfinite(low) and math.isfinite(high)):
        return None
    return low, high


def measured_sample_rate(time_s: np.ndarray) -> float | None:
    """Reciprocal of the median positive finite time step, None if there is none.

    Parameters
    ----------
    time_s
        Sample times. [s]

    Returns
    -------
    float or None
        Sample rate. [Hz]
    """
    step = np.diff(np.asarray(time_s, dtype=np.float64))
    step = step[np.isfinite(step) & (step > 0)]
    if step.size == 0:
        return None
    return float(1.0 / np.median(step))


def _check_sample_rate(nominal_hz: float, measured_hz: float | None) -> Problem | None:
    if measured_hz is None or abs(measured_hz / nominal_hz - 1.0) <= SAMPLE_RATE_TOLERANCE:
        return None
    fix = (f"every step says so, the rate does not change within the file: fix the metadata "
           f"(--rate-hz {measured_hz:.6g})")
    wrong_rate = f"or the metadata's rate is wrong and the steps are right: pass --rate-hz " \
        f"{measured_hz:.6g}"
    for factor, unit, name in ((1000.0, "ms", "milliseconds"), (1e6, "us", "microseconds")):
        if abs(measured_hz * factor / nominal_hz - 1.0) <= 0.05:
            fix = (f"either the time column is in {name} (pass --time-unit {unit}: every "
                   f"duration then shrinks {factor:g} times) {wrong_rate}")
            break
    else:
        if abs(measured_hz / 1000.0 / nominal_hz - 1.0) <= 0.05:
            fix = ("the steps are 1000 times shorter than the metadata's period: if you passed "
                   f"--time-unit ms, the time column is already in seconds (drop it); "
                   f"{wrong_rate}")
    return Problem(
        "sample_rate",
        f"column 'time_s': the median time step {1.0 / measured_hz:.6g} s means "
        f"{measured_hz:.6g} Hz but the metadata says sample_rate_hz = {nominal_hz:g}; {fix}",
        column="time_s",
        value=f"{measured_hz:.6g}",
    )


def _check_time_unit(measured_hz: float | None, time_s: np.ndarray) -> Problem | None:
    """A sample rate inferred below :data:`SLOW_SAMPLE_RATE_HZ`: time in ms, most likely."""
    if measured_hz is None or measured_hz >= SLOW_SAMPLE_RATE_HZ:
        return None
    hours = (float(time_s[-1]) - float(time_s[0])) / 3600.0
    return Problem(
        "time_unit",
        f"column 'time_s': the time steps ({1.0 / measured_hz:.6g}) taken as seconds mean "
        f"{measured_hz:.6g} Hz ({hours:.4g} h in the first {time_s.size} rows), slower than "
        f"any gyro logger; if the time column is in milliseconds pass --time-unit ms "
        f"(that is {measured_hz * 1000.0:.6g} Hz); if the rate really is {measured_hz:.6g} Hz "
        f"confirm it with --rate-hz {measured_hz:.6g}",
        column="time_s", value=f"{measured_hz:.6g}")


def _block_noise(rate: np.ndarray, sample_rate_hz: float) -> float:
    """Robust scale of 1 s block means (MAD of their differences / √2): any sample rate."""
    rows = max(1, round(sample_rate_hz))
    blocks = rate.size // rows
    if blocks < 3:
        return math.nan
    means = rate[: blocks * rows].reshape(blocks, rows).mean(axis=1)
    step = np.diff(means)
    return float(1.4826 * np.median(np.abs(step - np.median(step))) / math.sqrt(2.0))


def _check_freq_unit(freq: np.ndarray, name: str = "freq_hz") -> Problem | None:
    freq = freq[np.isfinite(freq)]
    if freq.size == 0:
        return None
    median = float(np.median(freq))
    if 0 < median < KHZ_BELOW_HZ and KHZ_BELOW_HZ <= median * 1000.0 <= FREQ_MAX_HZ:
        message = f"{name} looks like kHz (median {median:.6g}); pass --freq-unit kHz"
    elif median <= 0 or median < KHZ_BELOW_HZ or median > FREQ_MAX_HZ:
        message = (
            f"{name} is implausible (median {median:.6g} Hz; the resonator frequency of an "
            f"HRG is a few hundred Hz to a few tens of kHz); check the column mapping "
            f"(--col {name}=<your column>) and the unit (--freq-unit Hz|kHz); a gyro without "
            "a frequency output: --thermometer sensor"
        )
    else:
        return None
    return Problem("freq_unit", message, column=name, value=f"{median:.6g}")


def _check_swapped(freq: np.ndarray, rate: np.ndarray, freq_name: str = "freq_hz",
                   rate_name: str = "rate_dph") -> Problem | None:
    """A frequency column whose values are a rate's and a rate column that holds a frequency.

    The rate column looks like a resonator frequency when its median lies in
    :data:`FREQ_SAMPLE_RANGE_HZ` and it hardly moves (median absolute deviation
    below 1 % of the median: a resonator moves ≈ 0.01 %/°C).
    """
    freq, rate = freq[np.isfinite(freq)], rate[np.isfinite(rate)]
    if freq.size == 0 or rate.size == 0:
        return None
    median_rate = float(np.median(rate))
    spread = float(np.median(np.abs(rate - median_rate)))
    in_band = FREQ_SAMPLE_RANGE_HZ[0] <= median_rate <= FREQ_SAMPLE_RANGE_HZ[1]
    median_freq = float(np.median(freq))
    if not in_band or spread > 0.01 * median_rate or FREQ_SAMPLE_RANGE_HZ[0] <= median_freq:
        return None
    return Problem(
        "swapped_columns",
        f"columns '{freq_name}' (median {median_freq:.6g}) and '{rate_name}' (median "
        f"{median_rate:.6g}, steady like a resonator frequency) look swapped; fix the header "
        f"or map them: --col {freq_name}={rate_name} --col {rate_name}={freq_name}",
        column=freq_name, value=f"{median_freq:.6g}")


def _check_rate_unit(rate: np.ndarray, input_rate_dph: float,
                     sample_rate_hz: float = 1.0, name: str = "rate_dph") -> Problem | None:
    rate = rate[np.isfinite(rate)]
    if rate.size < 2:
        return None
    with np.errstate(over="ignore", invalid="ignore"):  # 1e300 is reported by the bounds
        level = float(np.median(np.abs(rate)))
        noise = float(np.std(np.diff(rate)) / math.sqrt(2.0))
        block_noise = _block_noise(rate, sample_rate_hz)
    quiet_and_small = level < RATE_LEVEL_DPH and (
        noise < RATE_NOISE_DPH or 0.0 < block_noise < RATE_BLOCK_NOISE_DPH)
    scaled_input = False
    if abs(input_rate_dph) >= RATE_TABLE_DPH:
        ratio = float(np.median(rate)) / input_rate_dph
        scaled_input = any(0.5 <= ratio * factor <= 2.0 for factor in (3600.0, DEG_PER_RAD_X3600))
    if not (quiet_and_small or scaled_input):
        return None
    options = ["--rate-unit dps (°/s)", "--rate-unit radps (rad/s)"]
    if level * 3600.0 < 0.5:
        options.reverse()  # below 0.5 °/h even if it were °/s: rad/s is more likely
    return Problem(
        "rate_unit",
        f"{name} looks like °/s or rad/s, not °/h (median |rate| {level:.3g}, noise of "
        f"1 s means {block_noise:.3g}; a gyro recorded in °/h reads ≳ {RATE_LEVEL_DPH:g} °/h "
        f"with ≳ {RATE_BLOCK_NOISE_DPH:g} °/h noise in 1 s means); pass "
        f"{' or '.join(options)}",
        column=name,
        value=f"{level:.3g}",
    )


#: What ``freq_hz`` holds: the resonator frequency [Hz] (default) or, for a gyro without a
#: frequency output, a temperature sensor's reading [°C] (``--thermometer sensor``).
THERMOMETERS: tuple[str, ...] = ("resonator", "sensor")


def check_thermometer(thermometer: str) -> str:
    """Return ``thermometer`` if it is one of :data:`THERMOMETERS`, else raise InputError."""
    if thermometer not in THERMOMETERS:
        raise InputError(
            f"thermometer must be one of {list(THERMOMETERS)}, got {thermometer!r}; "
            "'sensor' for a gyro without a frequency output (its temperature_c column)"
        )
    return thermometer
