"""Spikes: single samples that no gyro, resonator or thermometer can produce.

IMU logs (PX4 or ArduPilot style) carry the odd garbage sample: a NaN where a
packet was lost, a rate of 10^30, a temperature of -273 °C, a resonator
frequency 20 % away from the rest of the run. A *spike* here is a row with

* a value that is not finite (NaN or infinite) in any column, or
* a value outside the physical bounds of its column (those of the validation:
  :data:`~hrgtc.recording.checks.FREQ_SAMPLE_RANGE_HZ`, ±1000 °/s for rates,
  :data:`~hrgtc.recording.checks.TEMPERATURE_RANGE_C` for temperatures; for the
  sensor thermometer, ``freq_hz`` in the temperature range), or
* a resonator frequency more than :data:`~hrgtc.recording.checks.FREQ_JUMP_FRACTION`
  away from the median of the first rows of its column.

``spikes="error"`` (the default) leaves them to the validation, whose error
names the file, column, row and value; ``spikes="drop"`` removes those rows
(:class:`SpikeFilter`) and says how many went, with the first of them, in a
:class:`~hrgtc.core.errors.SpikeWarning`.

Plausible values can still be spikes: a MEMS logger's single sample at −0.10 rad/s
in a stream at −0.065 ± 0.001 rad/s. :func:`find_spikes` is the robust,
time-windowed test for those (``spike_filter="drop"`` removes their rows and
counts them, ``"flag"`` keeps every row and marks them in a ``spike`` column, see
:class:`RobustSpikeFilter`). A sample is a spike when it stands out from *both*
neighbours by more than the threshold and from their mean by more than the
threshold: a single-sample excursion, not a step (a step is motion or a change of
state, left to the motion detector). The threshold is

    max(k · σ_MAD, m · LSB)

with σ_MAD = 1.4826 · MAD / sqrt(1.5) of the second differences (their MAD about
0: they carry no level and no linear trend)
``x[i] − (x[i−1] + x[i+1]) / 2`` over a window of ``window_s`` seconds (never across
a gap, a step of more than 2 median periods; a window with fewer than
:data:`MIN_WINDOW_SAMPLES` samples uses its segment's), and LSB the channel's
resolution (:func:`hrgtc.recording.resolution.resolution`): a quantised or
pulse-type stream, whose MAD is 0, keeps its pulses, and nothing symmetric about the
mean is removed, so the mean is not biased. With k = 8, a Gaussian stream of 10^8
samples loses none in expectation.

A rate excursion where the logged accelerometer moves across the sample (its samples
on either side disagree, :func:`moving_across`) is not a spike: it is a rotation shorter
than the sample period, caught by one sample (a unit turned by hand, logged at 1 Hz),
and the motion detector marks it (docs/real-loggers/motion.md).
"""

from __future__ import annotations

import os
import warnings
from collections import OrderedDict
from collections.abc import Mapping
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError, SpikeWarning
from hrgtc.core.forked import share_memo
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.recording.axes import axis_names, base_name
from hrgtc.recording.checks import _BOUNDS, FREQ_JUMP_FRACTION, TEMPERATURE_RANGE_C
from hrgtc.recording.gaps import GAP_PERIODS, GAP_TOLERANCE
from hrgtc.recording.motion import ACCEL_COLUMNS
from hrgtc.recording.resolution import resolution
from hrgtc.settings.reading import ReadSettings

