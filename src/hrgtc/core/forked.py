"""A command's independent pieces of work on every core: forked worker processes.

``calibrate`` reads its soaks one after the other, and each soak's pass (decoding,
validation, spike filter, at-rest detector, plateau) is independent of the others until
their plateaus are combined; on one core of two the command leaves half the machine idle
(``docs/benchmarks.md``). :func:`map_in_order` runs such pieces in worker processes forked
from the command after its imports, so a worker starts with everything the command holds
(its settings, its numba kernels, what it has read) and returns only its piece's result.

What the result is, and what the command sees, does not depend on the workers:

* the results come back in the items' order, each as the function gives it in-process;
* the warnings a piece raised are recorded in the worker (every one, whatever the
  filters) and said again in the command, in order, each from its own module and line,
  so the command's filters and "once per place" registries judge them as if the piece
  had run in-process;
* what a piece taught this process's memos (:func:`share_memo`: the files validated, the
  spike filter's pieces) is added to the command's memos, so a later pass reads as it
  would after an in-process piece;
* a piece that raised in a worker is run again in the command, after the pieces before
  it: its error is raised there, with its own traceback (and a piece that fails only in
  a worker gives its in-process result).

Workers are used on Linux only (``fork``), when :func:`processes` says the pieces are
worth it and the machine is not overloaded; ``HRGTC_PROCESSES=1`` runs everything in-process,
``HRGTC_PROCESSES=N`` sets the workers (a test forces them on small files).
"""

from __future__ import annotations

import io
import math
import os
import pickle
import signal
import sys
import warnings
from collections.abc import Callable, Iterator, MutableMapping, Sequence
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")
R = TypeVar("R")

#: Below this many bytes of input per piece of work, the pieces run in-process (forking a
#: command of a few hundred MB and starting a worker costs some 10-50 ms).
MIN_BYTES_PER_PIECE = 4 * 2**20
#: Boolean arrays of this many elements or more travel from a worker as bits.
_PACKED_FROM = 4096
#: The environment variable that sets the worker processes (1: none).
ENVIRONMENT = "HRGTC_PROCESSES"

#: Process-wide memos a worker's pieces add to (key -> value), each with the function
#: that keeps an entry in it (its own size limit applied).
_MEMOS: list[tuple[MutableMapping[Any, Any], Callable[[Any, Any], None]]] = []
#: The work of the pool being started: (function, items); read by the forked workers.
_WORK: tuple[Callable[[Any], Any], Sequence[Any]] | None = None
_IN_WORKER = False


def share_memo(memo: MutableMapping[Any, Any], keep: Callable[[Any, Any], None]) -> None:
    """Register a process-wide memo: what a worker's piece adds to it is given back and
    kept in the command's with ``keep(key, value)``."""
    _MEMOS.append((memo, keep))


def processes(pieces: int, paths: Sequence[Any] = ()) -> int:
    """How many worker processes :func:`map_in_order` should use for ``pieces`` pieces of
    work over the files ``paths``: ``HRGTC_PROCESSES`` if set, else one per core
    (:func:`idle_cores`, at most one per piece) when the files hold
    :data:`MIN_BYTES_PER_PIECE` per piece, else 1."""
    if _IN_WORKER or pieces < 2 or not sys.platform.startswith("linux"):
        return 1
    given = os.environ.get(ENVIRONMENT, "").strip()
    if given:
        try:
            return max(1, min(int(given), pieces))
        except ValueError:
            return 1
    size = 0
    for path in paths:
        try:
            size += os.path.getsize(path)
        except (OSError, TypeError, ValueError):
            continue
    if size < MIN_BYTES_PER_PIECE * pieces:
        return 1
    return max(1, min(idle_cores(), pieces))


def idle_cores() -> int:
    """The cores of this command's CPU set, or 1 on a machine whose last minute's load
    average is twice its cores or more. The workers cost CPU (their start-up, their first
    pieces' memory): they pay where a core is free and cost some 10-17 % of wall time where
    it is not (``docs/benchmarks.md``); the load average lags too much to tell which, so
    only an overloaded machine is spared them (``HRGTC_PROCESSES=1`` spares any)."""
    cores = len(os.sched_getaffinity(0))
    try:
        busy = os.getloadavg()[0]
    except OSError:
        busy = 0.0
    return 1 if busy >= 2 * cores else cores


