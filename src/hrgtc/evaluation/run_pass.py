"""How much better the gyro got: bias stability and Allan noise terms, raw vs compensated.

Section 4.2 of [1] reports the 1-sigma bias stability of a cool-down run before
(3.0143 °/h) and after (0.5848 °/h) compensation. :func:`evaluate` computes the
same figure at 1, 10 and 100 s for any run and model, the Allan noise terms
before and after, the share of samples outside the calibrated ranges, and,
where the run has a housing thermistor and the model keeps the classical
baseline, the same figures for compensation by housing temperature, so the
frequency method can be compared with the thermistor method. Simulated runs
carry the true bias; the model's residual against it is reported too.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hrgtc import recording as rec
from hrgtc.compensate import Compensator
from hrgtc.errors import InputError
from hrgtc.evaluation.metrics import allan_deviation, bias_stability, noise_terms
from hrgtc.model import UnitModel
from hrgtc.progress import Progress

DEFAULT_TAUS_S = (1.0, 10.0, 100.0)


def _clean(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _stability_table(rate_dph: np.ndarray, rate_hz: float, taus_s: Sequence[float]
                     ) -> dict[str, float | None]:
    """Bias stability at each tau; None where fewer than two blocks fit."""
    out: dict[str, float | None] = {}
    for tau in taus_s:
        blocks = rate_dph.size // max(1, round(tau * rate_hz))
        out[f"{tau:g}"] = bias_stability(rate_dph, rate_hz, tau) if blocks >= 2 else None
    return out


def _noise(rate_dph: np.ndarray, rate_hz: float) -> dict[str, Any]:
    terms = noise_terms(allan_deviation(rate_dph, rate_hz, taus="octave"))
    return {k: (_clean(v) if isinstance(v, float) else v) for k, v in terms.to_dict().items()}


@dataclass(frozen=True)
class Evaluation:
    """Raw vs compensated performance of one run.

    Attributes
    ----------
    file
        Name of the run.
    n_samples, sample_rate_hz
        Size and rate of the run. [-, Hz]
    bias_stability_dph
        ``{"raw"|"compensated"|"housing": {"1": ..., "10": ..., "100": ...}}``
        (``"housing"`` only with a housing baseline and ``housing_c``). [°/h]
    allan
        Noise terms (ARW, bias instability, RRW) of the same series, or empty.
    out_of_range_fraction
        Share of samples outside the calibrated temperature ranges.
    rate_out_of_range_fraction
        Share of samples whose df/dt is outside its training range.
    residual_rms_dph
        RMS of true bias minus model bias (simulated runs only). [°/h]
    """

    file: str
    n_samples: int
    sample_rate_hz: float
    bias_stability_dph: dict[str, dict[str, float | None]]
    allan: dict[str, dict[str, Any]]
    out_of_range_fraction: float
    rate_out_of_range_fraction: float
    residual_rms_dph: float | None = None

    @property
    def raw_10s(self) -> float:
        """10 s bias stability of the raw output. [°/h]"""
        return float(self.bias_stability_dph["raw"]["10"])  # type: ignore[arg-type]

    @property
    def compensated_10s(self) -> float:
        """10 s bias stability of the compensated output. [°/h]"""
        return float(self.bias_stability_dph["compensated"]["10"])  # type: ignore[arg-type]

    @property
    def improvement_10s(self) -> float:
        """raw / compensated 10 s bias stability."""
        return self.raw_10s / self.compensated_10s

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (the layout of ``hrgtc evaluate --json``)."""
        table = {k: dict(v) for k, v in self.bias_stability_dph.items()}
        table.setdefault("housing", None)  # type: ignore[arg-type]
        return {
            "file": self.file,
            "n_samples": self.n_samples,
            "sample_rate_hz": self.sample_rate_hz,
            "bias_stability_dph": table,
            "bias_stability_10s_dph": {"raw": self.raw_10s, "compensated": self.compensated_10s},
            "improvement_10s": self.improvement_10s,
            "allan": self.allan,
            "out_of_range_fraction": self.out_of_range_fraction,
            "rate_out_of_range_fraction": self.rate_out_of_range_fraction,
            "residual_rms_dph": self.residual_rms_dph,
        }

    def summary(self) -> str:
        """A small text table."""
        def fmt(v: float | None) -> str:
            return "    -   " if v is None else f"{v:8.4f}"

        taus = list(self.bias_stability_dph["raw"])
        lines = [f"{self.file}: {self.n_samples} samples at {self.sample_rate_hz:g} Hz",
                 "bias stability [°/h]  " + "".join(f"{t + ' s':>9}" for t in taus)]
        for name, row in self.bias_stability_dph.items():
            lines.append(f"  {name:<19}" + "".join(f" {fmt(row[t])}" for t in taus))
        lines.append(f"improvement at 10 s: {self.improvement_10s:.2f}×; out of calibrated range: "
                     f"{self.out_of_range_fraction:.1%} (df/dt beyond training: "
                     f"{self.rate_out_of_range_fraction:.1%})")
        if self.residual_rms_dph is not None:
            lines.append(f"RMS of true bias minus model: {self.residual_rms_dph:.4f} °/h")
        return "\n".join(lines)


