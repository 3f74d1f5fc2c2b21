"""The drift fit's later passes read only the columns it takes
(:mod:`hrgtc.pipeline.narrow_reading`): the same chunks as a whole pass, or a whole pass
from the first chunk that differs."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from hrgtc.drift.rest import RestPass
from hrgtc.drift.variables.registry import DRIFT_VARIABLES
from hrgtc.drift.windows import _EXTRA_COLUMNS
from hrgtc.pipeline.narrow_reading import NARROW_COLUMNS, PassPrints
from hrgtc.recording import ReadOptions
from hrgtc.recording.validated import forget
from hrgtc.simulate import simulate_files
from hrgtc.simulate import standard_profiles as profiles

pytestmark = pytest.mark.filterwarnings("ignore:.*single-sample spikes removed")


@pytest.fixture(scope="module")
def soak(tmp_path_factory):
    """A 3 h soak at 2 Hz (7 columns, 3 of them no drift pass takes), with spikes."""
    folder = tmp_path_factory.mktemp("narrow")
    run = simulate_files([profiles.soak(10.0, 3.0)], folder, "parquet", unit="paper-unit",
                         sample_rate_hz=2.0, seed=4)[0]
    table = pq.read_table(run.path)
    rate = table["rate_dph"].to_numpy().copy()
    rate[[1000, 5003, 9011, 17000]] += 500.0  # single-sample spikes the filter drops
    column = table.schema.get_field_index("rate_dph")
    pq.write_table(table.set_column(column, table.schema.field(column), pa.array(rate)),
                   run.path)
    return run.path


OPTIONS = ReadOptions(chunk_rows=4000).with_spike_default("drop")


def _whole(path, options=OPTIONS):
    dropped: dict[str, int] = {}
    return list(options.chunks(path, dropped=dropped)), dropped


def _same_columns(chunks, whole):
    assert len(chunks) == len(whole)
    for ours, theirs in zip(chunks, whole, strict=True):
        assert ours.metadata == theirs.metadata and ours.source == theirs.source
        for name in NARROW_COLUMNS:
            if name in theirs:
                np.testing.assert_array_equal(ours[name], theirs[name], strict=True)


def test_every_column_a_drift_pass_takes_is_read():
    """A variable, the at-rest detector or the window pass that takes a column the
    narrow pass leaves out would see it missing (or fall back on every file)."""
    taken = {c for v in DRIFT_VARIABLES for c in v.columns}
    taken |= set(RestPass.WANTED) | set(_EXTRA_COLUMNS) | {"time_s", "rate_dph"}
    assert taken <= set(NARROW_COLUMNS)


def test_a_pass_after_a_whole_one_reads_fewer_columns_and_the_same_rows(soak):
    forget()
    whole, dropped = _whole(soak)
    assert "chamber_c" in whole[0] and "bias_dph" in whole[0]
    prints = PassPrints()
    first = list(prints.whole(soak, OPTIONS.chunks(soak)))  # remembered: ran to the end
    assert len(first) == len(whole) > 3
    narrow_dropped: dict[str, int] = {}
    narrow = list(prints.chunks(OPTIONS, soak, narrow_dropped))
    assert "chamber_c" not in narrow[0] and "bias_dph" not in narrow[0]
    _same_columns(narrow, whole)
    assert narrow_dropped == dropped and dropped["spikes"] > 0


def test_a_chunk_that_differs_from_the_whole_pass_reads_every_column_from_there(soak):
    forget()
    whole, dropped = _whole(soak)
    prints = PassPrints()
    for _ in prints.whole(soak, OPTIONS.chunks(soak)):
        pass
    prints.files[str(soak)][2] = ("another file's chunk",)
    got: dict[str, int] = {}
    chunks = list(prints.chunks(OPTIONS, soak, got))
    _same_columns(chunks, whole)
    assert ["chamber_c" in c for c in chunks[:3]] == [False, False, True]
    assert got == dropped


def test_a_pass_left_early_or_other_options_read_every_column(soak):
    forget()
    prints = PassPrints()
    head = prints.whole(soak, OPTIONS.chunks(soak))
    next(head)
    head.close()
    assert str(soak) not in prints.files  # not fingerprinted: read whole again
    assert "chamber_c" in next(prints.chunks(OPTIONS, soak, {}))
    for _ in prints.whole(soak, OPTIONS.chunks(soak)):
        pass
    other = ReadOptions(chunk_rows=4000, spike_filter="drop", spikes="drop")
    assert "chamber_c" in next(prints.chunks(other, soak, {}))  # --spikes drop: whole
    forget()  # no validated whole pass known: whole
    assert "chamber_c" in next(prints.chunks(OPTIONS, soak, {}))
