"""File formats of recordings: one module per format, collected by one registry.

* :mod:`~hrgtc.recording.formats.base`: what a format provides (:class:`Format`, the
  stream reader :class:`Source`, the writer :class:`Sink`, :class:`TableSource`);
* :mod:`~hrgtc.recording.formats.parquet`, :mod:`~hrgtc.recording.formats.csv`,
  :mod:`~hrgtc.recording.formats.hdf5`: the built-in formats, each declaring its
  ``FORMAT``; read only: :mod:`~hrgtc.recording.formats.tdms`,
  :mod:`~hrgtc.recording.formats.matlab`, :mod:`~hrgtc.recording.formats.ulog`,
  :mod:`~hrgtc.recording.formats.dataflash`, :mod:`~hrgtc.recording.formats.mdf` (their
  libraries imported when a file is read; what they share in
  :mod:`~hrgtc.recording.formats.logs`);
* :mod:`~hrgtc.recording.formats.registry`: the registry (built-in formats and those
  of the ``hrgtc.formats`` entry points); every choice of a format goes through it.

Adding a format: see ``docs/architecture.md`` ("Adding a file format").
"""

from hrgtc.recording.formats.base import (
    SNIFF_BYTES,
    Format,
    Sink,
    Source,
    TableSource,
    column_unit,
    first_failing,
    is_column_name,
    kind_of,
    loads_json,
    metadata_json,
)
from hrgtc.recording.formats.csv import CsvSink, CsvSource
from hrgtc.recording.formats.hdf5 import HDF5_GROUP, Hdf5Sink, Hdf5Source
from hrgtc.recording.formats.parquet import METADATA_KEY, ParquetSink, ParquetSource
from hrgtc.recording.formats.registry import (
    ENTRY_POINT_GROUP,
    format_for,
    format_of,
    formats,
    get,
    is_recording,
    open_streams,
    output_suffixes,
    register,
    suffixes,
    writable,
)

__all__ = [
    "ENTRY_POINT_GROUP",
    "HDF5_GROUP",
    "METADATA_KEY",
    "SNIFF_BYTES",
    "CsvSink",
    "CsvSource",
    "Format",
    "Hdf5Sink",
    "Hdf5Source",
    "ParquetSink",
    "ParquetSource",
    "Sink",
    "Source",
    "TableSource",
    "column_unit",
    "first_failing",
    "format_for",
    "format_of",
    "formats",
    "get",
    "is_column_name",
    "is_recording",
    "kind_of",
    "loads_json",
    "metadata_json",
    "open_streams",
    "output_suffixes",
    "register",
    "suffixes",
    "writable",
]
