"""Evaluation metrics: bias stability, Allan deviation and the Allan noise terms.

The paper [1] judges a compensation by the bias stability of the gyro output
(Section 4.2 of [1]: 3.0143 -> 0.5848 °/h); DESIGN.md adds the Allan deviation
and the three noise terms that gyro data sheets quote.

- :func:`bias_stability`: 1σ of non-overlapping τ-second means, in °/h.
- :func:`allan_deviation` from :mod:`hrgtc.evaluation.allan`, :func:`noise_terms` from
  :mod:`hrgtc.evaluation.noise`.
- :func:`residual_against_truth`: how well a bias model tracks the simulator's
  true bias.

[1] X. Wang et al., Sensors 12(5), 6434-6446, 2012. doi:10.3390/s120506434
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from hrgtc.core import records
from hrgtc.core.errors import InputError
from hrgtc.core.records import Count, Record, Statistic
from hrgtc.core.summary import Figure, Summary
from hrgtc.evaluation.allan import (
    FLICKER_FLOOR_FACTOR,
    ONE_SIGMA,
    SECONDS_PER_HOUR,
    TAU_SPACINGS,
    AllanResult,
    _as_rate,
    _block_length,
    _check_sample_rate,
    allan_deviation,
    confidence_interval,
)
from hrgtc.evaluation.noise import NoiseTerms, noise_terms
from hrgtc.settings.compensation import BIAS_STABILITY_TAUS_S

__all__ = [
    "DEFAULT_TAUS_S", "FLICKER_FLOOR_FACTOR", "SECONDS_PER_HOUR", "TAU_SPACINGS",
    "AllanResult", "NoiseTerms", "ResidualResult", "allan_deviation", "bias_stability",
    "bias_stability_interval", "bias_stability_intervals", "bias_stability_table",
    "noise_terms", "residual_against_truth", "table_from_json",
    "table_to_json",
]

#: Averaging times of every bias-stability table (docs/method.md, "Metrics"). [s]
DEFAULT_TAUS_S = BIAS_STABILITY_TAUS_S


# --------------------------------------------------------------------------- bias stability
def _bias_stability(rate: np.ndarray, m: int) -> float:
    blocks = rate.size // m
    if blocks < 2:
        return math.nan
    means = rate[: blocks * m].reshape(blocks, m).mean(axis=1)
    return float(np.std(means, ddof=1))


def bias_stability(rate_dph: Any, sample_rate_hz: float, tau_s: float = 10.0) -> float:
    """Bias stability: 1σ of non-overlapping τ-second means of the rate.

    The figure of merit of Section 4.2 of [1] (3.0143 -> 0.5848 °/h at 10 s);
    definition of DESIGN.md: the record is cut into ``floor(N / m)`` blocks of
    ``m = round(tau_s * sample_rate_hz)`` samples (the incomplete last block is
    dropped), each block is averaged, and the sample standard deviation
    (``ddof=1``) of the block means is returned. A constant input rate does not
    change the result.

    Parameters
    ----------
    rate_dph
        Gyro output or bias, one value per sample. [°/h]
    sample_rate_hz
        Sample rate. [Hz]
    tau_s
        Averaging time. [s]

    Returns
    -------
    float
        Bias stability (1σ). [°/h]

    Raises
    ------
    InputError
        If fewer than two whole blocks fit in the record, or the input is not
        finite and 1-D.

    Examples
    --------
    >>> bias_stability([1.0, 3.0, 5.0, 7.0, 9.0, 11.0, 99.0], sample_rate_hz=1.0, tau_s=2.0)
    4.0
    """
    fs = _check_sample_rate(sample_rate_hz)
    rate = _as_rate(rate_dph, "rate_dph")
    m = _block_length(tau_s, fs)
    if rate.size // m < 2:
        raise InputError(
            f"bias stability at tau_s={tau_s:g} s needs at least 2 blocks of {m} samples, but "
            f"rate_dph has only {rate.size} samples ({rate.size / fs:g} s); use a shorter "
            "tau_s or a longer record"
        )
    return _bias_stability(rate, m)


def bias_stability_table(
    rate_dph: Any, sample_rate_hz: float, taus_s: Iterable[float] = DEFAULT_TAUS_S
) -> dict[float, float]:
    """Bias stability ``{tau_s: value}`` at several averaging times [s] -> [°/h].

    As :func:`bias_stability` (same arguments, ``taus_s`` in [s]), except that a
    τ for which fewer than two blocks fit gives NaN instead of an error (render
    it as "n/a" or JSON null).
    """
    fs = _check_sample_rate(sample_rate_hz)
    rate = _as_rate(rate_dph, "rate_dph")
    return {float(tau): _bias_stability(rate, _block_length(tau, fs)) for tau in taus_s}


def bias_stability_interval(
    value_dph: float, blocks: int, confidence: float = ONE_SIGMA
) -> tuple[float, float]:
    """Chi-squared confidence interval of a bias stability (1σ of ``blocks`` block means).

    The block means of a record whose bias varies as white noise at τ are
    independent, so ``(blocks − 1)·s²/σ²`` follows χ² with ``blocks − 1`` degrees
    of freedom (SP 1065 Eq. 45 with edf = blocks − 1): ``σ`` lies between
    ``s·√((k−1)/χ²(1 − p/2))`` and ``s·√((k−1)/χ²(p/2))``, p = 1 − confidence. Drift
    makes the block means correlated and the interval too narrow; it is a statement
    about noise, not about a ramp.

    Parameters
    ----------
    value_dph
        Bias stability from :func:`bias_stability`. [°/h]
    blocks
        Number of block means it was computed from (``floor(N / m)``).
    confidence
        Two-sided level in (0, 1), :data:`ONE_SIGMA` (0.683) by default.

    Returns
    -------
    lower, upper : float
        NaN for fewer than two blocks or a NaN value. [°/h]

    Examples
    --------
    >>> low, high = bias_stability_interval(1.0, blocks=101)
    >>> round(low, 3), round(high, 3)
    (0.936, 1.079)
    """
    if blocks < 2 or not math.isfinite(value_dph):
        return math.nan, math.nan
    lower, upper = confidence_interval(value_dph, blocks - 1, confidence)
    return float(lower), float(upper)


def bias_stability_intervals(
    table: Mapping[float, float], n_samples: int, sample_rate_hz: float,
    confidence: float = ONE_SIGMA,
) -> dict[float, tuple[float, float]]:
    """:func:`bias_stability_interval` of each τ of a table of a record of ``n_samples``."""
    fs = _check_sample_rate(sample_rate_hz)
    return {tau: bias_stability_interval(value, n_samples // _block_length(tau, fs), confidence)
            for tau, value in table.items()}


def table_to_json(table: Mapping[float, float]) -> dict[str, float | None]:
    """A bias-stability table as JSON: τ keys as text (``"10"``), NaN as None."""
    return {f"{tau:g}": None if math.isnan(v) else float(v) for tau, v in table.items()}


def table_from_json(data: Mapping[str, float | None]) -> dict[float, float]:
    """Inverse of :func:`table_to_json`."""
    return {float(tau): math.nan if v is None else float(v) for tau, v in data.items()}


# --------------------------------------------------------------------------- residual vs truth
@dataclass(frozen=True)
class ResidualResult:
    """Error of a bias model against the true bias (simulator ground truth).

    Attributes
    ----------
    rms_dph
        Root mean square of ``bias_model − true_bias``. [°/h]
    mean_dph
        Mean of the residual. [°/h]
    max_abs_dph
        Largest absolute residual. [°/h]
    bias_stability_dph
        Bias stability of the residual at each τ (NaN where < 2 blocks fit). [s] -> [°/h]
    n_samples
        Number of samples.
    """

    rms_dph: float
    mean_dph: float
    max_abs_dph: float
    bias_stability_dph: dict[float, float]
    n_samples: int

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types (:class:`ResidualRecord`; τ keys as text, NaN as None)."""
        return records.dump(self, ResidualRecord,
                            bias_stability_dph=table_to_json(self.bias_stability_dph))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> ResidualResult:
        """Inverse of :meth:`to_dict`."""
        values = records.load(data, ResidualRecord, "model-residual")
        return cls(**{**values, "bias_stability_dph": table_from_json(
            values["bias_stability_dph"])})

    def summary(self) -> Summary:
        """RMS, mean and largest model − true bias, and its bias stability at each τ
        (its text: two lines)."""
        error = (Figure("n_samples", "samples", self.n_samples),
                 Figure("rms_dph", "RMS", self.rms_dph, "deg/h", digits=4,
                        definition="Root mean square of bias model − true bias."),
                 Figure("mean_dph", "mean", self.mean_dph, "deg/h", digits=4,
                        definition="Mean of bias model − true bias."),
                 Figure("max_abs_dph", "max |.|", self.max_abs_dph, "deg/h", digits=4,
                        definition="Largest |bias model − true bias|."))
        stability = tuple(Figure(f"bias_stability_dph.{tau:g}", f"{tau:g} s", value, "deg/h",
                                 digits=4, definition=f"1σ of the {tau:g} s means of bias "
                                 "model − true bias.")
                          for tau, value in self.bias_stability_dph.items())
        return Summary("model - true bias", (("model - true bias", error),
                                             ("bias stability of the residual", stability)),
                       layout=("model - true bias over {n_samples} samples: rms {rms_dph:.4g} "
                               "deg/h, mean {mean_dph:.4g} deg/h, max |.| {max_abs_dph:.4g} deg/h",
                               "bias stability of the residual [deg/h]: " + ", ".join(
                                   f"{tau:g} s: {{bias_stability_dph.{tau:g}:.4g}}"
                                   for tau in self.bias_stability_dph)))


