"""One run of a campaign read once: its block means, raw and compensated, Earth rate removed.

:func:`read_series` streams a run's file chunk by chunk and keeps the means of
``block_s``-long blocks of time (since the run's first sample) of the bias
``rate_dph − Ω_E`` (Ω_E the Earth-rate component of the manifest), of the same after
compensation with the model (``rate_comp_dph − Ω_E``) and of the chosen temperature;
with ``keep_samples`` it keeps the samples too (the Allan deviation's run). A rate-table
run is read whole and gives its holds (:func:`hrgtc.drift.rate_segments.find_rate_segments`)
with the mean temperature of each.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.compensate import Compensator
from hrgtc.core.errors import InputError
from hrgtc.core.files import file_sha256
from hrgtc.drift.rate_segments import RateSegment, find_rate_segments
from hrgtc.drift.rest import RestPass, RunRest
from hrgtc.model import Model
from hrgtc.recording import ReadOptions, Recording
from hrgtc.testreport.manifest import RunEntry

__all__ = ["RunSeries", "read_series"]


@dataclass(frozen=True, eq=False)
class RunSeries:
    """A run's block means (and, where kept, its samples).

    Attributes
    ----------
    entry, sha256
        The manifest's run and the SHA-256 of its file.
    n_samples, sample_rate_hz
        Samples read and their rate. [-], [Hz]
    metadata_input_rate_dph
        The input rate the file's metadata states (compared with the manifest's Earth rate).
    time_s
        Start of each block, since the run's first sample. [s]
    bias_dph, compensated_dph
        Block means of the output less the Earth rate, raw and after compensation (None
        without a model). [°/h]
    temperature_c
        Block means of the temperature column. [°C]
    samples_dph, compensated_samples_dph
        The samples of the same (``keep_samples`` only). [°/h]
    segments, segment_temperature_c, segment_span_c
        A rate-table run's holds, the mean temperature of each and its span (max − min). [°C]
    mean_time_s
        Mean time of each block's samples, since the run's first sample (None: the block's
        middle): a rate of change of the block means is taken against it, so that a block
        a burst fills only in part is placed where its samples are. [s]
    n_moving
        Samples the motion detector found not at rest (``--motion exclude``, the default),
        left out of the block means.
    samples_at_rest
        True for each kept sample the motion detector found at rest (``keep_samples``
        only): the Allan deviation takes the longest stretch of them, :meth:`still_stretch`.
    """

    entry: RunEntry
    sha256: str
    n_samples: int
    sample_rate_hz: float
    metadata_input_rate_dph: float
    time_s: np.ndarray
    bias_dph: np.ndarray
    compensated_dph: np.ndarray | None
    temperature_c: np.ndarray
    samples_dph: np.ndarray | None = None
    compensated_samples_dph: np.ndarray | None = None
    segments: tuple[RateSegment, ...] = ()
    segment_temperature_c: tuple[float, ...] = ()
    segment_span_c: tuple[float, ...] = ()
    mean_time_s: np.ndarray | None = None
    n_moving: int = 0
    samples_at_rest: np.ndarray | None = None

    def still_stretch(self, first: int) -> tuple[int, int]:
        """Rows [start, stop) of the longest run of samples at rest from row ``first`` on
        (all of them without the detector's verdict; (first, first) if none is at rest)."""
        n = 0 if self.samples_dph is None else self.samples_dph.size
        if self.samples_at_rest is None:
            return first, max(first, n)
        padded = np.concatenate(([False], self.samples_at_rest[first:], [False]))
        edges = np.flatnonzero(padded[1:] != padded[:-1])
        if not edges.size:
            return first, first
        starts, stops = edges[0::2], edges[1::2]
        k = int(np.argmax(stops - starts))
        return first + int(starts[k]), first + int(stops[k])

    def sample_times_s(self) -> np.ndarray:
        """Where each block's samples are: their mean time (else the block's middle). [s]"""
        if self.mean_time_s is not None:
            return self.mean_time_s
        width = float(self.time_s[1] - self.time_s[0]) if self.time_s.size > 1 else 0.0
        return self.time_s + 0.5 * width

    def settle_s(self, default_s: float) -> float:
        """The time left out at the run's start: its own ``settle_s`` or ``default_s``. [s]"""
        return default_s if self.entry.settle_s is None else self.entry.settle_s

    def after(self, start_s: float, compensated: bool = False) -> np.ndarray:
        """Block means of the bias from ``start_s`` on (raw or compensated). [°/h]"""
        values = self.compensated_dph if compensated else self.bias_dph
        if values is None:
            raise InputError(f"{self.entry.name}: no compensated output without a model")
        return values[self.time_s >= start_s]


class _Blocks:
    """Sums and counts per block index, grown as chunks come."""

    def __init__(self, names: tuple[str, ...]) -> None:
        self.sums = {name: np.zeros(0) for name in names}
        self.counts = np.zeros(0)

    def add(self, index: np.ndarray, columns: dict[str, np.ndarray]) -> None:
        size = int(index.max()) + 1 if index.size else 0
        if size > self.counts.size:
            grow = size - self.counts.size
            self.counts = np.concatenate([self.counts, np.zeros(grow)])
            self.sums = {k: np.concatenate([v, np.zeros(grow)]) for k, v in self.sums.items()}
        self.counts[:size] += np.bincount(index, minlength=size)
        for name, values in columns.items():
            self.sums[name][:size] += np.bincount(index, weights=values, minlength=size)

    def means(self) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        kept = self.counts > 0
        return np.flatnonzero(kept), {k: v[kept] / self.counts[kept] for k, v in self.sums.items()}


def _temperature(chunk: Recording, column: str, entry: RunEntry) -> np.ndarray:
    if column not in chunk.names:
        raise InputError(f"{entry.path}: no column {column!r} for the temperature; the file has "
                         f"{', '.join(chunk.names)}; set [settings] temperature_column")
    return np.asarray(chunk[column], dtype=np.float64)


def read_series(entry: RunEntry, *, earth_rate_dph: float, block_s: float,
                temperature_column: str, model: Model | None = None,
                read_options: ReadOptions | None = None,
                keep_samples: bool = False) -> RunSeries:
    """Read one run (the module docstring says what is kept).

    Parameters
    ----------
    entry
        The run of the manifest.
    earth_rate_dph
        The Earth-rate component subtracted from the output. [°/h]
    block_s
        Block length. [s]
    temperature_column
        The temperature the block means keep. [°C]
    model
        The compensation model, or None.
    read_options
        How to read the file.
    keep_samples
        Keep the samples (for the Allan deviation).
    """
    options = read_options or ReadOptions()
    if entry.role == "rate-table":
        return _rate_table(entry, options, earth_rate_dph, block_s, temperature_column)
    columns, metadata, rest = _read_run(entry, options, earth_rate_dph, temperature_column,
                                        model)
    keep = rest.keep
    blocks = _Blocks(tuple(columns))
    blocks.add(np.floor(columns["time"][keep] / block_s).astype(np.int64),
               {name: values[keep] for name, values in columns.items()})
    index, means = blocks.means()
    return RunSeries(
        entry=entry, sha256=file_sha256(entry.path), n_samples=int(keep.size),
        sample_rate_hz=float(metadata.sample_rate_hz),
        metadata_input_rate_dph=float(metadata.input_rate_dph),
        time_s=index * float(block_s), bias_dph=means["bias"],
        compensated_dph=means.get("compensated"), temperature_c=means["temperature"],
        mean_time_s=means["time"], n_moving=rest.n_moving,
        samples_dph=columns["bias"] if keep_samples else None,
        compensated_samples_dph=columns.get("compensated") if keep_samples else None,
        samples_at_rest=keep if keep_samples else None)


def _read_run(entry: RunEntry, options: ReadOptions, earth_rate_dph: float,
              temperature_column: str, model: Model | None
              ) -> tuple[dict[str, np.ndarray], Any, RunRest]:
    """A run's samples (time since its first, bias, temperature, compensated) and the
    motion detector's verdict on them (``--motion``, as calibration and evaluation judge
    a run: handling is not the bias)."""
    compensator = None if model is None else Compensator(model)
    rest = RestPass(options.motion or "exclude", name=str(entry.path))
    parts: dict[str, list[np.ndarray]] = {}
    first, metadata = None, None
    for chunk in options.chunks(entry.path):
        time = np.asarray(chunk.time_s, dtype=np.float64)
        if first is None:
            first, metadata = float(time[0]), chunk.metadata
        rest.partial_fit(chunk)
        found = {"time": time - first, "temperature": _temperature(chunk, temperature_column,
                                                                   entry),
                 "bias": np.asarray(chunk.rate_dph, dtype=np.float64) - earth_rate_dph}
        if compensator is not None:
            found["compensated"] = np.asarray(compensator.transform(chunk)["rate_comp_dph"],
                                              np.float64) - earth_rate_dph
        for name, values in found.items():
            parts.setdefault(name, []).append(values)
    if metadata is None:
        raise InputError(f"{entry.path}: the recording holds no rows")
    return {k: np.concatenate(v) for k, v in parts.items()}, metadata, rest.finish()


def _rate_table(entry: RunEntry, options: ReadOptions, earth_rate_dph: float, block_s: float,
                temperature_column: str) -> RunSeries:
    recording = options.read(entry.path)
    if "input_rate_dph" not in recording.names:
        raise InputError(f"{entry.path}: a rate-table run needs the column input_rate_dph "
                         "(the table's known rate on the sensitive axis, Earth rate included)")
    temperature = _temperature(recording, temperature_column, entry)
    segments = find_rate_segments(recording)
    parts = [temperature[s.first_row:s.first_row + s.rows] for s in segments]
    time = np.asarray(recording.time_s, np.float64)
    blocks = _Blocks(("bias", "temperature"))
    blocks.add(np.floor((time - time[0]) / block_s).astype(np.int64),
               {"bias": np.asarray(recording.rate_dph, np.float64) - earth_rate_dph,
                "temperature": temperature})
    index, means = blocks.means()
    return RunSeries(
        entry=entry, sha256=file_sha256(entry.path), n_samples=len(recording),
        sample_rate_hz=float(recording.sample_rate_hz),
        metadata_input_rate_dph=float(recording.metadata.input_rate_dph),
        time_s=index * float(block_s), bias_dph=means["bias"], compensated_dph=None,
        temperature_c=means["temperature"], segments=segments,
        segment_temperature_c=tuple(float(np.mean(p)) for p in parts),
        segment_span_c=tuple(float(np.ptp(p)) for p in parts))