SPIKE_POLICIES: tuple[str, ...] = ("error", "drop")
#: What the robust filter does with the spikes it finds.
SPIKE_FILTERS: tuple[str, ...] = ("off", "drop", "flag")
#: Defaults of the robust filter: k (× σ_MAD), m (× LSB), window [s].
SPIKE_K = ReadSettings.spike_k
SPIKE_LSB = ReadSettings.spike_lsb
SPIKE_WINDOW_S = ReadSettings.spike_window_s
#: Fewest samples a window needs for its own σ_MAD (else its segment's).
MIN_WINDOW_SAMPLES = 16
#: Rows the resolution (LSB) of a channel is taken from (its first ones).
RESOLUTION_ROWS = 100_000
#: Name of the column that marks spikes with ``spike_filter="flag"``.
SPIKE_COLUMN = "spike"
_MAD_TO_SIGMA = 1.482602218505602  # 1 / Φ^-1(3/4): MAD of a Gaussian -> its σ
_SECOND_DIFF = 1.224744871391589  # sqrt(1.5): σ of x[i] − (x[i−1] + x[i+1]) / 2 in σ of x

__all__ = ["SPIKE_FILTERS", "SPIKE_POLICIES", "RobustSpikeFilter", "SpikeFilter",
           "check_spike_policy", "find_spikes", "moving_across"]


def check_spike_policy(spikes: str) -> str:
    """Return ``spikes`` if it is one of :data:`SPIKE_POLICIES`, else raise InputError."""
    if spikes not in SPIKE_POLICIES:
        raise InputError(f"spikes must be one of {list(SPIKE_POLICIES)}, got {spikes!r}; "
                         "'drop' removes the rows of implausible samples")
    return spikes


class SpikeFilter:
    """Drop the rows of spikes from consecutive pieces of a recording, counting them.

    Parameters
    ----------
    thermometer
        ``"resonator"`` or ``"sensor"`` (``freq_hz`` then holds a temperature [°C]).
    source
        The file, for the warning.

    Attributes
    ----------
    dropped
        Rows dropped so far.
    first
        ``(column, row, value)`` of the first spike (row in the file's data rows,
        from 0), None without any.
    """

    def __init__(self, thermometer: str = ReadSettings.thermometer,
                 source: str | None = None) -> None:
        self.sensor = thermometer == "sensor"
        self.source = source
        self.dropped = 0
        self.first: tuple[str, int, float] | None = None
        self._reference: dict[str, float] = {}
        self._axes: tuple[str, ...] = ()
        #: The temperature is a raw count not mapped to °C (--temp-unit count alone, or a
        #: --temp-ref log mapping it later): it has no °C bounds to be judged by here.
        self.counts = False

    def _bounds(self, name: str) -> tuple[float, float] | None:
        base = base_name(name, self._axes)
        if self.counts and (base == "temperature_c" or (base == "freq_hz" and self.sensor)):
            return None
        if base == "freq_hz" and self.sensor:
            return TEMPERATURE_RANGE_C
        bounds = _BOUNDS.get(base)
        return None if bounds is None else (bounds[0], bounds[1])

    def _bad(self, name: str, values: np.ndarray) -> np.ndarray:
        bad = ~np.isfinite(values)
        bounds = self._bounds(name)
        with np.errstate(invalid="ignore"):
            if bounds is not None:
                bad |= (values < bounds[0]) | (values > bounds[1])
            if base_name(name, self._axes) == "freq_hz" and not self.sensor:
                if name not in self._reference and (~bad).any():
                    self._reference[name] = float(np.median(values[~bad]))
                reference = self._reference.get(name)
                if reference is not None:
                    bad |= np.abs(values - reference) > FREQ_JUMP_FRACTION * reference
        return bad

    def drop(self, columns: Mapping[str, np.ndarray], row_offset: int) -> dict[str, np.ndarray]:
        """``columns`` without the rows of spikes (the same arrays when there is none).

        Parameters
        ----------
        columns
            Float64 columns in the contract's names and units.
        row_offset
            File row of the first row of ``columns``.
        """
        keep: np.ndarray | None = None
        first: tuple[str, int, float] | None = None
        self._axes = axis_names(columns)
        for name, values in columns.items():
            bad = self._bad(name, values)
            if bad.any():
                i = int(np.argmax(bad))
                if first is None or i < first[1]:
                    first = (name, i, float(values[i]))
                keep = ~bad if keep is None else keep & ~bad
        if keep is None or first is None:
            return dict(columns)
        if self.first is None:
            self.first = (first[0], row_offset + first[1], first[2])
        self.dropped += int(keep.size - np.count_nonzero(keep))
        return {name: values[keep] for name, values in columns.items()}

    def warn(self) -> None:
        """Issue a :class:`~hrgtc.core.errors.SpikeWarning` saying how many rows were dropped."""
        if not self.dropped or self.first is None:
            return
        name, row, value = self.first
        where = f"{self.source}: " if self.source else ""
        warnings.warn(
            f"{where}dropped {self.dropped} row(s) with spikes (--spikes drop); the first: "
            f"column '{name}', row {row}, value {value:.6g}",
            SpikeWarning, stacklevel=3)


