"""Plotting blocks of an evaluation pass: the means of consecutive blocks of samples, fed
chunk by chunk, that the report's figures draw (never the raw samples of a long run)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Self

import numpy as np

#: Shortest plotting block. [s]
BLOCK_S = 10.0


class BlockMeans:
    """Means of consecutive blocks of ``rows`` samples, fed chunk by chunk."""

    def __init__(self, rows: int) -> None:
        self.rows = rows
        self.offset = 0
        self._parts: dict[str, list[tuple[int, np.ndarray]]] = {}

    def partial_fit(self, columns: Mapping[str, np.ndarray]) -> Self:
        """Add the next rows (every column of one length)."""
        n = len(next(iter(columns.values())))
        index = (self.offset + np.arange(n)) // self.rows
        first = int(index[0])
        for name, values in {"_count": np.ones(n), **columns}.items():
            sums = np.bincount(index - first, weights=np.asarray(values, dtype=np.float64))
            self._parts.setdefault(name, []).append((first, sums))
        self.offset += n
        return self

    def finish(self) -> dict[str, np.ndarray]:
        """Block means of every column (the last block may be shorter)."""
        blocks = -(-self.offset // self.rows)
        totals = {}
        for name, parts in self._parts.items():
            total = np.zeros(blocks)
            for first, sums in parts:
                total[first : first + sums.size] += sums
            totals[name] = total
        count = totals.pop("_count")
        return {name: total / count for name, total in totals.items()}


def block_rows(rows: int, sample_rate_hz: float, max_points: int) -> int:
    """Rows per plotting block: at least :data:`BLOCK_S`, at most ``max_points`` blocks."""
    return max(round(BLOCK_S * sample_rate_hz), -(-rows // max(int(max_points), 1)), 1)
