"""At rest is checked, not assumed: find the samples where the gyro was moved.

A drift model is a law of the bias of a gyro at rest. A recording picked up,
turned or shaken between still periods holds samples whose rate is the motion,
not the bias; trained on, they pull the temperature and df/dt terms and set the
trained ranges. :func:`detect_motion` marks every sample that is not at rest:

- **level**: the rate (minus the known input rate) against the *local* still
  baseline, a robust running level (median of ``baseline_s`` blocks, then a
  running median of those over :data:`BASELINE_BLOCKS` blocks, interpolated in
  time) and against the two anchors around the sample (a step of the still level,
  a new orientation, is at rest when motion is found within a block of it), not
  against zero: a MEMS axis may sit several °/s from zero at rest. A
  sample is moving when it lies more than ``threshold`` robust σ from the
  baseline for at least ``min_motion_s`` (and two samples): an isolated
  single-sample excursion is a spike (the spike filter's business), not motion.
- **variance**: the robust (MAD-based) spread of the first differences in
  ``window_s`` blocks against the at-rest noise of the whole recording: shaking
  without a net rate.
- **clipped**: runs of ``clip_samples`` equal values at a channel's extreme, away
  from its baseline (saturation).
- **accelerometer**: the same level and variance tests on each mapped ``accel_*``
  column (a tilt or a knock that the gyro barely sees).
- **guard**: ``guard_s`` after (and ``guard_before_s`` before) every moving
  sample, while the unit settles.

Every window is in seconds and lives inside one contiguous segment: a gap (a
time step larger than :data:`GAP_FACTOR` median periods, or a step that does not
go forward) starts a new segment, and neither the baseline nor a guard reaches
across it.

The same detector finds the still periods of an in-field update:
:meth:`MotionMask.still_periods`.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.core.summary import Figure, Summary, escape
from hrgtc.settings.reading import DROPOUT_S

#: A gap: a time step larger than this many median periods.
GAP_FACTOR = 2.0
#: Consistency constant of the MAD for a Gaussian (σ = 1.4826 · MAD).
MAD_TO_SIGMA = 1.482602218505602
#: Baseline blocks in the running median of block medians (centred).
BASELINE_BLOCKS = 5
#: Fewest samples of a variance block (the MAD of fewer differences is too noisy a figure).
VARIANCE_MIN_SAMPLES = 32
#: What calibration and evaluation do with moving samples (``--motion``).
MOTION_POLICIES = ("exclude", "keep", "error")
#: Motion found for at least this long (beyond its guards) is handling, next to which a
#: short still pause is not at rest (:attr:`MotionSettings.min_still_s`). [s]
HANDLING_S = 5.0
#: Reasons a sample is marked, in the order they are reported.
REASONS = ("level", "variance", "clipped", "accelerometer", "guard", "short_still")
#: Columns read as accelerometer axes when present.
ACCEL_COLUMNS = ("accel_x", "accel_y", "accel_z")


@dataclass(frozen=True)
class MotionSettings:
    """How :func:`detect_motion` decides that a sample is not at rest.

    Attributes
    ----------
    baseline_s
        Block length of the robust running level of each channel. [s]
    window_s
        Block length of the variance test (at least :data:`VARIANCE_MIN_SAMPLES`). [s]
    threshold
        Level test: distance from the baseline in robust σ of the at-rest noise.
    variance_ratio
        Variance test: ratio of a block's robust σ of first differences to the
        recording's above which the block is moving.
    min_motion_s
        Shortest excursion (beyond ``threshold``) that counts as motion; shorter ones,
        and single samples always, are spikes. [s]
    guard_s, guard_before_s
        Samples this long after / before motion are marked too (the unit settling;
        the motion's onset below the threshold). [s]
    min_still_s
        A still stretch next to handling (motion lasting :data:`HANDLING_S` beyond its
        guards), between two handlings or from the start or to the end of a segment,
        shorter than this is not at rest either (reason ``short_still``): a unit put down
        for a moment between handlings has not settled (the hand's warmth, a thermal
        gradient), and its few samples would set the trained ranges. Stretches between gaps
        only (a burst logger's bursts) or between scattered single marks are never
        marked. [s]
    clip_samples
        Equal consecutive samples at a channel's extreme that make a clipped plateau.
    """

    baseline_s: float = 60.0
    window_s: float = 1.0
    threshold: float = 6.0
    variance_ratio: float = 3.0
    min_motion_s: float = 0.1
    guard_s: float = 5.0
    guard_before_s: float = 2.0
    clip_samples: int = 3
    min_still_s: float = 300.0

    def __post_init__(self) -> None:
        for name in ("baseline_s", "window_s", "threshold", "variance_ratio"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise InputError(f"motion setting {name} must be a positive number, got "
                                 f"{value!r}")
        for name in ("min_motion_s", "guard_s", "guard_before_s", "min_still_s"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise InputError(f"motion setting {name} must be a number of seconds >= 0, "
                                 f"got {value!r}")
        if int(self.clip_samples) < 2:
            raise InputError(f"motion setting clip_samples must be at least 2, got "
                             f"{self.clip_samples!r}")

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MotionSettings:
        """Inverse of :meth:`to_dict` (missing keys take their defaults)."""
        known = set(cls.__dataclass_fields__)
        return cls(**{k: v for k, v in data.items() if k in known})


@dataclass(frozen=True, eq=False)
class MotionMask:
    """Which samples of a recording are not at rest, and why.

    Attributes
    ----------
    moving
        True where the sample is not at rest (any reason), one per sample.
    reasons
        Reason (:data:`REASONS`) -> boolean mask; a sample may have several.
    breaks
        ``breaks[i]``: sample i + 1 starts a new contiguous segment (a gap, or a step
        that does not go forward); :attr:`segment` numbers the segments.
    noise
        Channel -> robust σ of its at-rest noise (sample to sample). [channel unit]
    settings
        The settings used.
    """

    moving: np.ndarray
    reasons: dict[str, np.ndarray]
    breaks: np.ndarray
    noise: dict[str, float] = field(default_factory=dict)
    settings: MotionSettings = field(default_factory=MotionSettings)

    @property
    def n_samples(self) -> int:
        return int(self.moving.size)

    @functools.cached_property
    def segment(self) -> np.ndarray:
        """Index of the contiguous segment of each sample (a gap starts a new one); computed
        when first asked for (eight bytes a sample)."""
        segment = np.zeros(self.moving.size, dtype=np.int64)
        if self.moving.size > 1:
            np.cumsum(self.breaks, out=segment[1:])
        return segment

    @property
    def n_moving(self) -> int:
        """Samples not at rest."""
        return int(np.count_nonzero(self.moving))

    @property
    def fraction(self) -> float:
        """Share of samples not at rest (0 for an empty recording)."""
        return self.n_moving / self.n_samples if self.n_samples else 0.0

    @property
    def still(self) -> np.ndarray:
        """True where the sample is at rest."""
        return ~self.moving

    def counts(self) -> dict[str, int]:
        """Samples marked for each reason (a sample may count under several)."""
        return {r: int(np.count_nonzero(m)) for r, m in self.reasons.items()}

    def still_periods(self, min_s: float = 0.0, time_s: np.ndarray | None = None,
                      join_gap_s: float = 0.0) -> list[tuple[int, int]]:
        """Index ranges ``[start, stop)`` of contiguous still samples inside one segment.

        With ``time_s``, periods shorter than ``min_s`` seconds are left out, and a break
        of the time axis no longer than ``join_gap_s`` (a dropout: a late or lost record)
        does not cut a period. This is what an in-field update of the bias uses.
        """
        still = self.still.astype(np.int8)
        breaks = np.flatnonzero(self.breaks) + 1
        if time_s is not None and join_gap_s > 0.0 and breaks.size:
            breaks = breaks[time_s[breaks] - time_s[breaks - 1] > join_gap_s]
        edges = np.diff(np.concatenate([[0], still, [0]]))
        starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
        out: list[tuple[int, int]] = []
        for start, stop in zip(starts, stops, strict=True):
            cuts = breaks[(breaks > start) & (breaks < stop)]
            bounds = [int(start), *map(int, cuts), int(stop)]
            for a, b in itertools.pairwise(bounds):
                if time_s is not None and min_s > 0 and time_s[b - 1] - time_s[a] < min_s:
                    continue
                out.append((a, b))
        return out

    def to_dict(self) -> dict[str, Any]:
        """The counts as plain JSON types (not the masks)."""
        return {"n_samples": self.n_samples, "n_moving": self.n_moving,
                "fraction": self.fraction, "reasons": self.counts(),
                "noise": dict(self.noise), "settings": self.settings.to_dict()}

    def summary(self) -> Summary:
        """Samples not at rest, their share and the count of each reason (its text: one
        line)."""
        counts = {r: n for r, n in self.counts().items() if n}
        figures = (Figure("n_moving", "samples not at rest", self.n_moving,
                          definition="Samples marked as moving for any reason."),
                   Figure("n_samples", "samples", self.n_samples),
                   Figure("fraction", "share not at rest", self.fraction, spec=".1%"),
                   *(Figure(f"counts.{r}", f"marked by {r}", n,
                            definition=f"Samples marked by the {r} test (a sample may count "
                            "under several).") for r, n in counts.items()))
        why = ", ".join(f"{escape(r)} {{counts.{r}}}" for r in counts)
        return Summary("motion", (("motion", figures),), layout=(
            "motion: {n_moving} of {n_samples} samples not at rest ({fraction:.1%})"
            + (f" [{why}]" if why else ""),))


# --------------------------------------------------------------------------- helpers
# The loops are in C (hrgtc.recording._motion_kernel wraps _motion_native.c; no numba);
# their numpy definitions are kept beside the tests that compare them
# (tests/motion_reference.py).
#: Differences sampled to bracket the middle ranks of their median.
_SAMPLE = 65_536


def _difference_median(x: np.ndarray, breaks: np.ndarray, mode: int,
                       centre: float = 0.0) -> tuple[float, int]:
    """``(np.median(d), d.size)`` of the first differences ``d`` of ``x`` that ``mode``
    selects (``hrgtc.recording._motion_kernel``: forward steps, steps inside segments,
    or their absolute deviations from ``centre``), without building ``d``: a sorted
    sample of them brackets the middle ranks, one pass counts what lies below and
    keeps what lies between, and the middle values are picked from those (exact; all
    of ``d`` is gathered only if the bracket missed). ``(nan, 0)``: none selected."""
    from hrgtc.recording import _motion_kernel as kernel

    count, sample = kernel.difference_sample(x, breaks, mode, centre, _SAMPLE)
    if count == 0:
        return math.nan, 0
    middle = ((count - 1) // 2, count // 2)
    if sample.size >= 64 and count > 4 * sample.size:
        sample.sort()
        margin = 4 * math.isqrt(sample.size) + 16
        lo = sample[max(int(middle[0] / count * sample.size) - margin, 0)]
        hi = sample[min(int(middle[1] / count * sample.size) + margin, sample.size - 1)]
        below, equal_lo, between, equal_hi = kernel.bracket(x, breaks, mode, centre, lo, hi)
        ranks = [k - below for k in middle]
        if all(0 <= r < equal_lo + between.size + equal_hi for r in ranks):
            inner = sorted({r - equal_lo for r in ranks if 0 <= r - equal_lo < between.size})
            if inner:
                between.partition(inner)
            picked = [lo if r < equal_lo else between[r - equal_lo]
                      if r < equal_lo + between.size else hi for r in ranks]
            return float(np.mean(picked)), count  # np.median's mean of the middle values
    return float(np.median(kernel.gather(x, breaks, mode, centre, count))), count


def _breaks(time_s: np.ndarray, gap_factor: float = GAP_FACTOR) -> tuple[np.ndarray, float]:
    """``(breaks, period)``: ``breaks[i]`` when sample i + 1 starts a new segment (a step
    longer than ``gap_factor`` median forward steps, or not forward), and the median
    forward step (1 if none). [s]"""
    from hrgtc.recording import _motion_kernel as kernel

    if time_s.size < 2:
        return np.zeros(0, dtype=bool), 1.0
    median, count = _difference_median(time_s, np.zeros(time_s.size - 1, dtype=bool),
                                        kernel.FORWARD)
    period = float(median) if count else 1.0
    return kernel.find_breaks(time_s, gap_factor * period), period


def segments_of(time_s: np.ndarray, gap_factor: float = GAP_FACTOR) -> np.ndarray:
    """Segment index of each sample: a new segment after each gap or backward step.

    Examples
    --------
    >>> segments_of(np.array([0.0, 1.0, 2.0, 10.0, 11.0])).tolist()
    [0, 0, 0, 1, 1]
    """
    from hrgtc.recording import _motion_kernel as kernel

    time_s = np.ascontiguousarray(time_s, dtype=np.float64)
    if time_s.size < 2:
        return np.zeros(time_s.size, dtype=np.int64)
    return kernel.segment_index(_breaks(time_s, gap_factor)[0])


def _bounds(breaks: np.ndarray, n: int) -> list[tuple[int, int]]:
    edges = np.flatnonzero(breaks) + 1
    starts = np.concatenate([[0], edges])
    stops = np.concatenate([edges, [n]])
    return [(int(a), int(b)) for a, b in zip(starts, stops, strict=True)]


def _period(time_s: np.ndarray, breaks: np.ndarray, forward: float) -> float:
    """Median time step inside the segments (``forward``: the median forward step). [s]"""
    from hrgtc.recording import _motion_kernel as kernel

    if time_s.size < 2:
        return 1.0
    if not breaks.any():  # the steps inside segments are all the forward steps
        return forward
    median, count = _difference_median(time_s, breaks, kernel.INSIDE_FORWARD)
    return float(median) if count else 1.0


def _rows(seconds: float, period: float, minimum: int = 1) -> int:
    return max(round(seconds / period), minimum)


def _resolution(values: np.ndarray) -> float:
    """Smallest step between distinct values (the quantum of a quantised stream; from the
    first 200,000 values, which show it as well as all of them)."""
    distinct = np.unique(values[:200_000][np.isfinite(values[:200_000])])
    if distinct.size < 2:
        return 0.0
    return float(np.min(np.diff(distinct)))


def _block_edges(n: int, rows: int) -> np.ndarray:
    """Edges of the baseline blocks of a segment of ``n`` samples (about ``rows`` each)."""
    blocks = max(n // rows, 1)
    return np.linspace(0, n, blocks + 1).astype(np.int64)


@dataclass
class _Channel:
    name: str
    values: np.ndarray
    sigma: float = 0.0
    diff_sigma: float = 0.0
    lsb: float = 0.0
    diff_centre: float = 0.0  # median first difference inside segments


def _prepare(name: str, values: np.ndarray, breaks: np.ndarray) -> _Channel:
    """A channel's at-rest noise: robust σ of its first differences inside segments."""
    from hrgtc.recording import _motion_kernel as kernel

    lsb = _resolution(values)
    diff_sigma = centre = 0.0
    if values.size >= 2:
        centre, count = _difference_median(values, breaks, kernel.INSIDE)
        if count:
            diff_sigma = MAD_TO_SIGMA * _difference_median(values, breaks, kernel.DEVIATION,
                                                           centre)[0]
    # white noise: a difference has twice the variance of a sample; the quantum floors it
    sigma = max(diff_sigma / math.sqrt(2.0), lsb)
    return _Channel(name, values, sigma, max(diff_sigma, lsb), lsb,
                    float(centre) if diff_sigma else 0.0)


# --------------------------------------------------------------------------- detection
def detector_rate(rate: np.ndarray, input_rate: Any, out: np.ndarray | None = None
                  ) -> np.ndarray:
    """The rate the level test reads: ``rate`` minus the known ``input_rate`` (a number or
    one per sample; ``rate`` itself when None or 0), into ``out`` if given (it may be
    ``rate``)."""
    if input_rate is None or (np.ndim(input_rate) == 0 and input_rate == 0):
        return rate
    return np.subtract(rate, np.asarray(input_rate, dtype=np.float64), out=out)


def detect_motion(
    time_s: Any,
    rates: Mapping[str, Any] | Any,
    *,
    accel: Mapping[str, Any] | None = None,
    input_rate: Any = None,
    settings: MotionSettings | None = None,
    overwrite: bool = False,
) -> MotionMask:
    """Mark the samples of a recording that are not at rest.

    Parameters
    ----------
    time_s
        Sample times (gaps allowed: each contiguous segment is treated alone). [s]
    rates
        The gyro rate, one array, or several axes as name -> array (motion on any
        axis marks the sample). [any rate unit, e.g. °/h]
    accel
        Accelerometer axes, name -> array (optional). [any unit]
    input_rate
        The known input rate (a number or one per sample), subtracted from every rate
        before the level test: a rate table's steps are not motion. [unit of ``rates``]
    settings
        Thresholds and windows (:class:`MotionSettings`).
    overwrite
        The rate arrays (float64, contiguous) are the caller's to change: the input rate
        is subtracted in place (:func:`detector_rate`) instead of into a new array (a
        fresh array of a long recording costs its page faults, ``docs/benchmarks.md``).

    Returns
    -------
    MotionMask

    Examples
    --------
    >>> t = np.arange(0.0, 600.0, 0.1)
    >>> rate = 4.0 + 0.01 * np.random.default_rng(1).standard_normal(t.size)
    >>> rate[3000:3030] += 50.0  # three seconds of handling
    >>> mask = detect_motion(t, rate)
    >>> bool(mask.moving[3000:3030].all()), bool(mask.moving[:2900].any())
    (True, False)
    """
    from hrgtc.recording import _motion_kernel as kernel

    s = settings or MotionSettings()
    time_s = np.ascontiguousarray(time_s, dtype=np.float64)
    if time_s.ndim != 1:
        raise InputError("time_s must be one-dimensional")
    n = time_s.size
    channels = dict(rates) if isinstance(rates, Mapping) else {"rate": rates}
    arrays: dict[str, np.ndarray] = {}
    for name, values in channels.items():
        values = np.ascontiguousarray(values, dtype=np.float64)
        arrays[name] = detector_rate(values, input_rate, values if overwrite else None)
    accel_names = []
    for name, values in dict(accel or {}).items():
        arrays[name] = np.ascontiguousarray(values, dtype=np.float64)
        accel_names.append(name)
    for name, values in arrays.items():
        if values.shape != (n,):
            raise InputError(f"motion channel {name!r} has {values.size} samples, time_s has "
                             f"{n}; give one value per sample")
        row = int(kernel.first_not_finite(values))
        if row >= 0:
            raise InputError(f"motion channel {name!r} is not finite at row {row}; drop or "
                             "repair non-finite samples first (--spikes drop)")
    reasons = {r: np.zeros(n, dtype=bool) for r in REASONS}
    if n == 0:
        return MotionMask(np.zeros(0, dtype=bool), reasons, np.zeros(0, dtype=bool), {}, s)
    breaks, forward = _breaks(time_s)
    period = _period(time_s, breaks, forward)
    prepared = [_prepare(name, values, breaks) for name, values in arrays.items()]
    base_rows = _rows(s.baseline_s, period, 8)
    var_rows = _rows(s.window_s, period, VARIANCE_MIN_SAMPLES)
    min_run = max(_rows(s.min_motion_s, period), 2)
    bounds = _bounds(breaks, n)
    stepped = {"level": np.zeros(n, dtype=bool), "accelerometer": np.zeros(n, dtype=bool)}
    for channel in prepared:
        extremes = np.array([np.max(channel.values), np.min(channel.values)])
        kind = "accelerometer" if channel.name in accel_names else "level"
        outputs = ((reasons["accelerometer"],) * 3 if kind == "accelerometer" else
                   (reasons["level"], reasons["variance"], reasons["clipped"]))
        tests = kernel.ChannelTests(
            int(BASELINE_BLOCKS), int(var_rows), int(min_run),
            float(s.threshold * channel.sigma), float(channel.diff_sigma),
            float(channel.diff_centre), float(MAD_TO_SIGMA),
            float(s.variance_ratio * channel.diff_sigma),
            float(s.threshold * max(channel.sigma, channel.lsb)), float(extremes[0]),
            float(extremes[1]), int(s.clip_samples), bool(channel.sigma > 0),
            kind == "accelerometer")
        for a, b in bounds:
            kernel.segment_tests(time_s[a:b], channel.values[a:b],
                                 _block_edges(b - a, base_rows), tests,
                                 (*(o[a:b] for o in outputs), stepped[kind][a:b]))
    starts, stops = (np.array(side, dtype=np.int64) for side in zip(*bounds, strict=True))
    # a step of the still level (a new orientation's offset) bends the interpolated
    # baseline for up to a block either side; within a block of motion found it is what
    # that motion left, at rest; a step with no motion near (a rate table starting, which
    # a gyro alone cannot tell from a new offset) stays motion
    near = np.zeros(n, dtype=bool)
    found = (reasons["level"], reasons["variance"], reasons["clipped"],
             reasons["accelerometer"])
    kernel.guard(found, starts, stops, base_rows, base_rows, near, np.zeros(n, dtype=bool))
    for kind, runs in stepped.items():
        kernel.isolated_runs(runs, near, reasons[kind])
    after, before = _rows(s.guard_s, period, 0), _rows(s.guard_before_s, period, 0)
    moving = np.zeros(n, dtype=bool)
    kernel.guard(found, starts, stops, after, before, moving, reasons["guard"])  # never
    # across a gap
    # stretches judged across dropouts (a lost record is no pause between handlings)
    joined = kernel.steps_over(time_s, max(GAP_FACTOR * period, DROPOUT_S)) + 1
    _short_still(time_s, moving, np.r_[0, joined], np.r_[joined, n], s.min_still_s,
                 s.guard_s + s.guard_before_s + HANDLING_S, reasons["short_still"])
    noise = {c.name: c.sigma for c in prepared}
    return MotionMask(moving, reasons, breaks, noise, s)


def _short_still(time_s: np.ndarray, moving: np.ndarray, starts: np.ndarray,
                 stops: np.ndarray, min_still_s: float, handling_s: float,
                 marked: np.ndarray) -> None:
    """Mark (in ``moving`` and ``marked``) the still stretches of each segment
    ``[starts[k], stops[k])`` next to handling (a stretch of motion, guards included, of at
    least ``handling_s``) that last less than ``min_still_s``. Scattered single marks (a
    coarse channel's steps, each with its guard) are no handling: the still stretches
    between them stay at rest."""
    if min_still_s <= 0 or not moving.any():
        return
    for a, b in zip(starts.tolist(), stops.tolist(), strict=True):
        part = moving[a:b]
        if not part.any():
            continue  # no motion in the segment: a burst, a quiet run
        # the runs of the segment, alternately still and moving (the padding ends each)
        edges = np.flatnonzero(np.diff(np.concatenate([[-1], part.astype(np.int8), [-1]])))
        lows, highs = edges[:-1], edges[1:]
        still = ~part[lows]
        span = time_s[a + highs - 1] - time_s[a + lows]
        handling = ~still & (span >= handling_s)
        before = np.concatenate([[False], handling[:-1]])
        after = np.concatenate([handling[1:], [False]])
        for lo, hi in zip(lows[still & (before | after) & (span < min_still_s)].tolist(),
                          highs[still & (before | after) & (span < min_still_s)].tolist(),
                          strict=True):
            moving[a + lo:a + hi] = True
            marked[a + lo:a + hi] = True


def recording_motion(recording: Any, settings: MotionSettings | None = None) -> MotionMask:
    """:func:`detect_motion` on a :class:`~hrgtc.recording.Recording`.

    Reads ``rate_dph`` (minus ``input_rate_dph``, the column where logged, else the
    metadata's) and, where present, the accelerometer columns :data:`ACCEL_COLUMNS`.
    """
    names = set(recording.names)
    input_rate = (recording["input_rate_dph"] if "input_rate_dph" in names
                  else recording.metadata.input_rate_dph)
    accel = {c: recording[c] for c in ACCEL_COLUMNS if c in names}
    return detect_motion(recording.time_s, {"rate_dph": recording.rate_dph}, accel=accel or None,
                         input_rate=input_rate, settings=settings)


# --------------------------------------------------------------------------- orientation
def orientation_labels(vectors: Any, tolerance_deg: float = 10.0,
                       centres: Sequence[Sequence[float]] = ()) -> tuple[np.ndarray, list]:
    """Cluster mean accelerometer vectors into orientations by the angle between them.

    Each vector joins the first known orientation within ``tolerance_deg`` of its
    direction, else starts a new one (with ``centres`` given, an unknown direction gets
    the label -1 instead: an orientation never seen in training is not guessed).

    Returns
    -------
    labels, centres
        Orientation index of each vector, and the unit vector of each orientation.

    Examples
    --------
    >>> labels, found = orientation_labels([[0, 0, 1], [0, 0.01, 1], [1, 0, 0]])
    >>> labels.tolist(), len(found)
    ([0, 0, 1], 2)
    """
    vectors = np.atleast_2d(np.asarray(vectors, dtype=np.float64))
    cosine = math.cos(math.radians(tolerance_deg))
    known = [np.asarray(c, dtype=np.float64) / np.linalg.norm(c) for c in centres]
    fixed = bool(known)
    labels = np.full(vectors.shape[0], -1, dtype=np.int64)
    for k, v in enumerate(vectors):
        norm = float(np.linalg.norm(v))
        if norm == 0.0:
            continue
        u = v / norm
        dots = [float(u @ c) for c in known]
        if dots and max(dots) >= cosine:
            labels[k] = int(np.argmax(dots))
        elif not fixed:
            known.append(u)
            labels[k] = len(known) - 1
    return labels, [c.tolist() for c in known]
