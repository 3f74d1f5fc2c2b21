"""Column dicts regrouped into pieces of a fixed number of rows (the chunks of a read)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np


def rechunk(tables: Iterator[dict[str, np.ndarray]], rows: int) -> Iterator[dict[str, np.ndarray]]:
    """Regroup column dicts into consecutive pieces of exactly ``rows`` rows (last shorter)."""
    buffer: list[dict[str, np.ndarray]] = []
    held = 0
    for part in tables:
        n = len(next(iter(part.values()))) if part else 0
        if n == 0:
            continue
        buffer.append(part)
        held += n
        while held >= rows:
            joined = buffer[0] if len(buffer) == 1 else _join(buffer)
            yield {k: v[:rows] for k, v in joined.items()}
            rest = {k: v[rows:] for k, v in joined.items()}
            held -= rows
            buffer = [rest] if held else []
    if held:
        yield _join(buffer)


def _join(parts: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    if len(parts) == 1:
        return parts[0]
    return {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
