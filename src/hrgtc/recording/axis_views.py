"""One axis of a multi-axis file, chunk by chunk: its views and the check of its frequency
against the band a model's axis can reach (:func:`hrgtc.recording.io.iter_chunks` with
``axis``, and :mod:`hrgtc.evaluation.run_evaluation` for every axis of one reading)."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from hrgtc.core.errors import RecordingError
from hrgtc.recording.axes import axis_view
from hrgtc.recording.schema import Recording


def axis_views(chunks: Iterator[Recording], axis: str, band: tuple[float, float] | None,
                path: str) -> Iterator[Recording]:
    """The view of ``axis`` of each of ``chunks`` (read from ``path``), its frequency
    checked against the plausible ``band`` of that axis of a model (None: unchecked)."""
    row = 0
    try:
        for chunk in chunks:
            view = axis_view(chunk, axis)
            if band is not None:
                check_axis_band(view, axis, band, row, path)
            row += len(chunk)
            yield view
    finally:
        chunks.close()  # type: ignore[attr-defined]


def check_axis_band(view: Recording, axis: str, band: tuple[float, float], row: int,
                    path: str) -> None:
    """Refuse a frequency of ``axis``'s view (whose first row is ``row`` of ``path``)
    outside the ``band`` that axis of a model can reach."""
    if not len(view):
        return
    freq = view.freq_hz
    bad = np.flatnonzero(~((freq >= band[0]) & (freq <= band[1])))
    if bad.size:
        raise RecordingError(
            f"{path}: column freq_hz_{axis}, row {row + int(bad[0])}: "
            f"{float(freq[bad[0]])!r} is outside the band {band[0]:.6g} to {band[1]:.6g} this "
            f"axis of the model can reach ({bad.size} such rows in the chunk); is it another "
            "unit's file, or the wrong column?")
