"""Row numbers of the file, whatever the reader left out before validation.

The reader drops rows before the validator sees them: spikes (``--spikes drop``, the
robust ``--spike-filter drop``), duplicated rows (the time repair) and the rows
outside ``--start/--end``. A later problem's row must still name the row of the
file (0 = the first data row, as every message of the validator), so the reader
carries each row's file row in a private column (:data:`ROW_KEY`) through those
stages, takes it off before the :class:`~hrgtc.recording.Recording` is built, and
hands it to the validator, which keeps it as a sparse map (:class:`FileRows`: one
entry per run of rows left out, not one per row) and rewrites the rows of its
problems with it.
"""

from __future__ import annotations

import dataclasses
import re
from typing import Self

import numpy as np

from hrgtc.recording.checks import Problem

#: Private column of the reader's parts: the file row of each row (float64, so it
#: passes every stage as the other columns do). Never in a Recording.
ROW_KEY = "__file_row__"


def with_file_rows(part: dict[str, np.ndarray], offset: int) -> dict[str, np.ndarray]:
    """``part`` (rows ``offset`` on of the file) with its file rows in :data:`ROW_KEY`."""
    n = len(next(iter(part.values()))) if part else 0
    return {**part, ROW_KEY: np.arange(offset, offset + n, dtype=np.float64)}


def take_file_rows(part: dict[str, np.ndarray]) -> tuple[dict[str, np.ndarray],
                                                          np.ndarray | None]:
    """``part`` without :data:`ROW_KEY`, and the file rows it held (None if none)."""
    if ROW_KEY not in part:
        return part, None
    rows = part[ROW_KEY]
    return {k: v for k, v in part.items() if k != ROW_KEY}, rows


class FileRows:
    """The file row of each row the validator saw, as a sparse map.

    ``shift = file row - row seen`` only grows, by the rows left out before it; the
    map keeps the rows seen where it changes.

    Examples
    --------
    >>> rows = FileRows().partial_fit(0, np.array([0.0, 1.0, 3.0, 4.0]))  # row 2 dropped
    >>> rows = rows.partial_fit(4, np.array([5.0, 9.0]))  # rows 6-8 too
    >>> [rows.file_row(k) for k in range(6)]
    [0, 1, 3, 4, 5, 9]
    """

    def __init__(self) -> None:
        self._at: list[int] = [0]
        self._shift: list[int] = [0]

    def partial_fit(self, offset: int, file_rows: np.ndarray) -> Self:
        """The file rows of the next ``len(file_rows)`` rows seen, from row ``offset`` on."""
        if not len(file_rows):
            return self
        shift = np.asarray(file_rows, dtype=np.int64) - np.arange(offset, offset + len(file_rows))
        changes = np.flatnonzero(np.diff(shift)) + 1
        if shift[0] != self._shift[-1]:
            changes = np.concatenate([[0], changes])
        self._at += (offset + changes).tolist()
        self._shift += shift[changes].tolist()
        return self

    def finish(self) -> Self:
        """The map of the rows seen (read with :meth:`file_row` and :meth:`problem`)."""
        return self

    def file_row(self, row: int) -> int:
        """The file row of row ``row`` seen."""
        k = int(np.searchsorted(self._at, row, side="right")) - 1
        return int(row + self._shift[max(k, 0)])

    @property
    def identity(self) -> bool:
        """True while no row was left out."""
        return self._shift[-1] == 0 and len(self._shift) == 1

    def problem(self, problem: Problem) -> Problem:
        """``problem`` with its row (and the rows its message names) rows of the file."""
        if problem.row is None or self.identity:
            return problem
        row = self.file_row(problem.row)
        if row == problem.row:
            return problem
        message = re.sub(rf"\brow {problem.row}\b", f"row {row}", problem.message)
        return dataclasses.replace(problem, row=row, message=message)


class RemovedInSlice:
    """The rows a filter removed that lie inside a ``--start/--end`` slice.

    A filter that needs the neighbours of a row (the spike filters) runs before the slice
    is cut, so its count covers the whole file; the accounting of the part read counts
    only those between the first and the last file row the slice kept.
    """

    def __init__(self) -> None:
        self._removed: list[np.ndarray] = []
        self._first, self._last = np.inf, -np.inf

    def filtered(self, before: dict[str, np.ndarray], after: dict[str, np.ndarray]) -> None:
        """Note the file rows of ``before`` (a part with :data:`ROW_KEY`) not in ``after``."""
        rows = before.get(ROW_KEY)
        if rows is not None and len(after[ROW_KEY]) < len(rows):
            self._removed.append(np.setdiff1d(rows, after[ROW_KEY]))

    def kept(self, file_rows: np.ndarray | None) -> None:
        """Note the file rows of a part the slice kept."""
        if file_rows is not None and len(file_rows):
            self._first = min(self._first, float(file_rows[0]))
            self._last = max(self._last, float(file_rows[-1]))

    @property
    def count(self) -> int:
        """Removed rows between the first and the last row kept."""
        rows = np.concatenate(self._removed) if self._removed else np.empty(0)
        return int(np.count_nonzero((rows >= self._first) & (rows <= self._last)))