def evaluate_chunks(
    model: UnitModel,
    chunks: Iterable[rec.Recording],
    name: str,
    *,
    taus_s: Sequence[float] = DEFAULT_TAUS_S,
    allan: bool = True,
    progress: Progress | None = None,
) -> Evaluation:
    """Evaluate one run given as consecutive chunks (see :func:`evaluate`)."""
    frequency = Compensator(model)
    housing = Compensator(model, "housing") if model.housing is not None else None
    raw, compensated, by_housing, truth = [], [], [], []
    rate_hz: float | None = None
    input_rate = 0.0
    for chunk in chunks:
        if rate_hz is None:
            rate_hz = chunk.metadata.sample_rate_hz
            input_rate = chunk.metadata.input_rate_dph
            if housing is not None and "housing_c" not in chunk:
                housing = None
        out = frequency.process(chunk)
        raw.append(chunk.rate_dph - input_rate)
        compensated.append(out["rate_comp_dph"] - input_rate)
        if housing is not None:
            by_housing.append(housing.process(chunk)["rate_comp_dph"] - input_rate)
        if "bias_dph" in chunk:
            truth.append(chunk["bias_dph"] - out["bias_model_dph"])
        if progress is not None:
            progress(frequency.samples, 0)
    if rate_hz is None:
        raise InputError(f"{name}: the run holds no samples")
    series = {"raw": np.concatenate(raw), "compensated": np.concatenate(compensated)}
    if by_housing:
        series["housing"] = np.concatenate(by_housing)
    n = series["raw"].size
    if n < 2 * round(10.0 * rate_hz):
        raise InputError(f"{name}: {n / rate_hz:.1f} s is too short for a 10 s bias stability "
                         "(it needs at least 20 s)")
    table = {k: _stability_table(v, rate_hz, taus_s) for k, v in series.items()}
    noise = {k: _noise(v, rate_hz) for k, v in series.items()} if allan else {}
    residual = float(np.sqrt(np.mean(np.concatenate(truth) ** 2))) if truth else None
    return Evaluation(name, n, float(rate_hz), table, noise, frequency.out_of_range_fraction,
                      frequency.rate_out_of_range_fraction, residual)


def evaluate(
    run: rec.Recording | str | os.PathLike[str],
    model: UnitModel,
    *,
    taus_s: Sequence[float] = DEFAULT_TAUS_S,
    allan: bool = True,
    columns: Any = None,
    units: Any = None,
    metadata: Any = None,
    chunk_rows: int = 1_000_000,
    progress: Progress | None = None,
) -> Evaluation:
    """Raw vs compensated bias stability, Allan noise terms and range shares of one run.

    Parameters
    ----------
    run
        A :class:`~hrgtc.recording.Recording` or a file, read chunk by chunk.
    model
        The unit's model.
    taus_s
        Averaging times of the bias stability (Section 4.2 of [1] uses 10 s). [s]
    allan
        Also compute the Allan noise terms (ARW, bias instability, RRW).
    columns, units, metadata
        Reading options for files (see :func:`hrgtc.recording.read`).
    """
    if isinstance(run, rec.Recording):
        return evaluate_chunks(model, [run], Path(run.source or "recording").name,
                               taus_s=taus_s, allan=allan, progress=progress)
    chunks = rec.iter_chunks(run, rows=chunk_rows, columns=columns, units=units,
                             metadata=metadata)
    return evaluate_chunks(model, chunks, Path(run).name, taus_s=taus_s, allan=allan,
                           progress=progress)
