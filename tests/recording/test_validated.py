"""A file validated to its end is not validated again by a later pass with the same options
(hrgtc.recording.validated): the same chunks, the same warnings, and a changed file or
other options validated anew."""

from __future__ import annotations

import os
import warnings
from unittest import mock

import numpy as np
import pytest

from hrgtc.core.errors import GapWarning, RecordingError
from hrgtc.recording import Metadata, ReadOptions, Recording, iter_chunks, validated, write
from hrgtc.recording.validation import HEURISTIC_ROWS, RecordingValidator

RATE_HZ = 200.0


def _recording(n: int = 3000, pause_at: int | None = None, seed: int = 0) -> Recording:
    rng = np.random.default_rng(seed)
    time_s = np.arange(n) / RATE_HZ
    if pause_at is not None:  # a pause of 2 s: bridged by default, with a GapWarning
        time_s[pause_at:] += 2.0
    columns = {"time_s": time_s, "freq_hz": 4425.0 + 0.01 * rng.standard_normal(n),
               "rate_dph": 10.0 + 2.0 * rng.standard_normal(n),
               "housing_c": 21.0 + 0.1 * rng.standard_normal(n)}
    return Recording(columns, Metadata(sample_rate_hz=RATE_HZ, unit="u"))


@pytest.fixture(autouse=True)
def _fresh():
    validated.forget()
    yield
    validated.forget()


def _passes(path, options, times=2):
    """The chunks of ``times`` passes and how many chunks each validator saw."""
    seen: list[int] = []
    real = RecordingValidator.partial_fit

    def counted(self, chunk, file_rows=None):
        seen.append(len(chunk))
        return real(self, chunk, file_rows)

    out = []
    with mock.patch.object(RecordingValidator, "partial_fit", counted):
        for _ in range(times):
            before = len(seen)
            chunks = list(iter_chunks(path, options, chunk_rows=700))
            out.append((chunks, len(seen) - before))
    return out


def test_a_second_pass_yields_the_same_chunks_without_validating(tmp_path):
    path = tmp_path / "run.parquet"
    write(_recording(), path)
    (first, checked_first), (second, checked_second) = _passes(path, ReadOptions())
    assert checked_first == 5 and checked_second == 0  # 3000 rows in chunks of 700
    assert len(first) == len(second) == 5
    for a, b in zip(first, second, strict=True):
        assert a.names == b.names and a.metadata == b.metadata
        for name in a.names:
            assert np.array_equal(a[name].view(np.int64), b[name].view(np.int64))


def test_other_options_or_a_changed_file_are_validated_again(tmp_path):
    path = tmp_path / "run.parquet"
    write(_recording(), path)
    _passes(path, ReadOptions(), times=1)
    [(_, checked)] = _passes(path, ReadOptions(spike_filter="drop"), times=1)
    assert checked == 5  # other options: validated
    bad = _recording(seed=1)
    bad = bad.with_columns(freq_hz=np.where(np.arange(3000) == 2500, np.nan, bad.freq_hz))
    write(bad, path, force=True)  # the same name, another file: its problem is found
    with pytest.raises(RecordingError, match="row 2500"):
        _passes(path, ReadOptions(), times=1)


def test_a_pass_left_early_or_refused_remembers_nothing(tmp_path):
    path = tmp_path / "run.parquet"
    write(_recording(n=HEURISTIC_ROWS + 20_000), path)  # more rows than the first look
    chunks = iter_chunks(path, ReadOptions(), chunk_rows=HEURISTIC_ROWS)
    next(chunks)
    chunks.close()  # a head: the rest of the file was never checked
    [(_, checked)] = _passes(path, ReadOptions(), times=1)
    assert checked == 172  # 120 000 rows in chunks of 700


def test_the_warnings_of_the_validation_are_said_on_every_pass(tmp_path):
    path = tmp_path / "run.parquet"
    write(_recording(pause_at=1500), path)
    for _ in range(2):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            list(iter_chunks(path, ReadOptions(), chunk_rows=700))
        gaps = [str(w.message) for w in caught if issubclass(w.category, GapWarning)]
        assert len(gaps) == 1 and "1 dropout(s) no longer than 5 s" in gaps[0]


def test_a_file_rewritten_in_place_with_its_time_and_size_is_validated_again(tmp_path):
    path = tmp_path / "run.csv"
    good = "time_s,freq_hz,rate_dph\n" + "".join(
        f"{k / RATE_HZ:.3f},4425.000,10.000\n" for k in range(400))
    path.write_text(good)
    stat = path.stat()
    list(iter_chunks(path, ReadOptions(), chunk_rows=100))
    bad = good[:-len("4425.000,10.000\n")] + "4425.000,   nan\n"  # same size, last row NaN
    assert len(bad) == len(good)
    path.write_text(bad)
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # the same modification time
    with pytest.raises(RecordingError, match="rate_dph"):
        list(iter_chunks(path, ReadOptions(), chunk_rows=100))
