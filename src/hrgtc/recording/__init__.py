"""Recordings: stage 1 of the pipeline.

Takes a user's file (Parquet, CSV or HDF5, with their column names and units)
and gives a validated :class:`Recording` in the contract of DESIGN.md — whole
(:func:`read`) or in chunks of bounded memory (:func:`iter_chunks`) — or a
description of it (:func:`describe`). :class:`RecordingWriter` and :func:`write`
write recordings atomically.

Modules: ``schema`` (the type and its columns), ``formats`` (the file formats,
one module each, and their registry), ``align`` (the streams of a file on one time
axis), ``axes`` (multi-axis recordings: :func:`axis_names`,
:func:`axis_view`), ``mapping`` (user columns and units), ``validation`` (the contract's
checks), ``checks`` (the single checks and unit heuristics), ``gaps`` (gap
policies), ``spikes`` (implausible samples: an error, or dropped), ``io``
(reading), ``writing`` (atomic writing), ``info`` (what is in a file), ``marks``
(the mark of a compensated output).
"""

from hrgtc.recording.axes import AXIS_COLUMNS, axis_input_rate_dph, axis_names, axis_view
from hrgtc.recording.gaps import Gap, split_at_gaps
from hrgtc.recording.info import RecordingInfo, describe
from hrgtc.recording.io import (
    ReadOptions,
    RecordingWriter,
    count_rows,
    iter_chunks,
    open_source,
    read,
    write,
)
from hrgtc.recording.mapping import parse_columns, parse_unit, parse_units
from hrgtc.recording.schema import (
    COLUMNS,
    REQUIRED_COLUMNS,
    SCHEMA_VERSION,
    Metadata,
    Recording,
    concatenate,
)
from hrgtc.recording.validation import (
    Problem,
    RecordingValidator,
    ValidationReport,
    validate,
)

__all__ = [
    "AXIS_COLUMNS",
    "COLUMNS",
    "REQUIRED_COLUMNS",
    "SCHEMA_VERSION",
    "Gap",
    "Metadata",
    "Problem",
    "ReadOptions",
    "Recording",
    "RecordingInfo",
    "RecordingValidator",
    "RecordingWriter",
    "ValidationReport",
    "axis_input_rate_dph",
    "axis_names",
    "axis_view",
    "concatenate",
    "count_rows",
    "describe",
    "iter_chunks",
    "open_source",
    "parse_columns",
    "parse_unit",
    "parse_units",
    "read",
    "split_at_gaps",
    "validate",
    "write",
]
