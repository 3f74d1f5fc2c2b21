"""The C floating type of the firmware export: double, or float32 for FPU-only MCUs.

Every constant, variable declaration and ``math.h`` call that
:mod:`hrgtc.export.c.source` and :mod:`hrgtc.export.c.header` print goes
through one :class:`CType`, so the body is written once for both builds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hrgtc.core.errors import InputError
from hrgtc.export.c.plan import CPlan


@dataclass(frozen=True)
class CType:
    """The C floating type the export is written in: its name, literal suffix and math calls.

    Every constant, variable and ``math.h`` call of the generated code goes through one
    of these, so the same text generators write the double build and the float32 build.
    """

    name: str
    suffix: str

    def literal(self, value: float, name: str) -> str:
        """A finite constant as a C literal of this type that reads back to the same value.

        ``%.17g`` for double; for float the shortest decimal that reads back to the
        same float32 (``numpy.float32``'s repr), with an ``f`` suffix.
        """
        value = float(value)
        if not math.isfinite(value):
            raise InputError(
                f"model constant {name} is {value}; a model with non-finite numbers cannot be "
                "exported: recalibrate the unit"
            )
        if self.suffix:
            single = np.float32(value)
            if not np.isfinite(single):
                raise InputError(f"model constant {name} = {value:g} overflows float32; export "
                                 "with --precision double")
            text = str(single)
        else:
            text = f"{value:.17g}"
        if not any(c in text for c in ".eEn"):
            text += ".0"
        return text + self.suffix

    def call(self, function: str) -> str:
        """The ``math.h`` function of this type: ``pow`` -> ``powf`` for float."""
        return function + self.suffix


DOUBLE = CType("double", "")
SINGLE = CType("float", "f")


def ctype(plan: CPlan) -> CType:
    """The C type of a plan's precision (``double`` or ``single``)."""
    return SINGLE if plan.precision == "single" else DOUBLE