def map_in_order(work: Callable[[T], R], items: Sequence[T], workers: int) -> Iterator[R]:
    """``work(item)`` for each of ``items``, in order; with ``workers`` > 1 the first in the
    command, the others in that many forked processes (see the module docstring for what
    stays the same). What the first piece loads (imports, compiled kernels) the workers
    inherit instead of loading it each; a ``work`` with a ``prepare()`` method has it
    called before the fork too."""
    if workers < 2 or len(items) < 3:
        for item in items:
            yield work(item)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    global _WORK
    yield work(items[0])
    prepare = getattr(work, "prepare", None)
    if prepare is not None:
        prepare()
    sys.stdout.flush()  # a worker must not write the command's buffered output again
    sys.stderr.flush()
    pool = ProcessPoolExecutor(min(workers, len(items) - 1),
                               mp_context=multiprocessing.get_context("fork"),
                               initializer=_start_worker)
    _WORK = (work, items)
    try:  # with fork, every worker starts at the first submission
        sent_back = pool.map(_run_piece, range(1, len(items)))
    finally:
        _WORK = None
    index = 1
    with pool:
        try:
            for sent in sent_back:
                result, said, memos, failed = pickle.loads(sent)
                if failed:  # its error raised here (its warnings said once, from here)
                    result = work(items[index])
                else:
                    _say_again(said)
                    for (_, keep), added in zip(_MEMOS, memos, strict=True):
                        for key, value in added:
                            keep(key, value)
                index += 1
                yield result
        except BrokenProcessPool:  # a worker killed (out of memory): the rest run here
            pool.shutdown(wait=False, cancel_futures=True)
            for item in items[index:]:
                yield work(item)


def _start_worker() -> None:
    """A worker: no nested pools; Ctrl-C and SIGTERM are the command's to handle (its
    handlers, e.g. removing its temporary files, must not run in a worker)."""
    global _IN_WORKER
    _IN_WORKER = True
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _run_piece(index: int) -> bytes:
    """In a worker: the piece ``index``'s result, its warnings, what it added to the memos,
    and whether it raised, pickled (:class:`_Compact`)."""
    assert _WORK is not None
    work, items = _WORK
    before = [set(memo) for memo, _ in _MEMOS]
    failed = False
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            result = work(items[index])
        except Exception:
            result, failed = None, True
    said = [(_portable(w.message), w.category, w.filename, w.lineno) for w in caught]
    added = [[(k, v) for k, v in memo.items() if k not in seen]
             for (memo, _), seen in zip(_MEMOS, before, strict=True)]
    try:
        return _dumps((result, said, added, failed))
    except Exception:  # a result that cannot travel: the piece is run in the command
        return _dumps((None, [], [[] for _ in _MEMOS], True))


class _Compact(pickle.Pickler):
    """A pickler that sends a large boolean array as its bits (a sample mask of a few
    million rows: an eighth of the bytes through the pipe)."""

    def reducer_override(self, obj: Any) -> Any:
        if (type(obj) is np.ndarray and obj.dtype == np.bool_
                and obj.size >= _PACKED_FROM):
            return _unpacked, (np.packbits(obj, axis=None), obj.shape)
        return NotImplemented


def _unpacked(bits: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    size = math.prod(shape)
    return np.unpackbits(bits, count=size).view(np.bool_).reshape(shape)


def _dumps(value: Any) -> bytes:
    buffer = io.BytesIO()
    _Compact(buffer, protocol=pickle.HIGHEST_PROTOCOL).dump(value)
    return buffer.getvalue()


def _portable(message: Warning | str) -> Warning | str:
    """The warning itself if it survives pickling, else its text."""
    try:
        pickle.loads(pickle.dumps(message))
    except Exception:
        return str(message)
    return message


def _say_again(said: Sequence[tuple[Any, ...]]) -> None:
    """Warn each recorded warning again from its own module and line."""
    if not said:
        return
    modules = {os.path.abspath(m.__file__): m for m in list(sys.modules.values())
               if isinstance(getattr(m, "__file__", None), str)}
    for message, category, filename, lineno in said:
        module = modules.get(os.path.abspath(filename))
        registry = (None if module is None
                    else module.__dict__.setdefault("__warningregistry__", {}))
        warnings.warn_explicit(message, category, filename, lineno,
                               module=None if module is None else module.__name__,
                               registry=registry)
