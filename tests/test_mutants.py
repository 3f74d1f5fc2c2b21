"""Tests for the bugs a developer could plausibly make (issue 21, Deliver 8).

A hand-made mutation check found plausible one-token bugs that no test caught. Each
test below fails on its mutant (made by hand, the test run, the change reverted):

* ``split_at_gaps`` / the validator: ``(1.0 + GAP_TOLERANCE)`` -> ``(1.0 - ...)`` reads a
  step of exactly two periods (one missing sample) as a gap;
* duplicated column names read (the CSV reader, the Parquet reader);
* ``range_report``'s ``* 3600.0`` -> ``/ 3600.0`` (or dropped): the °C/h figures;
* the model-file check of an ordered training range removed;
* ``write_text_atomic`` writing ``path`` in place instead of a temporary file;
* ``Thermometer.in_range``'s ``f >= low`` -> ``f > low`` (the lower calibration edge), and
  the same edge of the compensator's training ranges.

The df/dt-state-between-runs and gap-on-chunk-boundary mutants belong to the
streaming tests (``tests/compensate``).
"""

from __future__ import annotations

import dataclasses
import errno
import json
import os
import re
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from hrgtc.compensate import Compensator
from hrgtc.core.errors import ModelFileError, RecordingError
from hrgtc.core.files import write_text_atomic
from hrgtc.model import load_model, save_model
from hrgtc.recording import Metadata, Recording, read, split_at_gaps, validate, write

from fuzzing import make_model
from synthetic import THERMOMETER, ramp_run


@pytest.fixture(scope="module")
def model():
    return make_model()


# -- the gap threshold's tolerance -----------------------------------------------------------
def _times_with_one_sample_dropped(rate_hz: float = 10.0, rows: int = 200) -> np.ndarray:
    """Times i/rate with one sample removed where the double step rounds above 2 periods."""
    t = np.arange(rows) / rate_hz
    step = t[2:] - t[:-2]
    k = int(np.flatnonzero(step > 2.0 / rate_hz)[0]) + 1  # rounding makes it 2.0000000000004
    assert t[k + 1] - t[k - 1] > 2.0 / rate_hz  # the case the tolerance exists for
    return np.delete(t, k)


def _recording(time_s: np.ndarray) -> Recording:
    n = time_s.size
    rng = np.random.default_rng(1)
    return Recording({"time_s": time_s, "freq_hz": np.full(n, 4428.0) + rng.normal(0, 1e-3, n),
                      "rate_dph": 10.0 + rng.normal(0.0, 1.0, n)},
                     Metadata(sample_rate_hz=10.0, input_rate_dph=10.0))


def test_a_step_of_exactly_two_periods_is_not_a_gap():
    run = _recording(_times_with_one_sample_dropped())
    assert len(split_at_gaps(run)) == 1
    report = validate(run, gaps="error", raise_errors=False)
    assert report.n_gaps == 0 and report.ok, report.problems


def test_a_step_just_over_two_periods_is_a_gap():
    t = np.arange(200) / 10.0
    t[100:] += 0.1001  # a step of 2.001 periods
    run = _recording(t)
    assert [len(s) for s in split_at_gaps(run)] == [100, 100]
    with pytest.raises(RecordingError, match=r"column 'time_s', row 100: 1 gap"):
        validate(run, gaps="error", dropout_s=0.0)  # no dropout: the gap itself refused
    assert validate(run, gaps="error").n_dropouts == 1  # 0.2 s: a dropout, bridged


# -- duplicated column names -----------------------------------------------------------------
def test_duplicated_column_names_are_refused_by_every_reader(tmp_path):
    run = _recording(np.arange(200) / 10.0)
    text = write(run, tmp_path / "r.csv").read_text().replace("freq_hz,rate_dph",
                                                                "rate_dph,rate_dph")
    (tmp_path / "dup.csv").write_text(text)
    with pytest.raises(RecordingError, match=r"dup.csv: columns 2 and 3 .* both named 'rate_dph'"):
        read(tmp_path / "dup.csv")
    table = pa.Table.from_arrays([pa.array(run[k]) for k in run.names],
                                 names=["time_s", "rate_dph", "rate_dph"])
    pq.write_table(table, tmp_path / "dup.parquet")
    with pytest.raises(RecordingError, match=r"dup.parquet: columns 2 and 3 are both named "
                       r"'rate_dph'"):
        read(tmp_path / "dup.parquet", metadata={"sample_rate_hz": 10.0})


