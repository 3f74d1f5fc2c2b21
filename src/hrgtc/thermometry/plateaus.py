"""Soak plateaus: the settled frequency of each chamber set-point, Section 3 of [1].

The paper soaks the gyro 4-5 h per chamber set-point and reads the frequency
once it "did not change any more" (Fig. 3 of [1]: the resonator in vacuum
settles after ~15,000 s); the settled frequencies are Table 1, to which Eq. (18)
is fitted (:func:`hrgtc.thermometry.fit`). :func:`find_plateaus` does this on
recordings, on block means (10 s by default), so hours of 200 Hz data cost a
few bincounts:

1. **Segments**: stretches where the chamber stays within ``chamber_tolerance_c``
   of one value for at least ``min_duration_s``; a file may hold one soak or
   many set-points in sequence.
2. **Settled stretch**: the trailing run of a segment where the robust slope of
   the frequency over ``min_duration_s`` windows (median of block differences
   half a window apart) stays below ``slope_threshold_hz_per_h``.
3. **Settling-curve fit** (:func:`hrgtc.thermometry.settling.fit_transient`, re-exported
   here): f(t) after the chamber reached its set-point, fitted with one or two
   exponentials of the two-node thermal network (with the cubic f(T) of Eq. 17
   of [1]) and extrapolated to f_inf, so that soaks cut short still give their
   settled frequency.

**The value for the thermometer table** is ``Plateau.settled_freq_hz`` (what
:func:`plateau_table` returns): with ``extrapolate=True`` (default) the fitted
f_inf whenever the fit is well determined (slowest time constant shorter than
the fitted span, standard error finite and below ``max_fit_std_c``), otherwise
the mean of the settled stretch; with ``extrapolate=False`` always that mean.

[1] X. Wang, W. Wu, Z. Fang, B. Luo, Y. Li, Q. Jiang, "Temperature Drift
    Compensation for Hemispherical Resonator Gyro Based on Natural Frequency",
    Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from hrgtc.core import records
from hrgtc.core.errors import CalibrationError, InputError, RecordingError
from hrgtc.core.progress import Progress
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.recording import Recording
from hrgtc.settings.calibration import PlateauSettings
from hrgtc.thermometry.settling import (
    MIN_FIT_POINTS,
    TransientFit,
    fit_transient,
)

__all__ = [
    "DEFAULT_HZ_PER_C",
    "Plateau",
    "TransientFit",
    "find_plateaus",
    "fit_transient",
    "plateau_table",
    "plateaus_from_recordings",
]

_PLATEAU = PlateauSettings
#: Approximate df/dT, the linear term of Eq. (18) of [1]. [Hz/°C]
DEFAULT_HZ_PER_C = _PLATEAU.hz_per_c
#: 0.01 Hz/h = 0.027 °C/h at 0.37 Hz/°C. A first-order tail is slope x tau from equilibrium,
#: so with the ~40 min resonator time constant behind the 15,000 s settling of [1] the soak
#: is then within ~0.02 °C of it, the table tolerance of issue 4. [Hz/h]
DEFAULT_SLOPE_THRESHOLD_HZ_PER_H = _PLATEAU.slope_threshold_hz_per_h
#: 30 min: ~0.75 resonator time constants, and long enough to resolve 0.01 Hz/h under mHz
#: frequency noise (the slope's standard error is then ~1e-4 Hz/h at 200 Hz). [s]
DEFAULT_MIN_DURATION_S = _PLATEAU.min_duration_s
#: What a climatic chamber holds around its set-point. [°C]
DEFAULT_CHAMBER_TOLERANCE_C = _PLATEAU.chamber_tolerance_c
#: Largest standard error of an extrapolated f_inf, in resonator temperature. [°C]
DEFAULT_MAX_FIT_STD_C = _PLATEAU.max_fit_std_c


@dataclass(frozen=True)
class Plateau(records.Written):
    """One soak: its final stretch, settled frequency and settling-curve fit.

    Attributes
    ----------
    chamber_c
        Mean chamber temperature of the final stretch: the table's temperature. [°C]
    freq_hz, freq_std_hz
        Mean and standard deviation of the frequency samples of the final stretch. [Hz]
    n_samples
        Samples in the final stretch.
    start_s, end_s
        The final stretch: the settled stretch, or the last ``min_duration_s``
        when the slope criterion is not met. [s]
    slope_hz_per_h
        Robust frequency slope over the last ``min_duration_s``. [Hz/h]
    settled
        True when the slope criterion holds over the final stretch.
    settled_freq_hz, settled_freq_std_hz
        The frequency for the thermometer table (module docstring), standard error. [Hz]
    method
        ``"transient fit"`` or ``"settled mean"``: where ``settled_freq_hz`` comes from.
    residual_unsettled_c
        Resonator temperature minus its equilibrium at the end of the record,
        ``(f(end) - f_inf) / hz_per_c`` from the fit (NaN without a usable fit). [°C]
    hz_per_c
        Sensitivity used for conversions to °C. [Hz/°C]
    segment_start_s
        When the chamber reached this set-point (start of the fit). [s]
    fit
        The settling-curve fit (None if the segment is too short to fit).
    source
        The recording's source (file), if known.
    """

    chamber_c: float
    freq_hz: records.Statistic
    freq_std_hz: records.Statistic
    n_samples: records.Count
    start_s: float
    end_s: float
    slope_hz_per_h: records.Statistic
    settled: bool
    settled_freq_hz: records.Statistic
    settled_freq_std_hz: records.Statistic
    method: str
    residual_unsettled_c: records.Statistic
    hz_per_c: records.Statistic
    segment_start_s: float
    fit: TransientFit | None = None
    source: str | None = None

    @property
    def slope_c_per_h(self) -> float:
        """Final slope in resonator temperature, ``slope_hz_per_h / hz_per_c``. [°C/h]"""
        return self.slope_hz_per_h / self.hz_per_c

    def summary(self) -> Summary:
        """The settled frequency, the final stretch's mean, std and slopes, the residual
        unsettled temperature and the transient fit (its figures after ``fit.``); its text
        a few lines."""
        where = escape(f" [{self.source}]") if self.source else ""
        state = "settled" if self.settled else "not settled by slope"
        figures = (
            Figure("chamber_c", "chamber", self.chamber_c, "°C"),
            Figure.with_error("settled_freq_hz", "settled frequency", self.settled_freq_hz,
                              self.settled_freq_std_hz, "Hz", definition="The resonator's "
                              f"frequency once settled at the plateau ({self.method})."),
            Figure("settled_freq_std_hz", "its standard error", self.settled_freq_std_hz, "Hz"),
            Figure("start_h", "final stretch from", self.start_s / 3600, "h"),
            Figure("end_h", "final stretch to", self.end_s / 3600, "h"),
            Figure("n_samples", "samples", self.n_samples),
            Figure("freq_hz", "mean frequency", self.freq_hz, "Hz",
                   definition="Mean frequency of the final stretch."),
            Figure("freq_std_hz", "frequency std", self.freq_std_hz, "Hz"),
            Figure("slope_hz_per_h", "slope", self.slope_hz_per_h, "Hz/h"),
            Figure("slope_c_per_h", "slope in temperature", self.slope_c_per_h, "°C/h"),
            Figure("residual_unsettled_c", "residual unsettled temperature",
                   self.residual_unsettled_c, "°C", definition="How far from settled the "
                   "resonator still was, in °C, at the end of the plateau."))
        lines = [
            "plateau at chamber {chamber_c:.3f} °C" + where + ": settled frequency "
            "{settled_freq_hz:.5f} ± {settled_freq_std_hz:.2g} Hz " + escape(f"({self.method})"),
            "  final stretch {start_h:.2f}-{end_h:.2f} h ({n_samples} samples): mean "
            "{freq_hz:.5f} Hz, std {freq_std_hz:.2g} Hz, slope {slope_hz_per_h:+.3g} Hz/h "
            f"({{slope_c_per_h:+.3g}} °C/h), {state}",
            "  residual unsettled temperature {residual_unsettled_c:+.4f} °C",
        ]
        sections = [("plateau", figures)]
        if self.fit is not None:
            fit = self.fit.summary().renamed("fit.")
            sections += fit.sections
            lines += fit.lines("  ")
        return Summary(f"plateau at chamber {self.chamber_c:.3f} °C", tuple(sections),
                       layout=tuple(lines))


# -- block means, chamber segments and slopes -----------------------------------------
@dataclass(frozen=True)
class _Blocks:
    """Per-block statistics of one recording (blocks of ``block_s`` on its clock)."""

    count: np.ndarray
    time_s: np.ndarray  # mean time of the block
    first_s: np.ndarray  # time of its first sample
    last_s: np.ndarray  # time of its last sample
    freq_hz: np.ndarray  # mean frequency
    chamber_c: np.ndarray  # mean chamber temperature
    dev_sq_sum: np.ndarray  # sum of (freq - ref_hz)^2
    ref_hz: float


def _where(recording: Recording) -> str:
    return f" in {recording.source}" if recording.source else ""


def _blocks(recording: Recording, block_s: float) -> _Blocks:
    if "chamber_c" not in recording:
        raise RecordingError(
            f"column 'chamber_c' not found{_where(recording)} (columns {list(recording.names)}); "
            "soak calibration needs the chamber temperature: map your chamber column to "
            "chamber_c (e.g. --column chamber_c=YOUR_NAME)"
        )
    for name in ("time_s", "freq_hz", "chamber_c"):
        bad = np.flatnonzero(~np.isfinite(recording[name]))
        if bad.size:
            raise RecordingError(
                f"column {name!r}{_where(recording)} is {recording[name][bad[0]]} at row "
                f"{bad[0]} ({bad.size} non-finite rows); clean or cut the recording "
                "(hrgtc.recording.validate lists the problems)"
            )
    time = recording.time_s
    steps = np.flatnonzero(np.diff(time) <= 0)
    if time.size < 2 or steps.size:
        row = int(steps[0]) + 1 if steps.size else 0
        raise RecordingError(
            f"time_s{_where(recording)} must increase over at least 2 rows; it does not at "
            f"row {row}: sort the rows or remove duplicated samples"
        )
    from hrgtc.thermometry._plateau_kernel import block_index, block_sums  # numba: when used

    idx = (block_index(np.ascontiguousarray(time, dtype=np.float64), float(block_s))
           if block_s > 0 else np.floor_divide(time - time[0], block_s).astype(np.intp))
    ref = float(recording.freq_hz[0])
    count_all, time_sum, dev_sum, dev_sq_sum, chamber_sum = block_sums(
        idx, np.ascontiguousarray(time, dtype=np.float64),
        np.ascontiguousarray(recording.freq_hz, dtype=np.float64), ref,
        np.ascontiguousarray(recording["chamber_c"], dtype=np.float64))
    ids = np.flatnonzero(count_all >= max(1.0, 0.5 * np.median(count_all[count_all > 0])))
    count = count_all[ids].astype(np.float64)
    first = np.searchsorted(idx, ids, side="left")
    last = np.searchsorted(idx, ids, side="right") - 1
    return _Blocks(
        count=count,
        time_s=time_sum[ids] / count,
        first_s=time[first],
        last_s=time[last],
        freq_hz=ref + dev_sum[ids] / count,
        chamber_c=chamber_sum[ids] / count,
        dev_sq_sum=dev_sq_sum[ids],
        ref_hz=ref,
    )


def _chamber_segments(chamber_c: np.ndarray, tolerance_c: float, min_blocks: int):
    """(start, stop) block ranges where the chamber stays within tolerance of one level.

    Anchored at each stretch's end (where a soak is settled): the level is the
    median of the last minute of blocks, and the stretch extends back while the
    chamber stays within ``tolerance_c`` of it.
    """
    segments = []
    stop = chamber_c.size
    while stop >= min_blocks:
        level = float(np.median(chamber_c[max(0, stop - 6) : stop]))
        outside = np.flatnonzero(np.abs(chamber_c[:stop] - level) > tolerance_c)
        start = int(outside[-1]) + 1 if outside.size else 0
        if stop - start >= min_blocks:
            # trim the ends of the slews in and out, beyond the chamber's own noise
            stretch = chamber_c[start:stop]
            deviation = np.abs(stretch - np.median(stretch))
            band = max(5.0 * 1.4826 * float(np.median(deviation)), 0.02 * tolerance_c)
            inside = np.flatnonzero(deviation <= band)
            first, last = start + int(inside[0]), start + int(inside[-1]) + 1
            if last - first >= min_blocks:
                segments.append((first, last))
        stop = min(start, stop - 1)
    return segments[::-1]


def _robust_slopes(time_s: np.ndarray, freq_hz: np.ndarray, window: int) -> np.ndarray:
    """Slope over each run of ``window`` blocks, for runs ending at block window-1, ... [Hz/s]

    The median of the differences of blocks half a window apart (Theil-Sen
    restricted to those pairs: robust to outliers, vectorised).
    """
    half = window // 2
    diffs = (freq_hz[half:] - freq_hz[:-half]) / (time_s[half:] - time_s[:-half])
    return np.median(sliding_window_view(diffs, window - half), axis=1)


# -- plateaus -----------------------------------------------------------------------
@dataclass(frozen=True)
class _Settings:
    threshold_hz_per_h: float
    min_duration_s: float
    tolerance_c: float
    block_s: float
    extrapolate: bool
    hz_per_c: float
    max_fit_std_c: float

    @property
    def window(self) -> int:
        return round(self.min_duration_s / self.block_s)


def _settings(options: Mapping[str, Any]) -> _Settings:
    values = {}
    for name, unit in (
        ("slope_threshold_hz_per_h", "Hz/h"), ("min_duration_s", "s"),
        ("chamber_tolerance_c", "°C"), ("block_s", "s"), ("max_fit_std_c", "°C"),
        ("hz_per_c", "Hz/°C"),
    ):  # fmt: skip
        raw = options[name]
        try:
            value = float(raw)
        except (TypeError, ValueError):
            value = math.nan
        if not (math.isfinite(value) and (value > 0 or (name == "hz_per_c" and value != 0))):
            kind = "a finite non-zero" if name == "hz_per_c" else "a positive"
            raise InputError(f"{name} must be {kind} number [{unit}], got {raw!r}")
        values[name] = value
    settings = _Settings(
        values["slope_threshold_hz_per_h"], values["min_duration_s"],
        values["chamber_tolerance_c"], values["block_s"], bool(options["extrapolate"]),
        values["hz_per_c"], values["max_fit_std_c"],
    )  # fmt: skip
    if settings.window < 3:
        raise InputError(
            f"min_duration_s={settings.min_duration_s:g} s is under 3 blocks of "
            f"block_s={settings.block_s:g} s; lengthen min_duration_s or shorten block_s"
        )
    return settings


def find_plateaus(
    recording: Recording | Sequence[Recording],
    *,
    slope_threshold_hz_per_h: float = DEFAULT_SLOPE_THRESHOLD_HZ_PER_H,
    min_duration_s: float = DEFAULT_MIN_DURATION_S,
    chamber_tolerance_c: float = DEFAULT_CHAMBER_TOLERANCE_C,
    block_s: float = _PLATEAU.block_s,
    extrapolate: bool = _PLATEAU.extrapolate,
    hz_per_c: float = DEFAULT_HZ_PER_C,
    max_fit_std_c: float = DEFAULT_MAX_FIT_STD_C,
    progress: Progress | None = None,
) -> list[Plateau]:
    """Settled plateaus of chamber soaks: the rows of Table 1 of [1] (Section 3).

    One plateau per stretch of stable chamber temperature at least
    ``min_duration_s`` long (method in the module docstring).

    Parameters
    ----------
    recording
        A recording with ``time_s``, ``freq_hz`` and ``chamber_c`` (one soak or
        many set-points in sequence), or a sequence of them (one file per soak,
        see :func:`plateaus_from_recordings`).
    slope_threshold_hz_per_h
        Settled: the robust frequency slope over every ``min_duration_s`` window
        of the stretch is below this. [Hz/h]
    min_duration_s
        Minimum settled time, the slope window and the shortest stable chamber
        stretch that counts as a soak. [s]
    chamber_tolerance_c
        The chamber stays within this of its level during a soak. [°C]
    block_s
        Length of the block means everything is computed on. [s]
    extrapolate
        Take ``settled_freq_hz`` from the settling-curve fit (:func:`fit_transient`)
        whenever it is well determined, even if the slope criterion is not met.
    hz_per_c
        Approximate df/dT for the °C figures; 0.37 Hz/°C is the linear term of
        Eq. (18) of [1]. [Hz/°C]
    max_fit_std_c
        Largest standard error of an extrapolated f_inf, ``std / hz_per_c``. [°C]
    progress
        Called with (done, total) chamber segments (recordings for a sequence).

    Returns
    -------
    list of Plateau
        In time order (recording order for a sequence).

    Raises
    ------
    CalibrationError
        No stable chamber stretch, or a soak that neither settles nor has a
        usable settling-curve fit (the message gives its final slope in Hz/h
        and °C/h).
    RecordingError
        No ``chamber_c`` column, non-finite values or non-increasing time.

    Examples
    --------
    A 2.5 h soak from 20 °C to -10 °C is far from settled, but its settling
    curve gives Eq. (18) of [1] at -10 °C (4421.0731 Hz) within ~0.01 °C:

    >>> from hrgtc import simulate
    >>> rec = simulate.simulate_run(simulate.soak(-10.0, 2.5), sample_rate_hz=1.0, seed=0)
    >>> (plateau,) = find_plateaus(rec)
    >>> plateau.settled, plateau.method, plateau.chamber_c
    (False, 'transient fit', -10.0)
    >>> abs(plateau.settled_freq_hz - 4421.0731) < 0.004
    True
    """
    chosen = PlateauSettings(
        slope_threshold_hz_per_h=slope_threshold_hz_per_h, min_duration_s=min_duration_s,
        chamber_tolerance_c=chamber_tolerance_c, block_s=block_s, extrapolate=extrapolate,
        hz_per_c=hz_per_c, max_fit_std_c=max_fit_std_c)
    if not isinstance(recording, Recording):
        return plateaus_from_recordings(recording, chosen, progress=progress)
    return _recording_plateaus(recording, _settings(dataclasses.asdict(chosen)), progress)


def _recording_plateaus(recording: Recording, settings: _Settings,
                        progress: Progress | None) -> list[Plateau]:
    """:func:`find_plateaus` of one recording: a plateau per stable chamber stretch."""
    blocks = _blocks(recording, settings.block_s)
    segments = _chamber_segments(blocks.chamber_c, settings.tolerance_c, settings.window)
    if not segments:
        c = blocks.chamber_c
        raise CalibrationError(
            f"no soak found{_where(recording)}: the chamber (block means {c.min():.2f} to "
            f"{c.max():.2f} °C) never stays within chamber_tolerance_c={settings.tolerance_c:g} "
            f"°C of one temperature for min_duration_s={settings.min_duration_s:g} s; is this a "
            "soak recording? If so, widen the tolerance or shorten min_duration_s"
        )
    plateaus = []
    for number, (lo, hi) in enumerate(segments):
        plateaus.append(_segment_plateau(recording, blocks, lo, hi, settings))
        if progress is not None:
            progress(float(number + 1), float(len(segments)))
    return plateaus


def _segment_plateau(
    recording: Recording, blocks: _Blocks, lo: int, hi: int, settings: _Settings
) -> Plateau:
    time, freq, window = blocks.time_s[lo:hi], blocks.freq_hz[lo:hi], settings.window
    slopes = _robust_slopes(time, freq, window) * 3600.0  # Hz/h, windows ending at window-1...
    ok = np.abs(slopes) < settings.threshold_hz_per_h
    start = hi - window
    if ok[-1]:
        bad = np.flatnonzero(~ok)
        start = lo + (int(bad[-1]) + 1 if bad.size else 0)
    count = blocks.count[start:hi]
    n = float(count.sum())
    mean_hz = float(np.sum(freq[start - lo :] * count) / n)
    var = (float(blocks.dev_sq_sum[start:hi].sum()) / n - (mean_hz - blocks.ref_hz) ** 2) * n
    chamber_c = float(np.sum(blocks.chamber_c[start:hi] * count) / n)
    slope = float(slopes[-1])
    fit = fit_transient(time, freq) if time.size >= MIN_FIT_POINTS else None
    fit_std_c = math.inf if fit is None else fit.f_inf_std_hz / abs(settings.hz_per_c)
    use_fit = settings.extrapolate and fit is not None and fit.usable
    use_fit = use_fit and fit_std_c <= settings.max_fit_std_c
    if not (ok[-1] or use_fit):
        if not settings.extrapolate:
            why = "pass extrapolate=True to estimate the settled frequency from the settling curve"
        elif fit is None:
            why = "the segment is too short to fit its settling curve"
        elif not fit.usable:
            why = f"the settling-curve fit cannot stand in: {fit.reason}"
        else:
            why = (
                f"the settling-curve fit cannot stand in: its settled frequency is uncertain "
                f"by ±{fit_std_c:.3g} °C, more than max_fit_std_c={settings.max_fit_std_c:g} °C"
            )
        threshold, per_c = settings.threshold_hz_per_h, settings.hz_per_c
        raise CalibrationError(
            f"the soak at chamber {chamber_c:.2f} °C{_where(recording)} ending at "
            f"{blocks.last_s[hi - 1] / 3600:.2f} h did not settle: over its last "
            f"{settings.min_duration_s / 60:g} min the frequency still changed by {slope:+.3g} "
            f"Hz/h ({slope / per_c:+.3g} °C/h at {per_c:g} Hz/°C), above "
            f"slope_threshold_hz_per_h={threshold:g} Hz/h ({threshold / per_c:.3g} °C/h); "
            f"{why}. Lengthen the soak (a resonator in vacuum needs hours: ~15,000 s in [1]) "
            "or raise slope_threshold_hz_per_h"
        )
    block_std = float(np.std(freq[start - lo :], ddof=1))
    usable = fit is not None and fit.usable
    return Plateau(
        chamber_c=chamber_c,
        freq_hz=mean_hz,
        freq_std_hz=math.sqrt(max(var, 0.0) / max(n - 1.0, 1.0)),
        n_samples=round(n),
        start_s=float(blocks.first_s[start]),
        end_s=float(blocks.last_s[hi - 1]),
        slope_hz_per_h=slope,
        settled=bool(ok[-1]),
        settled_freq_hz=fit.f_inf_hz if use_fit else mean_hz,
        settled_freq_std_hz=fit.f_inf_std_hz if use_fit else block_std / math.sqrt(hi - start),
        method="transient fit" if use_fit else "settled mean",
        residual_unsettled_c=fit.end_offset_hz / settings.hz_per_c if usable else math.nan,
        hz_per_c=settings.hz_per_c,
        segment_start_s=float(blocks.first_s[lo]),
        fit=fit,
        source=recording.source,
    )


def plateaus_from_recordings(
    recordings: Sequence[Recording],
    settings: PlateauSettings | None = None,
    *,
    progress: Progress | None = None,
) -> list[Plateau]:
    """:func:`find_plateaus` of each recording (e.g. one file per soak), concatenated.

    ``settings`` are the plateau finder's (:func:`find_plateaus` with its fields as
    keywords, the defaults when None); ``progress`` is called with (done, total) recordings.
    """
    words = dataclasses.asdict(settings or PlateauSettings())
    items = list(recordings)
    if not items:
        raise InputError("no recordings given; pass at least one soak recording")
    plateaus: list[Plateau] = []
    for number, item in enumerate(items):
        if not isinstance(item, Recording):
            raise InputError(
                f"recordings[{number}] is a {type(item).__name__}, not a Recording; "
                "read files with hrgtc.recording.read"
            )
        plateaus.extend(find_plateaus(item, **words))
        if progress is not None:
            progress(float(number + 1), float(len(items)))
    return plateaus


def plateau_table(plateaus: Sequence[Plateau]) -> tuple[np.ndarray, np.ndarray]:
    """The unit's Table 1 (of [1]): chamber temperatures and settled frequencies.

    Feed it to :func:`hrgtc.thermometry.fit` (Eq. 18 of [1]).

    Returns
    -------
    chamber_c : numpy.ndarray
        ``Plateau.chamber_c`` of each plateau. [°C]
    freq_hz : numpy.ndarray
        ``Plateau.settled_freq_hz`` of each plateau. [Hz]
    """
    items = list(plateaus)
    if not items:
        raise CalibrationError("no plateaus: the thermometer needs soaks at several temperatures")
    chamber = np.array([p.chamber_c for p in items], dtype=np.float64)
    return chamber, np.array([p.settled_freq_hz for p in items], dtype=np.float64)
