"""Export: a unit's or instrument's model written out for use outside Python.

Takes a :class:`~hrgtc.model.Model` (one axis or several) and
gives files that compute, sample by sample, what :class:`hrgtc.compensate.Compensator`
computes: dependency-free C99 for on-board use, in double or float32
(:func:`export_c`, ``output_format="c"``; the text modules in :mod:`hrgtc.export.c`),
or a documented ``key = value`` parameter file (``output_format="params"``,
:mod:`hrgtc.export.parameter_file`). :data:`FORMATS` lists the targets.

The stage sits beside :mod:`hrgtc.compensate` (neither imports the other): both read the
model and the drift variables' registry (:mod:`hrgtc.drift.variables`), and the tests
hold each export to the compensator.
"""

from hrgtc.export.c.plan import PRECISIONS
from hrgtc.export.export_c import FORMATS, export_c

__all__ = ["FORMATS", "PRECISIONS", "export_c"]
