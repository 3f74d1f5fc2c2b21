"""``compensate``'s motion detector runs beside the compensating pass (issue 27, item 8).

The detector's pass (``at_rest`` flags) and the compensation of the first chunk overlap; the
chunk waits for the flags only to be written. ``--motion error`` and a model whose output
depends on the flags wait for them first. The output is that of the serial order, bit for
bit (the compensation of a chunk does not read the flags but for orientation offsets).
"""

from __future__ import annotations

import threading

import numpy as np
import pytest

from compensate.test_at_rest_rows import CHUNK, handled
from hrgtc import drift
from hrgtc import recording as recording_io
from hrgtc.compensate import compensate_file, file_pass
from hrgtc.compensate.at_rest import RestFlags
from hrgtc.compensate.compensator import Compensator
from hrgtc.core.errors import CalibrationError
from hrgtc.drift.rest import run_rest
from hrgtc.model import AxisModel, Model
from hrgtc.settings.compensation import CompensateSettings

from synthetic import THERMOMETER, ramp_run

#: Longest wait for the other thread (a serial order never sets the event: the test fails).
WAIT_S = 60.0


@pytest.fixture(scope="module")
def unit_model():
    return Model.single(
        AxisModel(THERMOMETER, drift.fit([ramp_run(seed=21, hours=3.0)], THERMOMETER)))


@pytest.fixture(scope="module")
def source(tmp_path_factory):
    return recording_io.write(handled(), tmp_path_factory.mktemp("overlap") / "run.parquet")


def _run(source, out, model, **options):
    return compensate_file(source, out, model, settings=CompensateSettings(chunk_rows=CHUNK),
                           read_options=recording_io.ReadOptions(**options))


def test_the_first_chunk_is_compensated_while_the_detector_runs(unit_model, source, tmp_path,
                                                                 monkeypatch):
    """The detector waits until the first chunk is compensated: in a serial order (the
    flags first) it would wait for ever; here it finishes and the flags are right."""
    compensated = threading.Event()
    threads = {}
    transform = Compensator.transform

    def first_transform(self, chunk, at_rest=None):
        result = transform(self, chunk, at_rest)
        threads.setdefault("compensated", threading.get_ident())
        compensated.set()
        return result

    class WaitingFlags(RestFlags):
        def __init__(self, *args, **kwargs):
            threads["detector"] = threading.get_ident()
            assert compensated.wait(WAIT_S), "the first chunk was not compensated meanwhile"
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(Compensator, "transform", first_transform)
    monkeypatch.setattr(file_pass, "RestFlags", WaitingFlags)
    summary = _run(source, tmp_path / "out.parquet", unit_model)
    assert threads["detector"] != threads["compensated"]
    written = recording_io.read(tmp_path / "out.parquet")
    expected = run_rest(recording_io.ReadOptions().chunks(source, rows=CHUNK), "exclude").keep
    assert 0 < np.count_nonzero(~expected) < expected.size  # the bursts are found
    np.testing.assert_array_equal(written["at_rest"], expected.astype(np.float64))
    assert summary.accounting.to_dict()["flagged"]["motion"] == np.count_nonzero(~expected)


def test_the_output_is_that_of_the_serial_order(unit_model, source, tmp_path, monkeypatch):
    """With the detector made to finish first (the serial order), every column is the same,
    bit for bit."""
    _run(source, tmp_path / "overlap.parquet", unit_model)
    monkeypatch.setattr(Compensator, "needs_rest", property(lambda self: True))
    _run(source, tmp_path / "serial.parquet", unit_model)
    overlap = recording_io.read(tmp_path / "overlap.parquet")
    serial = recording_io.read(tmp_path / "serial.parquet")
    assert overlap.names == serial.names and "at_rest" in overlap.names
    for name in overlap.names:
        assert np.array_equal(overlap[name].view(np.int64), serial[name].view(np.int64)), name


@pytest.mark.parametrize("why", ["motion error", "orientation offsets"])
def test_flags_first_where_they_decide(why, unit_model, source, tmp_path, monkeypatch):
    """``--motion error`` stops at the first moving sample before anything is compensated;
    a model whose output reads the flags gets them before its first chunk."""
    order: list[str] = []
    transform = Compensator.transform

    def recorded(self, chunk, at_rest=None):
        order.append("compensated" if at_rest is None else "compensated with flags")
        return transform(self, chunk, at_rest)

    class RecordedFlags(RestFlags):
        def __init__(self, *args, **kwargs):
            try:
                super().__init__(*args, **kwargs)
            finally:
                order.append("flags")

    monkeypatch.setattr(Compensator, "transform", recorded)
    monkeypatch.setattr(file_pass, "RestFlags", RecordedFlags)
    if why == "motion error":
        with pytest.raises(CalibrationError, match=r"not at rest|moving|motion"):
            _run(source, tmp_path / "out.parquet", unit_model, motion="error")
        assert order == ["flags"]
        assert not (tmp_path / "out.parquet").exists()
    else:
        monkeypatch.setattr(Compensator, "needs_rest", property(lambda self: True))
        _run(source, tmp_path / "out.parquet", unit_model)
        assert order[0] == "flags" and set(order[1:]) == {"compensated with flags"}