# -- the robust, time-windowed filter -------------------------------------------------
# The loops are compiled (hrgtc.recording._spike_kernel, imported when first used: numba
# costs the import of a command that never filters); their numpy definition is kept in
# tests/spikes_reference.py and the masks are compared bit for bit.
def _channel_mask(which: str, time_s: np.ndarray, values: np.ndarray, k: float,
                  lsb_multiple: float, window_s: float, lsb: float | None) -> np.ndarray:
    """The compiled test ``which`` (``"spike"`` or ``"across"``) of one channel."""
    from hrgtc.recording import _spike_kernel as kernel

    x = np.ascontiguousarray(values, dtype=np.float64)
    t = np.ascontiguousarray(time_s, dtype=np.float64)
    if lsb is None:
        lsb = resolution(x[:RESOLUTION_ROWS])
    floor = lsb_multiple * float(lsb or 0.0)
    test = kernel.spike_mask if which == "spike" else kernel.across_mask
    rule = kernel.SpikeRule(float(k), floor, float(window_s), float(GAP_PERIODS),
                            1.0 + GAP_TOLERANCE, int(MIN_WINDOW_SAMPLES), float(_MAD_TO_SIGMA),
                            float(_SECOND_DIFF))
    return test(t, x, rule)


def moving_across(time_s: np.ndarray, values: np.ndarray, *, k: float = SPIKE_K,
                  lsb_multiple: float = SPIKE_LSB, window_s: float = SPIKE_WINDOW_S,
                  lsb: float | None = None) -> np.ndarray:
    """Samples across which a channel moves: a boolean mask, True where the samples on
    either side of it disagree, ``|x[i+1] − x[i−1]|`` or ``|x[i+2] − x[i−2]|`` beyond the
    threshold of :func:`find_spikes` (never across a gap; the sample itself is not used).

    An accelerometer that moves across a sample says the unit was being turned there: a
    single-sample rate excursion at that sample is a fast rotation caught by one sample
    (a handling pulse shorter than the sample period), not a spike. A glitch that hits
    every column of one row leaves the accelerometer's neighbours in agreement.
    """
    return _channel_mask("across", time_s, values, k, lsb_multiple, window_s, lsb)


def find_spikes(time_s: np.ndarray, values: np.ndarray, *, k: float = SPIKE_K,
                lsb_multiple: float = SPIKE_LSB, window_s: float = SPIKE_WINDOW_S,
                lsb: float | None = None) -> np.ndarray:
    """Single-sample spikes of a channel: a boolean mask, True at each spike.

    Parameters
    ----------
    time_s
        Time of each sample. [s]
    values
        The channel (any unit; NaN never a spike here: the validation names those).
    k
        Threshold in robust standard deviations σ_MAD of the window.
    lsb_multiple
        Threshold floor in steps of the channel's resolution (``m``).
    window_s
        Length of the windows σ_MAD is estimated on (cut at gaps). [s]
    lsb
        The channel's resolution; None: :func:`hrgtc.recording.resolution.resolution`
        of its first :data:`RESOLUTION_ROWS` values.

    Returns
    -------
    numpy.ndarray
        True where ``|x[i] − x[i±1]|`` and ``|x[i] − (x[i−1] + x[i+1]) / 2|`` all exceed
        ``max(k·σ_MAD, m·LSB)`` while ``|x[i+1] − x[i−1]|`` does not (the neighbours agree:
        one sample off a steady stream, not a stream in motion); at a segment's edge,
        against the next two samples.
    """
    return _channel_mask("spike", time_s, values, k, lsb_multiple, window_s, lsb)


