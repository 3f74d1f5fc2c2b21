"""Settings of compensation and evaluation (stages 3-4): chunks, deviation curve, report."""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.settings import setting

#: Rows of one Parquet row group of the files hrgtc writes, and rows per chunk when a file
#: is compensated: chunks are read without joining batches and written without waiting for
#: the next chunk.
ROW_GROUP_ROWS = 1 << 20
#: Deviation curves of the evaluation (:mod:`hrgtc.evaluation.deviation_curves`).
DEVIATIONS = ("oadev", "adev", "mdev", "hdev", "tdev")
#: Averaging times of the bias stability an evaluation reports. [s]
BIAS_STABILITY_TAUS_S = (1.0, 10.0, 100.0)
#: The 1σ two-sided level, erf(1/√2): the intervals' default coverage.
ONE_SIGMA = 0.6826894921370859


@dataclass(frozen=True)
class CompensateSettings:
    """How ``hrgtc compensate`` streams a file (:func:`hrgtc.compensate.compensate_file`)."""

    chunk_rows: int = setting(ROW_GROUP_ROWS, "Rows per processing chunk.")


@dataclass(frozen=True)
class EvaluationSettings:
    """How ``hrgtc evaluate`` measures a run (:func:`hrgtc.evaluation.evaluate`)."""

    deviation: str = setting(
        "oadev", "Deviation curve: oadev (overlapping Allan), adev (non-overlapping), mdev "
        "(modified), hdev (Hadamard), tdev (time). Noise terms come from adev/oadev.",
        choices=DEVIATIONS)
    taus_s: tuple[float, ...] = setting(
        BIAS_STABILITY_TAUS_S, "Averaging times of the bias stability (Section 4.2 of the "
        "paper uses 10 s).", unit="s", cli=None)
    allan: bool = setting(True, "Also compute the Allan deviations and noise terms (ARW, "
                          "bias instability, RRW).", cli=None)
    confidence: float = setting(
        ONE_SIGMA, "Two-sided level of the intervals (bias stability and Allan deviation).",
        cli=None)


#: What the evaluations of held-out runs measure inside ``calibrate``: the bias stability
#: only (no Allan deviations or noise terms).
BIAS_ONLY = EvaluationSettings(allan=False)


@dataclass(frozen=True)
class ReportSettings:
    """How ``hrgtc report`` draws its page (:func:`hrgtc.report.build_report`)."""

    max_points: int = setting(
        20_000, "Most points per plotted curve (block means of 10 s or more).")
    title: str | None = setting(None, "Page title.", default_text="names the unit")
    kind: str = setting(
        "paper", "The kind of report (hrgtc.report.kinds.KINDS): its data and its templates; "
        "paper lays the calibration's evidence out like the paper.", cli=None)
    axes: tuple[str, ...] | None = setting(
        None, "The axes to show; None: all. The model's and each run's axes must agree "
        "unless this names those to show.", cli=None)
