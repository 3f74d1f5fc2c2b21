"""Reading options that read each file once and serve every later reading from memory.

Calibrating an instrument runs the single-gyro calibration on each axis's view of the
same files, and each calibration reads a file several times (the soak plateaus, the
at-rest pass, the window means, the held-out evaluation). :class:`ReadOnce` is a
:class:`~hrgtc.recording.ReadOptions` whose ``read``, ``head`` and ``chunks`` read a file
(all its axes, validated as a whole) the first time it is asked for with given reading
options, keep it, and hand out its rows in the same chunks as the streamed reading
would (and each axis's view, with the plausible-band check of
:meth:`~hrgtc.recording.ReadOptions.chunks`). The price is memory: the files are held
whole, so use it where one reading of each file is worth holding them (a multi-axis
calibration), not to stream a long run.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import Any

from hrgtc.core.errors import InputError
from hrgtc.recording.io import ReadOptions, iter_chunks
from hrgtc.recording.schema import Recording, concatenate
from hrgtc.settings.reading import ReadSettings

__all__ = ["ReadOnce"]


@dataclass(frozen=True)
class ReadOnce(ReadOptions):
    """:class:`~hrgtc.recording.ReadOptions` that keep each file read (see the module).

    ``cache`` is shared by every copy made with :func:`dataclasses.replace` (another
    ``axis``, another band), so all the axes of a file share one reading; another
    slice (``start``/``end``) or mapping is another reading.
    """

    cache: dict[Any, Any] = field(default_factory=dict, compare=False, repr=False)

    def _whole(self, path: str | Path) -> Recording:
        whole = replace(self, axis=None, freq_band_hz=None, freq_span_hz=None, motion="keep")
        key = (str(Path(path).resolve()),
               repr([getattr(whole, f.name) for f in fields(ReadSettings)]))
        if key not in self.cache:
            dropped: dict[str, int] = {}
            self.cache[key] = concatenate(list(iter_chunks(path, whole, dropped=dropped)))
            self.cache[("dropped", *key)] = dropped  # type: ignore[assignment]
        return self.cache[key]

    def _dropped(self, path: str | Path) -> dict[str, int]:
        """The rows the spike filters removed from the file's one reading."""
        whole = replace(self, axis=None, freq_band_hz=None, freq_span_hz=None, motion="keep")
        key = (str(Path(path).resolve()),
               repr([getattr(whole, f.name) for f in fields(ReadSettings)]))
        return self.cache.get(("dropped", *key), {})  # type: ignore[return-value]

    def _cached(self) -> bool:
        # a single-axis reading with a plausible band is checked by the reader itself
        return self.axis is not None or self.freq_band_hz is None

    def chunks(self, path: str | Path, rows: int | None = None,
               dropped: dict[str, int] | None = None) -> Iterator[Recording]:
        """The file's rows in chunks of ``rows`` (with ``axis``: that axis's views);
        ``dropped`` as for :meth:`~hrgtc.recording.ReadOptions.chunks`."""
        if not self._cached():
            return super().chunks(path, rows, dropped)
        whole = self._whole(path)
        if dropped is not None:
            spikes = self._dropped(path).get("spikes", 0)
            dropped["spikes"] = dropped.get("spikes", 0) + spikes
        size = rows or self.chunk_rows
        pieces = (whole.slice(start, min(start + size, len(whole)))
                  for start in range(0, len(whole), size))
        if self.axis is None:
            return pieces
        return self._axis_chunks(pieces, str(path))

    def read(self, path: str | Path, keep: Sequence[str] | None = None) -> Recording:
        """The whole file (with ``axis``, its view; with ``keep``, those columns only)."""
        if not self._cached():
            return super().read(path, keep)
        whole = concatenate(list(self.chunks(path, rows=max(1, len(self._whole(path))))))
        if keep is None:
            return whole
        return Recording({k: whole[k] for k in keep if k in whole}, whole.metadata,
                         whole.source)

    def head(self, path: str | Path, rows: int = 10_000) -> Recording:
        """The first ``rows`` rows (columns and metadata)."""
        if not self._cached():
            return super().head(path, rows)
        chunks = self.chunks(path, rows=rows)
        try:
            return next(chunks)
        except StopIteration:
            raise InputError(f"{path}: the recording holds no rows") from None
