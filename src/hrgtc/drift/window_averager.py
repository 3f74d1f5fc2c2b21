"""Means of non-overlapping windows over consecutive chunks (:mod:`hrgtc.drift.windows`).

A window never spans a segment break (a gap) nor a cut (samples left out as not at
rest); see :class:`_WindowMeans`.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hrgtc.core.timeline import min_partial_rows


class _WindowMeans:
    """Means of non-overlapping windows of ``rows`` samples over consecutive chunks.

    A window never spans a segment break (a gap): the partial window before it is kept
    when it holds at least :data:`PARTIAL_WINDOW_FRACTION` of ``rows``, else dropped and
    counted. At a cut (samples left out as not at rest) the partial window is dropped.

    Each chunk is averaged at once, whatever its number of segments (a burst file has
    thousands per chunk): the window bounds come from array arithmetic and the sums of
    every window from one ``numpy.add.reduceat``, which runs down contiguous columns
    when the block is column-major (as :func:`window_means` builds it).
    """

    def __init__(self, rows: int) -> None:
        self.rows = rows
        self.min_rows = min(rows, min_partial_rows(rows))
        self._carry: np.ndarray | None = None  # rows of the open window, from earlier chunks
        self.partial_dropped_rows = 0

    def transform(self, block: np.ndarray, breaks: Sequence[int] | np.ndarray = (),
                  cuts: Sequence[int] | np.ndarray = ()) -> np.ndarray:
        """Window means of ``block``; ``breaks``: its rows that start a new segment,
        ``cuts``: its rows that follow left-out samples (a row that is both is a break)."""
        n, width = block.shape
        breaks = _rows_inside(breaks, n)
        cuts = _rows_inside(cuts, n)
        if cuts.size:
            cuts = cuts[~np.isin(cuts, breaks, assume_unique=True)]
            starts = _rows_inside(np.concatenate([breaks, cuts]), n)
            at_break = np.isin(starts, breaks, assume_unique=True)
        else:
            starts, at_break = breaks, np.ones(breaks.size, dtype=bool)
        out = []
        if starts.size and starts[0] == 0:  # the carry's segment ends before the block
            out.append(self.flush() if at_break[0] else self.drop())
            starts, at_break = starts[1:], at_break[1:]
        carry = self._carry if self._carry is not None else np.empty((0, width))
        # segment k holds rows [begin[k], end[k]) of the block; the first starts with the
        # carry (at a negative row)
        begin = np.concatenate([[-carry.shape[0]], starts])
        end = np.append(starts, n)
        complete = (end - begin) // self.rows
        tail = begin + complete * self.rows  # the partial window at each segment's end
        # the partial windows before a break are kept when long enough, else counted;
        # those before a cut are counted; the last segment's is the new carry
        tail_rows = end[:-1] - tail[:-1]
        kept = at_break & (tail_rows > 0) & (tail_rows >= self.min_rows)
        self.partial_dropped_rows += int(tail_rows[~kept].sum())
        windows = int(complete.sum())
        offset = np.arange(windows) - np.repeat(np.cumsum(complete) - complete, complete)
        first = np.repeat(begin, complete) + offset * self.rows
        low = np.concatenate([first, tail[:-1][kept]])
        high = np.concatenate([first + self.rows, end[:-1][kept]])
        order = np.argsort(low, kind="stable")
        low, high = low[order], high[order]
        if tail[-1] >= 0:
            self._carry = block[tail[-1]:].copy()
        else:  # no window closed: the block joins the carry
            self._carry = np.concatenate([carry, block])
        if low.size:
            bounds = np.column_stack([np.maximum(low, 0), high]).ravel()
            sums = np.add.reduceat(block, bounds[bounds < n], axis=0)[::2]
            if low[0] < 0:  # the first window began in the carry
                sums[0] += carry.sum(axis=0)
            out.append(sums / (high - low)[:, None])
        out = [o for o in out if o.shape[0]]
        return np.concatenate(out) if out else np.empty((0, width))

    def drop(self) -> np.ndarray:
        """A cut: the partial window is dropped (counted); no window."""
        width = 0
        if self._carry is not None:
            self.partial_dropped_rows += self._carry.shape[0]
            width = self._carry.shape[1]
        self._carry = None
        return np.empty((0, width))

    def flush(self) -> np.ndarray:
        """End of a segment: the partial window, kept when long enough, else counted."""
        carry, self._carry = self._carry, None
        if carry is None or carry.shape[0] == 0:
            return np.empty((0, 0 if carry is None else carry.shape[1]))
        if carry.shape[0] >= self.min_rows:
            return carry.mean(axis=0, keepdims=True)
        self.partial_dropped_rows += carry.shape[0]
        return np.empty((0, carry.shape[1]))


def _rows_inside(rows: Sequence[int] | np.ndarray, n: int) -> np.ndarray:
    """The distinct ``rows`` in ``[0, n)``, sorted (without ``numpy.unique``'s hashing,
    milliseconds for the thousands of breaks of a burst file)."""
    rows = np.asarray(rows, dtype=np.int64).ravel()
    rows = rows[(rows >= 0) & (rows < n)]
    if rows.size > 1 and not np.all(rows[1:] > rows[:-1]):
        rows = np.sort(rows)
        rows = rows[np.concatenate([[True], rows[1:] != rows[:-1]])]
    return rows
