"""One axis's compensation: subtract its drift model from the gyro's output, chunk by chunk.

The streaming :class:`AxisCompensator` keeps one axis's causal df/dt filter state
between chunks, so a file of any size is compensated in bounded memory and any
chunking gives the batch result. It is the engine of
:class:`hrgtc.compensate.compensator.Compensator` (every axis of a model), used only
inside :mod:`hrgtc.compensate`. Eq. (22) of [1] applied as in Section 4.2 (Fig. 6).

Two engines compute the same numbers: ``"fused"`` (default) runs one compiled
pass per chunk (:mod:`hrgtc.compensate._kernel`, numba, imported on first use);
``"numpy"`` composes :mod:`hrgtc.drift.features`, :mod:`hrgtc.drift` and
:mod:`hrgtc.thermometry` array by array and is the reference the tests hold the
fused one to.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np

from hrgtc.compensate.ranges import RangeReport, range_report
from hrgtc.core.errors import CalibrationError, ExtrapolationWarning, HrgtcWarning, InputError
from hrgtc.core.timeline import RESTARTS_KEY, is_gap, restart_rows, settle_threshold_s
from hrgtc.drift import DriftModel
from hrgtc.drift.features import (
    LEVEL_VARIABLES,
    RATE_VARIABLES,
    FeatureStream,
    is_aux,
)
from hrgtc.drift.offsets import label_offsets, sample_offsets
from hrgtc.drift.rate_checks import filtered_levels, rate_filter_problems, warn_rate_filter
from hrgtc.drift.rate_filter import check_time, restart_mask
from hrgtc.model import AxisModel
from hrgtc.recording import Recording
from hrgtc.recording.gaps import check_gap_policy

#: Rows worked on at once: small enough for the temporaries to stay in cache.
BLOCK_ROWS = 1 << 17
#: Columns added by compensation.
OUTPUT_COLUMNS = ("rate_comp_dph", "bias_model_dph", "resonator_c_est", "in_range")
#: Column added when the model has a scale factor: its error at each sample's frequency.
SCALE_COLUMN = "scale_model_ppm"
#: Ways of computing them (see the module docstring).
ENGINES = ("fused", "numpy")


def output_columns(model: AxisModel) -> tuple[str, ...]:
    """Columns compensation of an axis with ``model`` adds (:data:`OUTPUT_COLUMNS`, and
    :data:`SCALE_COLUMN` when the axis has a scale factor)."""
    return OUTPUT_COLUMNS if model.scale_factor is None else (*OUTPUT_COLUMNS, SCALE_COLUMN)


def _in_training_range(
    model: DriftModel, values: Mapping[str, np.ndarray], variables: tuple[str, ...]
) -> np.ndarray:
    mask = np.ones(next(iter(values.values())).shape[0], dtype=bool)
    for variable in variables:
        if variable in model.ranges and variable in values:
            low, high = model.ranges[variable]
            x = values[variable]
            mask &= (x >= low) & (x <= high)
    return mask


class AxisCompensator:
    """Streaming compensation of consecutive chunks of one run, one axis.

    Parameters
    ----------
    model
        The axis's parts (thermometer + drift model, :class:`~hrgtc.model.AxisModel`).
    drift
        Which drift model to apply: ``"frequency"`` (the paper's, default) or
        ``"housing"`` (the classical thermistor baseline kept in the model file).
    engine
        ``"fused"`` (one compiled pass per chunk, default) or ``"numpy"`` (the
        array-by-array reference); both give the same numbers to rounding. A model
        with the heating/cooling switch ``dpos``, the second rate filter ``d2`` or an
        extra channel ``a_NAME`` runs on the numpy engine either way (the fused kernel
        computes f, df, h, dh and the gradient g only).
    gaps
        ``"split"``: the df/dt filter restarts at rest after every gap (a time step
        longer than :data:`~hrgtc.recording.validation.GAP_PERIODS` sample periods),
        as if each segment were its own run; any other policy (``"bridge"``,
        ``"error"``, ``"ignore"``, default): the filter is carried across the gap with
        the gap's Δt (each step of the filter uses the samples' times, also across
        chunks, so a gap on a chunk boundary is no different).

    """

    def __init__(self, model: AxisModel, drift: str = "frequency", engine: str = "fused",
                 gaps: str = "ignore") -> None:
        self.gaps = check_gap_policy(gaps)
        if engine not in ENGINES:
            raise InputError(f"engine must be 'fused' or 'numpy', got {engine!r}")
        if drift == "frequency":
            self.drift = model.drift
        elif drift == "housing":
            if model.housing is None:
                raise InputError(
                    "this model file has no housing-thermistor baseline (its training runs had "
                    "no housing_c column)"
                )
            self.drift = model.housing
        else:
            raise InputError(f"drift must be 'frequency' or 'housing', got {drift!r}")
        self.model = model
        #: Applied with the frequency drift model only (the housing baseline is bias only).
        self.scale_factor = model.scale_factor if drift == "frequency" else None
        self.engine = engine
        self._plan: Any = None
        self._variables = tuple(dict.fromkeys(("f", "df", *self.drift.variables)))
        self._levels = tuple(v for v in self._variables if v in LEVEL_VARIABLES or is_aux(v))
        self.reset()

    def reset(self) -> None:
        """Start a new run: the df/dt filter restarts at rest on the next sample."""
        self.restart()
        self._extremes = np.array([np.inf, -np.inf, np.inf, -np.inf])  # f, df min/max
        self.samples = 0
        self.out_of_range = 0
        self.rate_out_of_range = 0
        self.settling = 0
        self.temperature_nan = 0
        self.unknown_orientation = 0
        #: Samples beyond the trained temperature (calibrated frequencies or f's range).
        self.temperature_out = 0
        #: Per variable with a training range: [samples outside it, smallest, largest seen].
        self.variable_ranges: dict[str, list[float]] = {
            v: [0, np.inf, -np.inf] for v in self._variables if v in self.drift.ranges}
        self.segments = 1
        self._last_time: float | None = None

    def restart(self) -> None:
        """Restart the df/dt filter at rest on the next sample (after a gap); counts stay.

        The filter settles again: the first ``warmup_s`` after a restart are flagged
        ``in_range`` 0, as at the start of a run.
        """
        self._stream = FeatureStream(self.drift.settings, self._variables, self.model.thermometer)
        self._state: np.ndarray | None = None  # the fused engine's state (compensate._kernel)
        self._origin_s = math.nan  # time the filter (re)started (NaN: at the next sample)

    def _gap_rows(self, chunk: Recording) -> list[int]:
        """Rows of ``chunk`` that start a new segment (``gaps="split"``)."""
        time = chunk.time_s
        if not len(time):
            return []
        period = 1.0 / chunk.metadata.sample_rate_hz  # the package's one gap test:
        rows = (np.flatnonzero(is_gap(np.diff(time), period)) + 1).tolist()
        if self._last_time is not None and is_gap(time[0] - self._last_time, period):
            rows.insert(0, 0)
        self._last_time = float(time[-1])
        return rows

    def transform(self, chunk: Recording, at_rest: np.ndarray | None = None) -> Recording:
        """The next chunk of the run with the :data:`OUTPUT_COLUMNS` added.

        ``at_rest``: True for each sample of ``chunk`` at rest (the motion detector's
        mask, :class:`~hrgtc.compensate.at_rest.RestFlags`); None: all. A sample not at
        rest still gets an offset, but is not counted in :attr:`unknown_orientation` nor
        warned about: a unit mid-rotation is in no orientation (docs/real-loggers/motion.md).

        ``in_range`` is 1.0 where the frequency is inside the thermometer's calibrated
        range and the drift model's training range of f (and of h, g, a_NAME), df/dt (and
        dh/dt, d2) is inside its training range (a model trained on a cool-down has seen only
        negative df/dt), and the df/dt filter has settled (the first ``warmup_s`` of the
        run, which training leaves out too); else 0.0. The three are counted separately
        and each sample once: a settling sample in :attr:`settling` only, the settled
        ones outside a range in :attr:`out_of_range_fraction` and
        :attr:`rate_out_of_range_fraction`; :meth:`ranges` says how far the settled
        samples went. Large chunks
        are worked through in blocks of :data:`BLOCK_ROWS` rows, which keeps the
        temporaries in cache.
        """
        if self.samples == 0:
            if self.gaps != "split":  # split restarts the filter at each gap instead
                levels = filtered_levels(chunk, self.drift.variables)
                # up to a logger restart (the filter restarts there)
                head = restart_rows(chunk.time_s, chunk.metadata.extra.get(RESTARTS_KEY))
                stop = int(head[0]) if head.size else len(chunk)
                warn_rate_filter(rate_filter_problems(
                    chunk.time_s[:stop], {k: v[:stop] for k, v in levels.items()},
                    self.drift.settings.rate_tau_s, where=chunk.source or "",
                    thermometer_source=self.model.thermometer.source))
        restart = None
        cuts: list[int] = []
        if self.gaps == "split" and "time_s" in chunk:
            cuts = self._gap_rows(chunk)
            self.segments += len(cuts)
        if "time_s" in chunk:  # a logger restart is a new run: the filter restarts at rest
            rows = restart_rows(chunk.time_s, chunk.metadata.extra.get(RESTARTS_KEY))
            if self.samples == 0:
                rows = rows[rows > 0]
            cuts = sorted(set(cuts) | set(rows.tolist()))
        if cuts:  # the filters restart at rest on each segment's (run's) first row
            restart = restart_mask(len(chunk), cuts)
        return self._process(chunk, restart, at_rest)

    def _process(self, chunk: Recording, restart: np.ndarray | None = None,
                 at_rest: np.ndarray | None = None) -> Recording:
        n = len(chunk)
        out = {name: np.empty(n) for name in OUTPUT_COLUMNS}
        if not (self.engine == "fused" and self._fused(chunk, out, restart)):
            for start in range(0, n, BLOCK_ROWS):
                self._block(chunk.slice(start, start + BLOCK_ROWS), out, start,
                            None if restart is None else restart[start:start + BLOCK_ROWS])
        self._count_temperature_nan(out["resonator_c_est"], chunk)
        if "orientation" in self.drift.offset_mode:
            self._orientation_offsets(chunk, out, at_rest)
        if self.scale_factor is not None:
            # rate = input * (1 + k) + bias, so input = (rate - bias) / (1 + k).
            ppm = self.scale_factor.ppm(chunk.freq_hz)
            out[SCALE_COLUMN] = ppm
            out["rate_comp_dph"] /= 1.0 + 1e-6 * ppm
        return chunk.with_columns(**out)

    def _count_temperature_nan(self, estimate: np.ndarray, chunk: Recording) -> None:
        """Count NaN temperature estimates; warn at the first (once per compensator)."""
        bad = np.isnan(estimate)
        if not bad.any():
            return
        if not self.temperature_nan:
            i = int(np.argmax(bad))
            low, high = self.model.thermometer.temperature_range_c
            what = ("temperature" if self.model.thermometer.source == "sensor"
                    else "resonator temperature estimate resonator_c_est")
            row = self.samples - len(chunk) + i
            warnings.warn(
                f"{chunk.source or 'the run'}: the {what} is NaN from sample {row} "
                f"on (thermometer calibrated {low:.4g} to {high:.4g} °C; the inverse of f(T) "
                "is not extrapolated beyond it): those samples are flagged in_range = 0 and "
                "their compensation is an extrapolation of the drift model",
                ExtrapolationWarning, stacklevel=4)
        self.temperature_nan += int(np.count_nonzero(bad))

    def _orientation_offsets(self, chunk: Recording, out: dict[str, np.ndarray],
                             at_rest: np.ndarray | None = None) -> None:
        """Add each sample's trained orientation offset (:mod:`hrgtc.drift.offsets`) to the
        bias; an orientation never seen in training keeps the mean offset and is counted in
        :attr:`unknown_orientation` (and warned about once), not guessed. Samples not at
        rest (``at_rest`` False: handling, the accelerometer mid-rotation) keep it too but
        are not counted: they are flagged as motion instead."""
        axes = ("accel_x", "accel_y", "accel_z")
        labelled = not self.drift.orientations  # the user's orientation column
        readable = "orientation" in chunk if labelled else all(a in chunk for a in axes)
        if readable:
            if labelled:
                offset, unknown = label_offsets(self.drift.offsets_dph, chunk["orientation"])
            else:
                offset, unknown = sample_offsets(self.drift.offsets_dph, self.drift.orientations,
                                                 np.column_stack([chunk[a] for a in axes]))
            out["bias_model_dph"] += offset
            out["rate_comp_dph"] -= offset
        else:
            unknown = np.ones(len(chunk), dtype=bool)
        if at_rest is not None:
            if len(at_rest) != len(chunk):
                raise InputError(f"at_rest has {len(at_rest)} values for a chunk of "
                                 f"{len(chunk)} rows; give one per row")
            unknown = unknown & np.asarray(at_rest, dtype=bool)
        count = int(np.count_nonzero(unknown))
        if count and not self.unknown_orientation:
            spread = max(self.drift.offsets_dph.values()) - min(self.drift.offsets_dph.values())
            what = ("is in an orientation never seen in training" if readable else
                    "has no orientation column to tell its orientation" if labelled else
                    "has no accel_x/y/z columns to tell its orientation")
            warnings.warn(
                f"{chunk.source or 'the run'} {what}: its offset is unknown (the trained "
                f"orientations' offsets span {spread:.4g} °/h); the training mean is used and "
                "the compensated mean is uncertain by that much", HrgtcWarning, stacklevel=4)
        self.unknown_orientation += count

    def _fused(self, chunk: Recording, out: dict[str, np.ndarray],
               restart: np.ndarray | None = None) -> bool:
        """Compensate ``chunk`` into ``out`` with the kernel; False if it cannot (order > 5)."""
        from hrgtc.compensate import _kernel as kernel

        thermometer = self.model.thermometer
        if self._plan is None:
            violation = thermometer._monotonic_violation()
            if violation is not None:
                raise CalibrationError(violation)
            if not kernel.supports(thermometer) or not kernel.supports_variables(self._variables):
                return False  # the numpy engine computes the same numbers
            self._plan = kernel.plan(self.drift, thermometer, self._variables)
        counts = np.zeros(kernel.N_COUNTS, dtype=np.int64)
        freq = chunk.freq_hz
        housing = chunk["housing_c"] if self._plan.needs_housing else None
        if self._state is None:
            self._state = kernel.new_state()
        time_s = np.ascontiguousarray(chunk.time_s, dtype=np.float64)
        check_time(time_s, self._state[kernel.F_STATE])
        extremes = kernel.new_extremes()
        kernel.run(self._plan, self._state, (time_s, freq, chunk.rate_dph, housing), out, counts,
                   extremes, restart)
        self.samples += len(chunk)
        self._origin_s = float(self._state[kernel.ORIGIN])
        self.out_of_range += int(counts[kernel.OUT_OF_RANGE])
        self.rate_out_of_range += int(counts[kernel.RATE_OUT_OF_RANGE])
        self.settling += int(counts[kernel.SETTLING])
        self.temperature_out += int(counts[kernel.TEMPERATURE_OUT])
        if len(chunk):
            for v in self.variable_ranges:
                j = kernel.ORDER.index(v)
                self._track(v, int(counts[kernel.VARIABLE_OUT + j]), extremes[2 * j],
                            extremes[2 * j + 1])
            e = self._extremes
            e[0], e[1] = min(e[0], extremes[0]), max(e[1], extremes[1])
            e[2], e[3] = min(e[2], extremes[2]), max(e[3], extremes[3])
        return True

    def warm(self, chunk: Recording) -> None:
        """Load the fused kernel's compiled code for the types of ``chunk``'s columns,
        compensating nothing (their first 0 rows) and changing no state.

        :func:`~hrgtc.compensate.file_pass.compensate_file` calls it on a thread while the
        at-rest pass reads the file: numba's import and the loading of its cached
        dispatchers (some 0.5 s of CPU) then overlap that pass instead of delaying the
        first compensated chunk. The arrays are those :meth:`_fused` passes, so the types
        are the same and the first real call finds its code loaded
        (``tests/compensate/test_warm.py``). Does nothing where :meth:`_fused` would not
        run the kernel; raises what the kernel would raise on the chunk.
        """
        from hrgtc.compensate import _kernel as kernel

        thermometer = self.model.thermometer
        if (self.engine != "fused" or thermometer._monotonic_violation() is not None
                or not kernel.supports(thermometer)
                or not kernel.supports_variables(self._variables)):
            return
        block_plan = self._plan or kernel.plan(self.drift, thermometer, self._variables)
        none = slice(0, 0)
        freq = chunk.freq_hz[none]
        housing = chunk["housing_c"][none] if block_plan.needs_housing else freq
        time_s = np.ascontiguousarray(chunk.time_s, dtype=np.float64)[none]
        mask = np.zeros(0, dtype=np.int8)
        out = {name: np.empty(0) for name in OUTPUT_COLUMNS}
        columns = (time_s, mask, freq, chunk.rate_dph[none], housing)
        kernel._call(block_plan, kernel.new_state(), columns, out,
                     np.zeros(kernel.N_COUNTS, dtype=np.int64), kernel.new_extremes(), 0, 0)
        kernel.advance_filter(time_s, mask, freq, housing, block_plan.filter,
                              block_plan.uses_housing, kernel.new_state())

    def _settled(self, time_s: np.ndarray, restart: np.ndarray | None) -> np.ndarray:
        """True where the df/dt filter has settled: ``warmup_s`` seconds on the time axis since
        it (re)started (the run's first sample, or a restart row), as training's warm-up skip."""
        time_s = np.asarray(time_s, dtype=np.float64)
        if not time_s.size:
            return np.ones(0, dtype=bool)
        if math.isnan(self._origin_s):
            self._origin_s = float(time_s[0])
        origin = np.full(time_s.size, self._origin_s)
        if restart is not None and restart.any():  # the time of each row's (re)start
            rows = np.arange(time_s.size)
            last = np.maximum.accumulate(np.where(restart, rows, -1))
            origin = np.where(last >= 0, time_s[np.maximum(last, 0)], origin)
        self._origin_s = float(origin[-1])
        return time_s - origin >= settle_threshold_s(self.drift.settings.warmup_s)

    def _track(self, variable: str, outside: int, low: float, high: float) -> None:
        """Add a block's samples outside ``variable``'s range and its extremes."""
        kept = self.variable_ranges[variable]
        kept[0] += outside
        kept[1] = min(kept[1], float(low))
        kept[2] = max(kept[2], float(high))

    def _block(self, chunk: Recording, out: dict[str, np.ndarray], start: int,
               restart: np.ndarray | None = None) -> None:
        stop = start + len(chunk)
        values = self._stream.transform(chunk, restart)
        bias = self.drift.predict(values)
        thermometer = self.model.thermometer
        in_range = thermometer.in_range(chunk.freq_hz) & _in_training_range(
            self.drift, values, self._levels
        )
        rate_in_range = _in_training_range(self.drift, values, RATE_VARIABLES)
        temperature = thermometer.in_range(chunk.freq_hz) & _in_training_range(
            self.drift, values, ("f",))
        # a sample of the settling time is flagged by that reason only: the range counts
        # and the extremes seen are of the settled samples
        settled = self._settled(chunk.time_s, restart)
        self.temperature_out += int(np.count_nonzero(~temperature & settled))
        if len(chunk):
            for v in self.variable_ranges:
                x = values[v][settled]
                low, high = self.drift.ranges[v]
                outside = int(np.count_nonzero(~((x >= low) & (x <= high))))
                finite = np.isfinite(x).any()
                self._track(v, outside, np.nanmin(x) if finite else np.inf,
                            np.nanmax(x) if finite else -np.inf)
        np.subtract(chunk.rate_dph, bias, out=out["rate_comp_dph"][start:stop])
        out["bias_model_dph"][start:stop] = bias
        out["resonator_c_est"][start:stop] = thermometer.temperature(chunk.freq_hz, warn=False)
        out["in_range"][start:stop] = in_range & rate_in_range & settled
        self.samples += len(chunk)
        self.out_of_range += int(np.count_nonzero(~in_range & settled))
        self.rate_out_of_range += int(np.count_nonzero(~rate_in_range & settled))
        self.settling += int(np.count_nonzero(~settled))
        if settled.any():
            e = self._extremes
            for k, v in enumerate(("f", "df")):
                e[2 * k] = min(e[2 * k], float(np.min(values[v][settled])))
                e[2 * k + 1] = max(e[2 * k + 1], float(np.max(values[v][settled])))

    @property
    def out_of_range_fraction(self) -> float:
        """Share of the samples so far outside the calibrated temperature range or a level
        variable's training range (f, h, g, a_NAME), after the settling time (a settling
        sample is counted in :attr:`settling` only); :meth:`ranges` gives each apart."""
        return self.out_of_range / self.samples if self.samples else 0.0

    @property
    def rate_out_of_range_fraction(self) -> float:
        """Share of the samples so far, after the settling time, whose df/dt (dh/dt) is
        outside its training range."""
        return self.rate_out_of_range / self.samples if self.samples else 0.0

    def ranges(self) -> RangeReport:
        """Shares of the samples so far beyond the trained temperature and df/dt, how far."""
        df = self.variable_ranges.get("df", [self.rate_out_of_range])[0]
        counts = np.array([self.temperature_out, df, 0, self.settling])
        return range_report(self.drift, self.model.thermometer, self.samples, counts,
                            self._extremes, self.variable_ranges)

