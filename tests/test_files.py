"""Tests of hrgtc.files.WriteBehind: the bytes reach the file unchanged, the thread syncs
what the file grows by, and a failed sync is raised, never lost.

Truth: the bytes written, read back; the synced offset against the file's size; an
injected EIO.
"""

from __future__ import annotations

import errno
import os
import time

import numpy as np
import pytest

from hrgtc.files import WriteBehind
from hrgtc.recording import Metadata, RecordingWriter


def _wait_for(condition, seconds: float = 10.0) -> bool:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.005)
    return True


def test_write_behind_keeps_every_byte_and_syncs_what_the_file_grows_by(tmp_path):
    path = tmp_path / "out.bin"
    pieces = [np.random.default_rng(k).bytes(100_000 + 4096 * k) for k in range(4)]
    with open(path, "wb") as stream:
        behind = WriteBehind(path, poll_s=60.0)  # only advance() wakes it
        for piece in pieces:
            stream.write(piece)
            stream.flush()
            behind.advance()
            size = stream.tell()
            assert _wait_for(lambda size=size: behind.synced == size)
        syncs = behind.syncs
        behind.advance()  # nothing new: no sync, no error
        time.sleep(0.05)
        assert behind.syncs == syncs and 1 <= syncs <= len(pieces)
        behind.close()
        behind.close()  # closed: a no-op
        behind.advance()
        os.fsync(stream.fileno())
    assert path.read_bytes() == b"".join(pieces)


def test_write_behind_finds_new_bytes_without_being_woken(tmp_path):
    path = tmp_path / "out.bin"
    with open(path, "wb") as stream:
        behind = WriteBehind(path, poll_s=0.01)
        stream.write(b"x" * 50_000)
        stream.flush()
        assert _wait_for(lambda: behind.synced == 50_000)
        behind.close()


def test_a_failed_sync_is_raised_by_close(tmp_path, monkeypatch):
    def failing(fd):
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(os, "fdatasync", failing, raising=False)
    monkeypatch.setattr(os, "fsync", failing)
    path = tmp_path / "out.bin"
    path.write_bytes(b"y" * 1000)
    behind = WriteBehind(path, poll_s=0.01)
    assert _wait_for(lambda: behind._error is not None)
    with pytest.raises(OSError, match=r"out\.bin: writing to disk failed") as caught:
        behind.close()
    assert caught.value.errno == errno.EIO
    discarded = WriteBehind(path, poll_s=0.01)
    assert _wait_for(lambda: discarded._error is not None)
    discarded.close(discard=True)  # the file is being thrown away: nothing raised


def test_a_recording_writer_whose_sync_fails_leaves_nothing(tmp_path, monkeypatch):
    def failing(fd):
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(os, "fdatasync", failing, raising=False)
    out = tmp_path / "run.parquet"
    writer = RecordingWriter(out, Metadata(sample_rate_hz=10.0), ["time_s", "rate_dph"])
    writer.write({"time_s": np.arange(100.0) / 10, "rate_dph": np.zeros(100)})
    writer.start_writeback()
    assert _wait_for(lambda: writer._behind._error is not None)
    with pytest.raises(OSError, match="writing to disk failed"):
        writer.close()
    assert list(tmp_path.iterdir()) == []  # no output, no temporary file
