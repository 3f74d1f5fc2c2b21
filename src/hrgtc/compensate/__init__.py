"""Compensation: stage 4, a unit model applied to any later run.

Takes a :class:`~hrgtc.model.Model` and a recording and gives the
compensated output: batch or streaming (``compensator``: :class:`Compensator`
keeps the df/dt filter state across chunks; ``file_pass``: :func:`compensate_file`
works file to file in bounded memory). A whole instrument (:class:`~hrgtc.model.Model`,
every axis, bias and scale factor) is compensated by ``instrument``'s
:class:`InstrumentCompensator`. The same model as dependency-free C99 for on-board
use, or as a documented parameter file, is :mod:`hrgtc.export`.
"""

from hrgtc.compensate.compensator import OUTPUT_COLUMNS, Compensator, compensate
from hrgtc.compensate.file_pass import CompensationSummary, compensate_file
from hrgtc.compensate.multi_axis import (
    InstrumentCompensator,
    compensate_instrument_file,
    instrument_output_columns,
)

__all__ = [
    "OUTPUT_COLUMNS",
    "CompensationSummary", "Compensator", "InstrumentCompensator", "compensate",
    "compensate_file", "compensate_instrument_file", "instrument_output_columns"]
