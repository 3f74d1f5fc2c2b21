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


@dataclass(frozen=True)
class ReportSettings:
    """How ``hrgtc report`` draws its figures (:func:`hrgtc.report.build_report`)."""

    max_points: int = setting(
        20_000, "Most points per plotted curve (block means of 10 s or more).")