#: The masks :func:`find_spikes` gave this process, by file piece: the drift fit reads a
#: run several times (the at-rest pass, the window passes of the model and of the housing
#: baseline) and each pass would test the same rows again. A piece is known by its file
#: (path, modification time, size), first file row, column, the filter's settings and a
#: fingerprint of its times and values (first, last, sum); the spikes' rows are kept,
#: the :data:`_MEMO_PIECES` most recent pieces (a few MB). A column's resolution (LSB),
#: taken from a file's first piece, is kept here too, keyed the same way.
_MEMO: OrderedDict[tuple[object, ...], np.ndarray] = OrderedDict()
_MEMO_PIECES = 4096


def _keep(key: tuple[object, ...], value: Any) -> None:
    """Keep ``value`` in :data:`_MEMO`, the oldest pieces forgotten beyond its size."""
    _MEMO[key] = value
    _MEMO.move_to_end(key)
    while len(_MEMO) > _MEMO_PIECES:
        _MEMO.popitem(last=False)


# a worker process's pieces come back to the command (hrgtc.core.forked)
share_memo(_MEMO, _keep)


def _file_identity(source: str | None) -> tuple[str, int, int] | None:
    """(path, mtime, size) of the file ``source`` (None for none or a stream)."""
    if not source:
        return None
    try:
        stat = os.stat(source)
    except (OSError, TypeError, ValueError):
        return None
    return os.path.realpath(source), stat.st_mtime_ns, stat.st_size


def _fingerprint(values: np.ndarray) -> bytes:
    """First, last value and sum of ``values`` as bytes (a NaN equals itself)."""
    if not len(values):
        return b""
    return np.array([values[0], values[-1], np.sum(values)], dtype=np.float64).tobytes()


def _filtered_columns(columns: Mapping[str, np.ndarray], axes: tuple[str, ...],
                      sensor: bool) -> list[str]:
    """The columns the robust filter tests: rates and the thermometer (not twice)."""
    names = []
    for name in columns:
        base = base_name(name, axes)
        if base == "rate_dph" or base == "temperature_c" or (base == "freq_hz" and not sensor):
            names.append(name)
    return names


