"""A gzip-compressed CSV (``run.csv.gz``) reads as the same recording as the plain file.

Truth: the columns read from the compressed copy equal, bit for bit, those read from the
plain file (whole and in chunks, with the real tofupilot chamber file and a written one);
``hrgtc info`` prints the same figures; writing to ``.csv.gz`` is refused with what to do.
"""

from __future__ import annotations

import gzip
import shutil
from pathlib import Path

import numpy as np
import pytest
from tests.recording.test_formats import recording

from hrgtc.core.errors import RecordingError
from hrgtc.recording import iter_chunks, read, write
from hrgtc.recording.formats import format_for, open_streams, registry

DATA = Path(__file__).resolve().parents[1] / "data"
CHAMBER = DATA / "tofupilot-imu-chamber" / "imu_raw_data.csv"


def gzipped(source: Path, folder: Path) -> Path:
    target = folder / f"{source.name}.gz"
    with open(source, "rb") as plain, gzip.open(target, "wb") as packed:
        shutil.copyfileobj(plain, packed)
    return target


def assert_same(a, b) -> None:
    assert list(a.columns) == list(b.columns)
    for name in a.columns:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert a.metadata == b.metadata


def test_a_written_recording_reads_the_same_from_its_gzip_copy(tmp_path):
    plain = tmp_path / "run.csv"
    write(recording(), plain)
    packed = gzipped(plain, tmp_path)
    assert format_for(packed).name == "csv" and registry.is_recording(packed)
    assert_same(read(plain), read(packed))
    chunks = [c for c in iter_chunks(packed, chunk_rows=64)]
    assert len(chunks) > 1
    whole = read(plain)
    np.testing.assert_array_equal(np.concatenate([c["rate_dph"] for c in chunks]),
                                  whole["rate_dph"])


def test_the_real_chamber_file_reads_the_same_gzipped(tmp_path):
    (plain,), (packed,) = open_streams(CHAMBER), open_streams(gzipped(CHAMBER, tmp_path))
    assert packed.names == plain.names and packed.kinds() == plain.kinds()
    assert packed.count_rows() == plain.count_rows() == 8400
    names = [n for n, kind in plain.kinds().items() if kind == "numeric"]
    assert packed.read(names, set()).equals(plain.read(names, set()))
    plain.close()
    packed.close()


def test_writing_a_gzip_csv_is_refused_with_what_to_do(tmp_path):
    with pytest.raises(RecordingError, match=r"\.csv\.gz.*compress.*gzip"):
        write(recording(), tmp_path / "out.csv.gz")
    assert not (tmp_path / "out.csv.gz").exists()
