"""The still samples of each training run, and the training data's own centre.

A drift model is trained on samples at rest (:mod:`hrgtc.recording.motion`). Before
the window means are taken, one pass over each run reads only the columns the
detector needs (time, rate, known input rate, accelerometer axes), marks the
samples not at rest, and at the same time measures the centre of the frequency
(or temperature-sensor) channel over the still samples after the warm-up: the
drift terms are centred on it, so a model does not depend on an arbitrary
temperature offset (``--temp-offset``) or reference temperature.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hrgtc.core.errors import CalibrationError, InputError
from hrgtc.recording.motion import (
    ACCEL_COLUMNS,
    MOTION_POLICIES,
    MotionMask,
    MotionSettings,
    detect_motion,
)


@dataclass(frozen=True, eq=False)
class RunRest:
    """What the pre-pass found in one training run.

    Attributes
    ----------
    source
        The run's name.
    keep
        True for each sample the fit may use (all True with ``--motion keep``).
    mask
        The detector's result (None when motion is kept unchecked).
    freq_sum, freq_count
        Sum and number of the still ``freq_hz`` values after the warm-up (the centre).
    accel
        Whether the run logs the three accelerometer axes.
    duration_s
        From the run's first to its last sample (NaN without any). [s]
    """

    source: str
    keep: np.ndarray
    mask: MotionMask | None = None
    freq_sum: float = 0.0
    freq_count: int = 0
    accel: bool = False
    counts: dict[str, int] = field(default_factory=dict)
    duration_s: float = math.nan

    @property
    def n_moving(self) -> int:
        return int(np.count_nonzero(~self.keep))


def check_policy(policy: str) -> str:
    """``policy`` if it is one of :data:`MOTION_POLICIES`, else an error naming them."""
    if policy not in MOTION_POLICIES:
        raise InputError(f"motion policy {policy!r} is not known; use one of "
                         f"{', '.join(MOTION_POLICIES)} (--motion)")
    return policy


class RestPass:
    """:func:`run_rest` a chunk at a time: the detector's columns gathered as they come.

    The columns go into buffers of ``rows`` samples (grown if a run has more), so the
    chunks are not held: the memory is the columns once (a fresh large array costs
    its page faults, ``docs/benchmarks.md``). Parameters as :func:`run_rest`'s, and
    ``in_place``: the detector subtracts the input rate from the ``rate_dph`` buffer itself
    (no second array of the run's length), so that :attr:`columns` then holds the rate the
    detector read (:func:`hrgtc.recording.motion.detector_rate`), not the file's.
    """

    #: The columns gathered (those of them a chunk has).
    WANTED = ("time_s", "rate_dph", "freq_hz", "input_rate_dph", *ACCEL_COLUMNS)

    def __init__(self, policy: str = "exclude", settings: MotionSettings | None = None,
                 warmup_s: float = 0.0, name: str = "", rows: int | None = None,
                 in_place: bool = False) -> None:
        self.policy = check_policy(policy)
        self.settings, self.warmup_s, self.source = settings, warmup_s, name
        self.in_place = in_place
        self.rows = max(int(rows or 0), 0)
        self.input_rate = 0.0
        self._buffers: dict[str, np.ndarray] = {}
        self._filled: dict[str, int] = {}

    def partial_fit(self, chunk: Any) -> RestPass:
        """Add the detector's columns of the next chunk."""
        if not self.source:
            self.source = chunk.source or "run"
        if not self._buffers:
            self.input_rate = chunk.metadata.input_rate_dph
        for column in self.WANTED:
            if column not in chunk:
                continue
            values = np.asarray(chunk[column], dtype=np.float64)
            buffer = self._buffers.get(column)
            filled = self._filled.get(column, 0)
            if buffer is None or filled + values.size > buffer.size:
                grown = np.empty(max(self.rows, filled + values.size,
                                     0 if buffer is None else 2 * buffer.size))
                if buffer is not None:
                    grown[:filled] = buffer[:filled]
                buffer = self._buffers[column] = grown
            buffer[filled:filled + values.size] = values
            self._filled[column] = filled + values.size
        return self

    @property
    def columns(self) -> dict[str, np.ndarray]:
        """The columns gathered so far (views of the buffers; :meth:`finish` drops the
        buffers, not these views)."""
        return {k: b[:self._filled[k]] for k, b in self._buffers.items()}

    def finish(self) -> RunRest:
        """The run's still samples and still ``freq_hz`` centre (see :func:`run_rest`)."""
        return self.finish_each((self.warmup_s,))[0]

    def finish_each(self, warmups_s: Sequence[float]) -> list[RunRest]:
        """:meth:`finish` for each warm-up of ``warmups_s`` (the detector runs once: only
        the centre depends on the warm-up)."""
        columns = self.columns
        self._buffers, self._filled = {}, {}
        return _run_rest(columns, self.policy, self.settings, warmups_s, self.source,
                         self.input_rate, self.in_place)


def run_rest(chunks: Any, policy: str = "exclude", settings: MotionSettings | None = None,
             warmup_s: float = 0.0, name: str = "", rows: int | None = None) -> RunRest:
    """One pass over a run's chunks: its still samples and its still ``freq_hz`` centre.

    Parameters
    ----------
    chunks
        The run's consecutive :class:`~hrgtc.recording.Recording` chunks.
    policy
        ``"exclude"`` (moving samples are left out), ``"keep"`` (no detection: every
        sample is used) or ``"error"`` (moving samples are an error naming the run).
    settings
        The detector's settings.
    warmup_s
        Start of the run left out of the centre (the df/dt filter settling). [s]
    rows
        The run's rows if known (the buffers are sized once; a guess is grown).
    """
    rest = RestPass(policy, settings, warmup_s, name, rows)
    for chunk in chunks:
        rest.partial_fit(chunk)
    return rest.finish()


def _run_rest(columns: dict[str, np.ndarray], policy: str, settings: MotionSettings | None,
              warmups_s: Sequence[float], source: str, input_rate: float,
              in_place: bool = False) -> list[RunRest]:
    if not columns:
        return [RunRest(source, np.zeros(0, dtype=bool)) for _ in warmups_s]
    time_s = columns["time_s"]
    accel = all(c in columns for c in ACCEL_COLUMNS)
    mask = None
    keep = np.ones(time_s.size, dtype=bool)
    if policy != "keep":
        mask = detect_motion(
            time_s, {"rate_dph": columns["rate_dph"]},
            accel={c: columns[c] for c in ACCEL_COLUMNS if c in columns} or None,
            input_rate=columns.get("input_rate_dph", input_rate), settings=settings,
            overwrite=in_place)
        keep = mask.still
        if policy == "error" and mask.n_moving:
            first = int(np.flatnonzero(mask.moving)[0])
            raise CalibrationError(
                f"{source}: {mask.n_moving} of {mask.n_samples} samples are not at rest "
                f"(first at row {first}, t = {time_s[first]:g} s; {mask.summary()}); the drift "
                "model is a law of the gyro at rest: cut the handling out, or pass --motion "
                "exclude (leave them out, counted) or --motion keep (train on them)")
    out = []
    freq = columns.get("freq_hz")
    counts = {} if mask is None else mask.counts()
    for warmup_s in warmups_s:
        total, used = 0.0, 0
        if freq is not None:  # no centre to measure (compensate): no masks of the run's length
            still = keep & (time_s >= time_s[0] + warmup_s)
            total, used = float(np.sum(freq[still])), int(np.count_nonzero(still))
        out.append(RunRest(source, keep, mask, total, used, accel, dict(counts),
                           float(time_s[-1] - time_s[0]) if time_s.size else math.nan))
    return out


def training_centre(rests: Sequence[RunRest]) -> float | None:
    """Mean ``freq_hz`` of the still samples after the warm-up of all runs (None: none)."""
    count = sum(r.freq_count for r in rests)
    if count == 0:
        return None
    return sum(r.freq_sum for r in rests) / count


def check_long_enough(rests: Sequence[RunRest], warmup_s: float) -> None:
    """Refuse training runs that all end within the df/dt filter's warm-up: too short,
    not "no sample at rest" (issue 27's audit: a 2-10-row file), naming each run, its
    rows and the rows it would need at its own rate."""
    short = [r for r in rests if not r.duration_s > warmup_s]
    if not rests or len(short) < len(rests):
        return
    parts = []
    for run in short:
        rows = run.keep.size
        period = run.duration_s / (rows - 1) if rows > 1 and run.duration_s > 0 else math.nan
        needed = (f"; at its {1.0 / period:.4g} Hz, more than {math.ceil(warmup_s / period) + 1} "
                  "rows" if math.isfinite(period) else "")
        duration = f"{run.duration_s:g} s" if math.isfinite(run.duration_s) else "no time"
        parts.append(f"{run.source}: {rows} rows ({duration}) is too short to train on{needed}")
    raise CalibrationError(
        "; ".join(parts) + f": a drift run must last longer than the {warmup_s:g} s warm-up "
        "of the df/dt filter (left out of the fit), in practice hours of a temperature ramp")


def reference_point(rests: Sequence[RunRest], thermometer: Any, reference_c: float | None,
                    warmup_s: float = 0.0) -> tuple[float, float]:
    """``(f_ref [Hz], reference temperature [°C])`` of a drift fit.

    With ``reference_c`` None, the centre of the still training samples (not a fixed
    20 °C): the model then does not depend on an arbitrary temperature offset or scale.
    f_ref is ``thermometer.frequency(reference_c)`` either way (the model file's
    integrity check), the centre to the thermometer's round trip.
    """
    if reference_c is None:
        centre = training_centre(rests)
        if centre is None:
            check_long_enough(rests, warmup_s)
            raise CalibrationError("the drift runs hold no sample at rest after the "
                                   f"{warmup_s:g} s warm-up; see --motion")
        reference_c = float(thermometer.temperature(np.array([centre]), warn=False)[0])
        if not math.isfinite(reference_c):
            reference_c = float(np.mean(thermometer.temperature_range_c))
    return float(thermometer.frequency(reference_c)), float(reference_c)
