"""The files this process has read to their end and validated, with the options they were
read with: a later pass over the same file with the same options skips the validation.

A command reads a training file several times (``calibrate``: the soak plateaus, the at-rest
pass, the window means of the drift model and of the housing baseline,
``docs/benchmarks.md``); each pass used to validate every sample again, with the same
result. :func:`iter_chunks <hrgtc.recording.io.iter_chunks>` remembers the
:class:`~hrgtc.recording.checks.ValidationReport` of a pass that ran to the file's end
without a problem, keyed on the file's identity (resolved path, inode, modification time
in ns, size, a digest of its first and last 4 KiB: a file rewritten is another file) and on
the whole reading options, and a
later pass with the same key says the report's warnings again instead of validating (a
pass over some of the columns, too: ``calibrate``'s window pass,
:mod:`hrgtc.pipeline.narrow_reading`). A pass that stopped early (a head) or raised
remembers nothing.
"""

from __future__ import annotations

import hashlib
import os
from collections import OrderedDict
from collections.abc import Collection
from pathlib import Path
from typing import Any

from hrgtc.core.forked import share_memo
from hrgtc.recording.checks import ValidationReport

#: the most recent reports kept (one per file and reading options)
_KEPT = 64
#: bytes of each end of a file in its key
_END_BYTES = 4096
_REPORTS: OrderedDict[tuple[object, ...], ValidationReport] = OrderedDict()


def validation_key(path: str | Path, options: Any,
                   only: Collection[str] | None = None) -> tuple[object, ...] | None:
    """The key of a pass over ``path`` read with ``options`` (and ``only``); None for a
    path that is no regular file (a stream is never remembered)."""
    try:
        stat = os.stat(path)
    except (OSError, TypeError, ValueError):
        return None
    if not os.path.isfile(path):
        return None
    columns = None if only is None else tuple(sorted(only))
    return (os.path.realpath(path), stat.st_ino, stat.st_mtime_ns, stat.st_size,
            _ends(path, stat.st_size), repr(options), columns)


def _ends(path: str | Path, size: int) -> bytes:
    """A digest of the file's first and last :data:`_END_BYTES` bytes (a file rewritten in
    place within the clock's tick, same size, still differs in its header or footer: a
    Parquet footer holds every column chunk's offsets, a CSV its last rows)."""
    digest = hashlib.blake2b(digest_size=16)
    with open(path, "rb") as handle:
        digest.update(handle.read(_END_BYTES))
        if size > _END_BYTES:
            handle.seek(max(size - _END_BYTES, _END_BYTES))
            digest.update(handle.read(_END_BYTES))
    return digest.digest()


def known_report(key: tuple[object, ...] | None) -> ValidationReport | None:
    """The report of an earlier complete pass with ``key`` (None: validate); for a pass
    over some of the file's columns (``only``), also that of a pass over all of them with
    the same options: every column passed its checks, these among them."""
    if key is None:
        return None
    for each in (key, (*key[:-1], None)):
        report = _REPORTS.get(each)
        if report is not None:
            _REPORTS.move_to_end(each)
            return report
    return None


def remember(key: tuple[object, ...] | None, report: ValidationReport) -> None:
    """Keep the ``report`` of a pass with ``key`` that ran to the file's end and passed."""
    if key is None:
        return
    _REPORTS[key] = report
    _REPORTS.move_to_end(key)
    while len(_REPORTS) > _KEPT:
        _REPORTS.popitem(last=False)


# a worker process's reports come back to the command (hrgtc.core.forked)
share_memo(_REPORTS, remember)


def forget() -> None:
    """Forget every report (tests; a file changed in place within one ns keeps its key)."""
    _REPORTS.clear()
