"""Compensation: stage 4, a model applied to any later run.

Takes a :class:`~hrgtc.model.Model` (one axis or several) and a recording and gives the
compensated output: batch or streaming (``compensator``: :class:`Compensator` keeps
each axis's df/dt filter state across chunks, :func:`compensate` is one chunk;
``file_pass``: :func:`compensate_file` works file to file in bounded memory). A
single-axis model adds the plain columns, a multi-axis one each axis's under its suffix
(``multi_axis``: the model's axes matched to the recording's). Each axis is compensated by
its own ``axis.AxisCompensator``, the engine inside this package. The same model as
dependency-free C99 for on-board use, or as a documented parameter file, is
:mod:`hrgtc.export`.
"""

from hrgtc.compensate.compensator import OUTPUT_COLUMNS, Compensator, compensate, output_columns
from hrgtc.compensate.file_pass import CompensationSummary, compensate_file

__all__ = ["OUTPUT_COLUMNS", "CompensationSummary", "Compensator", "compensate",
           "compensate_file", "output_columns"]