#: A bias-stability table as JSON: τ as text (``"10"``) -> 1σ, null where not estimable. [°/h]
StabilityTable = dict[str, Statistic]


class ResidualRecord(Record):
    """The record of :class:`ResidualResult` (its ``to_dict``, ``from_dict``)."""

    rms_dph: Statistic
    mean_dph: Statistic
    max_abs_dph: Statistic
    bias_stability_dph: StabilityTable
    n_samples: Count


def residual_against_truth(
    *,
    bias_model_dph: Any,
    true_bias_dph: Any,
    sample_rate_hz: float,
    taus_s: Iterable[float] = DEFAULT_TAUS_S,
) -> ResidualResult:
    """How well a bias model tracks the true bias: statistics of ``bias_model − true_bias``.

    With ``compensated = rate − bias_model`` (Section 4.2 of [1]) and
    ``rate = input_rate + true_bias (+ noise)``, the bias left in the compensated
    output is ``compensated − input_rate = true_bias − bias_model (+ noise)``,
    the negative of this residual. Pass the ``bias_model_dph`` column of a
    compensated recording and the simulator's ``bias_dph`` column; keyword-only,
    so the two cannot be swapped. If the true bias excludes the noise, the
    residual is the pure model error.

    Parameters
    ----------
    bias_model_dph
        Bias predicted by the model. [°/h]
    true_bias_dph
        True bias (simulator ground truth, column ``bias_dph``). [°/h]
    sample_rate_hz
        Sample rate. [Hz]
    taus_s
        Averaging times of the bias-stability table. [s]

    Returns
    -------
    ResidualResult
        RMS, mean, maximum and bias stabilities of the residual.
    """
    fs = _check_sample_rate(sample_rate_hz)
    model = _as_rate(bias_model_dph, "bias_model_dph")
    truth = _as_rate(true_bias_dph, "true_bias_dph")
    if model.shape != truth.shape:
        raise InputError(
            f"bias_model_dph has {model.size} samples but true_bias_dph has {truth.size}; "
            "pass the two columns of the same recording"
        )
    residual = model - truth
    return ResidualResult(
        rms_dph=float(np.sqrt(np.mean(residual * residual))),
        mean_dph=float(residual.mean()),
        max_abs_dph=float(np.max(np.abs(residual))),
        bias_stability_dph=bias_stability_table(residual, fs, taus_s),
        n_samples=int(residual.size),
    )