class RobustSpikeFilter:
    """Find the single-sample spikes of consecutive pieces of a recording; drop or flag them.

    The rate columns and the thermometer (``freq_hz*``, or ``temperature_c*`` for the
    sensor thermometer) are tested with :func:`find_spikes`, each piece on its own
    (a piece's first and last samples by the edge rule).

    Parameters
    ----------
    mode
        ``"drop"`` (rows removed) or ``"flag"`` (rows kept, :data:`SPIKE_COLUMN` = 1.0).
    thermometer
        ``"resonator"`` or ``"sensor"``.
    source
        The file, for the warning.
    k, lsb_multiple, window_s
        See :func:`find_spikes`.

    Attributes
    ----------
    found
        Spikes found so far, by column.
    rows
        Rows with at least one spike so far.
    first
        ``(column, row, value)`` of the first spike (file row), None without any.
    """

    def __init__(self, mode: str = "drop", thermometer: str = ReadSettings.thermometer,
                 source: str | None = None, *, k: float = SPIKE_K,
                 lsb_multiple: float = SPIKE_LSB, window_s: float = SPIKE_WINDOW_S) -> None:
        check_spike_filter(mode)
        for name, value in (("k", k), ("lsb_multiple", lsb_multiple), ("window_s", window_s)):
            if not (isinstance(value, int | float) and np.isfinite(value) and value > 0):
                raise InputError(f"spike filter {name} must be a positive number, got {value!r}")
        self.mode = mode
        self.sensor = thermometer == "sensor"
        self.source = source
        self.k, self.lsb_multiple, self.window_s = float(k), float(lsb_multiple), float(window_s)
        self.found: dict[str, int] = {}
        self.counts = False  # True: temperature_c holds a raw count (no °C bounds)
        self.rows = 0
        #: Single-sample rate excursions not taken for spikes: the accelerometer moved
        #: across them (a rotation caught by one sample; the motion detector's business).
        self.in_motion = 0
        self.first: tuple[str, int, float] | None = None
        self._lsb: dict[str, float | None] = {}
        self._file = _file_identity(source)

    def apply(self, columns: Mapping[str, np.ndarray], row_offset: int) -> dict[str, np.ndarray]:
        """``columns`` without the rows of spikes (drop), or with a ``spike`` column (flag)."""
        out = dict(columns)
        if self.mode == "off" or "time_s" not in columns:
            return out
        axes = axis_names(columns)
        time_s = columns["time_s"]
        marked = np.zeros(len(time_s), dtype=bool)
        turning = self._turning(columns, time_s)
        for name in _filtered_columns(columns, axes, self.sensor):
            values = columns[name]
            if name not in self._lsb:  # the resolution of the first rows holds for the file
                self._lsb[name] = self._resolution(name, values, row_offset)
            mask = self._spikes(name, time_s, values, row_offset)
            if turning is not None and base_name(name, axes) == "rate_dph" and mask.any():
                self.in_motion += int(np.count_nonzero(mask & turning))
                mask &= ~turning  # a rotation caught by one sample: the motion detector's
            bounds = self._bounds(name, axes)
            if bounds is not None and mask.any():  # impossible values: --spikes says
                with np.errstate(invalid="ignore"):
                    mask &= (values >= bounds[0]) & (values <= bounds[1])
            if mask.any():
                count = int(np.count_nonzero(mask))
                self.found[name] = self.found.get(name, 0) + count
                i = int(np.argmax(mask))
                if self.first is None or (self.first[1] >= row_offset
                                          and row_offset + i < self.first[1]):
                    self.first = (name, row_offset + i, float(values[i]))
                marked |= mask
        self.rows += int(np.count_nonzero(marked))
        if self.mode == "flag":
            out[SPIKE_COLUMN] = marked.astype(np.float64)
            return out
        if not marked.any():
            return out
        keep = ~marked
        return {name: values[keep] for name, values in out.items()}

    def _resolution(self, name: str, values: np.ndarray, row_offset: int) -> float | None:
        """The resolution of a column's first rows, from :data:`_MEMO` when this process
        found it for the same piece of the same file (each pass over a file makes a new
        filter; the resolution scans and sorts :data:`RESOLUTION_ROWS` values)."""
        first = values[:RESOLUTION_ROWS]
        key = None
        if self._file is not None:
            key = ("resolution", self._file, row_offset, name, len(first), _fingerprint(first))
            if key in _MEMO:
                _MEMO.move_to_end(key)
                return _MEMO[key]  # type: ignore[return-value]
        lsb = resolution(first)
        if key is not None:
            _MEMO[key] = lsb  # type: ignore[assignment]
        return lsb

    def _spikes(self, name: str, time_s: np.ndarray, values: np.ndarray,
                row_offset: int) -> np.ndarray:
        """:func:`find_spikes` of one column of the piece at ``row_offset``, from
        :data:`_MEMO` when this process has tested the same piece already."""
        key = None
        if self._file is not None:
            key = (self._file, row_offset, name, len(values), self.k, self.lsb_multiple,
                   self.window_s, self._lsb[name], _fingerprint(time_s), _fingerprint(values))
            rows = _MEMO.get(key)
            if rows is not None:
                _MEMO.move_to_end(key)
                mask = np.zeros(len(values), dtype=bool)
                mask[rows] = True
                return mask
        mask = find_spikes(time_s, values, k=self.k, lsb_multiple=self.lsb_multiple,
                           window_s=self.window_s, lsb=self._lsb[name])
        if key is not None:
            _keep(key, np.flatnonzero(mask))
        return mask

    def _turning(self, columns: Mapping[str, np.ndarray], time_s: np.ndarray
                 ) -> np.ndarray | None:
        """Rows across which an accelerometer column moves (:func:`moving_across`); None
        without accelerometer columns."""
        names = [c for c in ACCEL_COLUMNS if c in columns]
        if not names:
            return None
        turning = np.zeros(len(time_s), dtype=bool)
        for name in names:
            values = columns[name]
            if name not in self._lsb:
                self._lsb[name] = resolution(values[:RESOLUTION_ROWS])
            turning |= moving_across(time_s, values, k=self.k, lsb_multiple=self.lsb_multiple,
                                     window_s=self.window_s, lsb=self._lsb[name])
        return turning

    def _bounds(self, name: str, axes: tuple[str, ...]) -> tuple[float, float] | None:
        """Physical bounds of a column: values beyond are for ``spikes``, not this filter."""
        base = base_name(name, axes)
        if base == "temperature_c" and not self.counts:
            return TEMPERATURE_RANGE_C
        if base == "temperature_c" or (base == "freq_hz" and self.sensor):
            return None
        bounds = _BOUNDS.get(base)
        return None if bounds is None else (bounds[0], bounds[1])

    def summary(self) -> Summary:
        """How many rows had spikes, per column, the threshold, what was done and the first
        (its text: one line; empty without any)."""
        if not self.rows or self.first is None:
            return Summary("single-sample spikes", layout=("",))
        done = "removed" if self.mode == "drop" else f"flagged in column '{SPIKE_COLUMN}'"
        name, row, value = self.first
        figures = (Figure("rows", "rows with spikes", self.rows,
                          definition=f"Rows with a single-sample spike, {done}."),
                   *(Figure(f"found.{column}", f"spikes in {column}", count)
                     for column, count in self.found.items()),
                   Figure("k", "threshold, σ_MAD", self.k), Figure("lsb_multiple",
                                                                   "threshold, LSB",
                                                                   self.lsb_multiple),
                   Figure("window_s", "window", self.window_s, "s"),
                   Figure("first.column", "first: column", name),
                   Figure("first.row", "first: row", row),
                   Figure("first.value", "first: value", value))
        per = ", ".join(f"{escape(column)} {{found.{column}}}" for column in self.found)
        where = escape(f"{self.source}: ") if self.source else ""
        return Summary("single-sample spikes", (("spikes", figures),), layout=(
            f"{where}{{rows}} row(s) with single-sample spikes {escape(done)} ({per}; "
            "threshold max({k:g}·σ_MAD, {lsb_multiple:g}·LSB) over {window_s:g} s windows); "
            "the first: column '{first.column}', row {first.row}, value {first.value:.6g}",))

    def warn(self) -> None:
        """One :class:`~hrgtc.core.errors.SpikeWarning` for the whole file (none without spikes)."""
        text = self.summary().text()
        if text:
            warnings.warn(text, SpikeWarning, stacklevel=3)


def check_spike_filter(mode: str) -> str:
    """Return ``mode`` if it is one of :data:`SPIKE_FILTERS`, else raise InputError."""
    if mode not in SPIKE_FILTERS:
        raise InputError(f"spike_filter must be one of {list(SPIKE_FILTERS)}, got {mode!r}; "
                         "'drop' removes single-sample spikes, 'flag' marks them in a "
                         f"'{SPIKE_COLUMN}' column")
    return mode
