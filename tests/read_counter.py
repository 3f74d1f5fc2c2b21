"""Count how often a command opens and reads each recording file (issue 22, Deliver 4).

:func:`count_reads` patches the recording sources (:mod:`hrgtc.recording.formats`,
:mod:`hrgtc.recording.csv`) for the duration of a ``with`` block and counts, per file:

* ``opens``: every :class:`~hrgtc.recording.formats.Source` opened (a head of the
  columns, a row count, a mark check and a pass over the data each open the file);
* ``passes``: iterations over the file's tables that ran to its end, and whole reads
  (``Source.read``): how often the data were read in full, heads left out;
* ``heads``: :meth:`hrgtc.recording.ReadOptions.head` calls (the first rows, for the
  columns and metadata; on a file shorter than the validation's heuristic rows a head
  reads it whole, so it is counted apart from the passes);
* ``rows``: rows delivered, all opens together (``rows / rows of the file`` counts the
  heads as fractions of a pass).

The counts name the file by its resolved path.
"""

from __future__ import annotations

import contextlib
from collections import Counter
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from unittest import mock

from hrgtc.recording.formats import Hdf5Source, ParquetSource
from hrgtc.recording.formats.csv import CsvSource


@dataclass
class ReadCounts:
    """Per-file counts (keys: resolved paths)."""

    opens: Counter = field(default_factory=Counter)
    passes: Counter = field(default_factory=Counter)
    rows: Counter = field(default_factory=Counter)
    heads: Counter = field(default_factory=Counter)
    in_head: int = 0

    def of(self, path: str | Path) -> tuple[int, int]:
        """``(opens, full passes)`` of one file."""
        key = str(Path(path).resolve())
        return self.opens[key], self.passes[key]

    def table(self, paths: list[str | Path]) -> dict[str, dict[str, int]]:
        """``{file name: {"opens", "passes", "heads"}}`` of ``paths``."""
        out = {}
        for path in paths:
            key = str(Path(path).resolve())
            out[Path(path).name] = {"opens": self.opens[key], "passes": self.passes[key],
                                    "heads": self.heads[key]}
        return out


@contextlib.contextmanager
def count_reads() -> Iterator[ReadCounts]:
    """Count the opens and full passes of every recording file read in the block."""
    counts = ReadCounts()
    patches = []
    for cls in (ParquetSource, CsvSource, Hdf5Source):
        init, iter_tables, read = cls.__init__, cls.iter_tables, cls.read

        def counted_init(self, path, *args, _init=init, **kwargs):
            counts.opens[str(Path(path).resolve())] += 1
            _init(self, path, *args, **kwargs)

        def counted_iter(self, names, as_text, rows, _iter=iter_tables):
            key = str(Path(self.path).resolve())
            for table in _iter(self, names, as_text, rows):
                counts.rows[key] += table.num_rows
                yield table
            if not counts.in_head:
                counts.passes[key] += 1

        def counted_read(self, names, as_text, _read=read):
            key = str(Path(self.path).resolve())
            table = _read(self, names, as_text)
            counts.rows[key] += table.num_rows
            counts.passes[key] += 1
            return table

        patches += [mock.patch.object(cls, "__init__", counted_init),
                    mock.patch.object(cls, "iter_tables", counted_iter),
                    mock.patch.object(cls, "read", counted_read)]
    from hrgtc.recording.io import ReadOptions

    head = ReadOptions.head

    def counted_head(self, path, rows=10_000):
        counts.heads[str(Path(path).resolve())] += 1
        counts.in_head += 1
        try:
            return head(self, path, rows)
        finally:
            counts.in_head -= 1

    patches.append(mock.patch.object(ReadOptions, "head", counted_head))
    with contextlib.ExitStack() as stack:
        for patch in patches:
            stack.enter_context(patch)
        yield counts
