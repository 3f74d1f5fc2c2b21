"""Tests of hrgtc.files.WriteBehind: the bytes reach the file unchanged, whichever path runs.

Truth: the bytes written, read back; the offsets the class reports against the file's size.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from hrgtc import files
from hrgtc.files import WriteBehind


@pytest.mark.parametrize("kernel_call", [True, False])
def test_write_behind_keeps_every_byte_and_tracks_the_pieces(tmp_path, monkeypatch, kernel_call):
    if not kernel_call:  # no sync_file_range: posix_fadvise, or nothing
        monkeypatch.setattr(files, "_sync_file_range", lambda: None)
    path = tmp_path / "out.bin"
    pieces = [np.random.default_rng(k).bytes(100_000 + 4096 * k) for k in range(4)]
    with open(path, "wb") as stream:
        behind = WriteBehind(path)
        sizes = []
        for piece in pieces:
            stream.write(piece)
            stream.flush()
            behind.advance()
            sizes.append(stream.tell())
            assert behind._started == sizes[-1]
            if kernel_call and behind._range is not None and len(sizes) > 1:
                assert behind._written == sizes[-2]  # the piece before is on disk
        behind.advance()  # nothing new: no error
        behind.close()
        behind.advance()  # closed: a no-op
        os.fsync(stream.fileno())
    assert path.read_bytes() == b"".join(pieces)
