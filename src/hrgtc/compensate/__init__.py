"""Compensation: stage 4, a unit model applied to any later run.

Takes a :class:`~hrgtc.model.UnitModel` and a recording and gives the
compensated output: batch or streaming (``compensator``: :class:`Compensator`
keeps the df/dt filter state across chunks; :func:`compensate_file` works file
to file in bounded memory), or dependency-free C99 for on-board use
(``export_c``, its text in ``c_text``, the float32 build in ``c_single`` and
``c_float32``, the scale factor in ``c_scale``) or a documented parameter file
(``parameter_file``). A whole instrument (:class:`~hrgtc.model.InstrumentModel`,
every axis, bias and scale factor) is compensated by ``instrument``'s
:class:`InstrumentCompensator`.
"""

from hrgtc.compensate.compensator import (
    OUTPUT_COLUMNS,
    CompensationSummary,
    Compensator,
    compensate,
    compensate_file,
)
from hrgtc.compensate.export_c import export_c
from hrgtc.compensate.multi_axis import (
    InstrumentCompensator,
    compensate_instrument_file,
    instrument_output_columns,
)

__all__ = [
    "OUTPUT_COLUMNS",
    "CompensationSummary", "Compensator", "InstrumentCompensator", "compensate",
    "compensate_file", "compensate_instrument_file", "export_c", "instrument_output_columns"]
