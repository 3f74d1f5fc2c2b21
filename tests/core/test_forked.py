"""Tests of hrgtc.core.forked: pieces of work in forked workers give what they give
in-process, in order, with the same warnings in the same order and the same memos after.

Truth: the same pieces run in-process (``workers=1``); the worker's pid (the pieces did run
elsewhere); exact array equality (a boolean mask travels as its bits).
"""

from __future__ import annotations

import os
import sys
import uuid
import warnings
from collections import OrderedDict

import numpy as np
import pytest

from hrgtc.core import forked
from hrgtc.core.errors import HrgtcWarning, InputError

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="worker processes are forked on Linux only")

_MEMO: OrderedDict = OrderedDict()
forked.share_memo(_MEMO, _MEMO.__setitem__)


def _piece(n: int) -> dict:
    """A piece's result: arrays whose values depend on ``n``, the pid that computed it."""
    rng = np.random.default_rng(n)
    mask = rng.random(10_007 + n) < 0.3  # not a multiple of 8: the last bits' padding
    _MEMO[("piece", n)] = n * n
    return {"n": n, "mask": mask, "grid": (rng.random((70, 90)) < 0.5), "x": rng.random(5),
            "small": np.array([True, False, True]), "view": mask[::3], "pid": os.getpid()}


def _warning_piece(token: str):
    def work(n: int) -> int:
        warnings.warn(f"{token} piece {n}", HrgtcWarning, stacklevel=1)
        if n % 2:
            warnings.warn(f"{token} the same for every odd piece", HrgtcWarning, stacklevel=1)
        return n
    return work


def _failing(n: int) -> int:
    warnings.warn(f"before the failure of piece {n}", HrgtcWarning, stacklevel=1)
    if n == 2:
        raise InputError(f"piece {n} is refused")
    return n


def test_workers_give_each_result_in_order_as_in_process():
    items = list(range(6))
    serial = list(forked.map_in_order(_piece, items, 1))
    _MEMO.clear()
    parallel = list(forked.map_in_order(_piece, items, 2))
    assert [r["n"] for r in parallel] == items
    assert parallel[0]["pid"] == os.getpid()  # the first here: the workers inherit its loads
    assert all(r["pid"] != os.getpid() for r in parallel[1:])  # the others in the workers
    assert all(s["pid"] == os.getpid() for s in serial)
    for s, p in zip(serial, parallel, strict=True):
        for key in ("mask", "grid", "x", "small", "view"):
            assert p[key].dtype == s[key].dtype and p[key].shape == s[key].shape
            np.testing.assert_array_equal(p[key], s[key])
    # what the workers added to a shared memo is in this process's
    assert [_MEMO[("piece", n)] for n in items] == [n * n for n in items]


def test_warnings_are_said_again_in_order_and_once_per_place():
    token = uuid.uuid4().hex  # fresh texts: no earlier test's registry hides them
    work = _warning_piece(token)
    with warnings.catch_warnings(record=True) as serial:
        warnings.simplefilter("always")
        list(forked.map_in_order(work, range(5), 1))
    with warnings.catch_warnings(record=True) as parallel:
        warnings.simplefilter("always")
        list(forked.map_in_order(work, range(5), 2))

    def said(caught):
        return [(str(w.message), w.category, w.filename, w.lineno) for w in caught]

    assert said(parallel) == said(serial)
    assert len(serial) == 7
    # the default action shows a text once per place: the workers' repeats are judged here
    once = _warning_piece(uuid.uuid4().hex)
    with warnings.catch_warnings(record=True) as parallel:
        warnings.simplefilter("default")
        list(forked.map_in_order(once, range(5), 2))
    assert len(parallel) == 6  # 5 pieces' own, the odd pieces' common text once


def test_a_failing_piece_raises_here_after_the_pieces_before_it():
    seen = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(InputError, match="piece 2 is refused"):
            for result in forked.map_in_order(_failing, range(5), 2):
                seen.append(result)
    assert seen == [0, 1]
    # the failing piece's warning once (from its run here), none of the pieces after it
    assert [str(w.message) for w in caught] == [
        f"before the failure of piece {n}" for n in (0, 1, 2)]


def test_processes_are_used_only_for_pieces_worth_a_fork(tmp_path, monkeypatch):
    small = tmp_path / "small.bin"
    small.write_bytes(b"x" * 1000)
    monkeypatch.delenv(forked.ENVIRONMENT, raising=False)
    assert forked.processes(4, [small] * 4) == 1
    assert forked.processes(1, [small]) == 1
    big = tmp_path / "big.bin"
    with open(big, "wb") as handle:
        handle.truncate(forked.MIN_BYTES_PER_PIECE)  # sparse: its size is what counts
    assert forked.processes(3, [big] * 3) == min(forked.idle_cores(), 3)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.0, 0.0, 0.0))  # an idle machine
    cores = len(os.sched_getaffinity(0))
    assert forked.processes(3, [big] * 3) == min(cores, 3)
    monkeypatch.setattr(os, "getloadavg", lambda: (cores + 0.5, 0.0, 0.0))  # busy: still
    assert forked.processes(3, [big] * 3) == min(cores, 3)
    monkeypatch.setattr(os, "getloadavg", lambda: (2.0 * cores, 0.0, 0.0))  # overloaded
    assert forked.processes(3, [big] * 3) == 1
    monkeypatch.setenv(forked.ENVIRONMENT, "1")
    assert forked.processes(3, [big] * 3) == 1
    monkeypatch.setenv(forked.ENVIRONMENT, "8")
    assert forked.processes(3, [small] * 3) == 3  # forced, at most one per piece


_COMMAND = os.getpid()


def _killed_in_a_worker(n: int) -> int:
    """Piece 2 dies in a worker (as the kernel's OOM killer ends it), not in the command."""
    if n == 2 and os.getpid() != _COMMAND:
        os.kill(os.getpid(), 9)
    return n * 10


def test_a_worker_killed_mid_piece_neither_hangs_nor_loses_a_piece():
    # multiprocessing.Pool would wait forever for the lost piece; the rest run here
    assert list(forked.map_in_order(_killed_in_a_worker, list(range(6)), 2)) == [
        0, 10, 20, 30, 40, 50]
