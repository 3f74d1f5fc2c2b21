"""Settings of the firmware export (stage 5): C99 or a parameter file."""

from __future__ import annotations

from dataclasses import dataclass

from hrgtc.settings import setting

#: Floating types of the C code.
PRECISIONS = ("double", "single")
#: What the export writes.
EXPORT_FORMATS = ("c", "params")


@dataclass(frozen=True)
class ExportSettings:
    """What ``hrgtc export-c`` writes (:func:`hrgtc.export.export_c`)."""

    prefix: str = setting("hrgtc", "C name prefix: <prefix>_model.h, <prefix>_step(), ...")
    precision: str = setting(
        "double", "double, or single: float32 for FPU-only MCUs (Cortex-M4F), the frequency "
        "passed centred, the worst error against double stated in the header.",
        choices=PRECISIONS)
    output_format: str = setting(
        "c", "c: <prefix>_model.h and .c; params: <prefix>_params.txt, key = value lines, "
        "every number documented, for firmware that evaluates its own polynomials.",
        cli="--format", choices=EXPORT_FORMATS)