# -- °C/h of the range report ----------------------------------------------------------------
def test_the_range_report_gives_the_resonators_rate_in_degrees_per_hour(model):
    for start_c, end_c in ((20.0, -20.0), (-20.0, 20.0)):  # a cool-down and a warm-up
        run = ramp_run(seed=4, start_c=start_c, end_c=end_c, hours=3.0)
        compensator = Compensator(model, engine="numpy")
        compensator.transform(run)
        seen = compensator.ranges().seen_rate_c_per_h
        # truth: the simulated resonator temperature's own rate, °C/s * 3600
        true_rate = np.diff(run["resonator_c"]) * run.metadata.sample_rate_hz * 3600.0
        fastest = true_rate.min() if end_c < start_c else true_rate.max()
        assert 10.0 < abs(fastest) < 25.0  # ~ 19 °C/h at its fastest
        assert seen[0 if end_c < start_c else 1] == pytest.approx(fastest, rel=0.25)
    trained = compensator.ranges().trained_rate_c_per_h
    assert -25.0 < trained[0] < -10.0 and abs(trained[1]) < 2.0  # trained on a cool-down


# -- a reversed training range in a model file -----------------------------------------------
@pytest.mark.parametrize("place", ["drift.ranges.f", "drift.ranges.df",
                                   "thermometer.temperature_range_c"])
def test_a_reversed_range_in_a_model_file_is_refused(model, tmp_path, place):
    data = json.loads(save_model(model, tmp_path / "m.json").read_text())
    parent = data
    *path, last = place.split(".")
    for key in path:
        parent = parent[key]
    parent[last] = list(reversed(parent[last]))
    data.pop("parameters_sha256")
    (tmp_path / "r.json").write_text(json.dumps(data))
    escaped = re.escape(place)
    with pytest.raises(ModelFileError,
                       match=rf"r.json.*{escaped}.*(reversed|not an ordered range)"):
        load_model(tmp_path / "r.json")


# -- write_text_atomic never writes in place -------------------------------------------------
def test_write_text_atomic_writes_a_temporary_file_and_a_failure_leaves_the_old_file(
        tmp_path, monkeypatch):
    target = tmp_path / "model.json"
    target.write_text("old content\n")
    written: list[str] = []

    def failing_fsync(fd: int) -> None:
        written.append(os.readlink(f"/proc/self/fd/{fd}"))
        raise OSError(errno.EIO, "Input/output error")

    monkeypatch.setattr(os, "fsync", failing_fsync)
    with pytest.raises(OSError):
        write_text_atomic(target, "new content\n", force=True)
    assert target.read_text() == "old content\n"
    where = Path(written[0])
    assert where.parent == tmp_path and where != target
    assert where.name.startswith(".model.json.") and where.name.endswith(".tmp")
    assert sorted(tmp_path.iterdir()) == [target]  # the temporary file is gone
    monkeypatch.undo()
    write_text_atomic(target, "new content\n", force=True)
    assert target.read_text() == "new content\n"


# -- the lower calibration edge --------------------------------------------------------------
def test_the_calibrated_range_includes_its_lower_and_upper_edges():
    low, high = THERMOMETER.frequency_range_hz
    f = np.array([np.nextafter(low, -np.inf), low, high, np.nextafter(high, np.inf)])
    assert THERMOMETER.in_range(f).tolist() == [False, True, True, False]


def test_the_training_range_includes_its_lower_edge_in_compensation(model):
    low, high = model.drift.ranges["f"]
    reference = model.drift.settings.reference_freq_hz
    edge = reference + low
    low = edge - reference  # the f that the compensator computes at that frequency
    drift = dataclasses.replace(model.drift, ranges={**model.drift.ranges, "f": (low, high)})
    # 120 s at 10 Hz: the first 50 s settle (counted as settling, never as out of range),
    # then 10 s mid-range and 60 s at the edge or one ulp below it (half of all samples)
    n = 1200
    for f_edge, outside in ((edge, 0.0), (np.nextafter(edge, -np.inf), 0.5)):
        freq = np.full(n, f_edge)
        freq[: n // 2] = reference + 0.5 * (low + high)
        run = Recording({"time_s": np.arange(n) / 10.0, "freq_hz": freq,
                         "rate_dph": np.full(n, 10.0)}, Metadata(sample_rate_hz=10.0))
        compensator = Compensator(model.with_parts(drift=drift), engine="numpy")
        compensator.transform(run)
        assert compensator.ranges().temperature_fraction == outside
