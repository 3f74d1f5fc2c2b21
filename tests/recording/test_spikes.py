"""Tests of hrgtc.recording.spikes: ``spikes="error"`` names the row, ``"drop"`` removes it.

Truth: the rows the test corrupts. Dropping them must leave exactly the other
rows, bit for bit, whole or streamed in chunks, and say how many went.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from hrgtc.core.errors import InputError, RecordingError, SpikeWarning
from hrgtc.recording import ReadOptions, Recording, describe, iter_chunks, read, write

RATE_HZ = 100.0
N = 500
SPIKES = {"rate_dph_y": (37, 1e30), "temperature_c": (211, -9999.0), "freq_hz_x": (402, 5400.0),
          "rate_dph_x": (450, float("nan"))}


def spiky_csv(tmp_path):
    rng = np.random.default_rng(11)
    columns = {
        "time_s": np.arange(N) / RATE_HZ,
        "freq_hz_x": 4425.0 + 0.01 * rng.standard_normal(N),
        "rate_dph_x": 10.0 + rng.standard_normal(N),
        "freq_hz_y": 4431.0 + 0.01 * rng.standard_normal(N),
        "rate_dph_y": -4.0 + rng.standard_normal(N),
        "temperature_c": 25.0 + 0.01 * rng.standard_normal(N),
    }
    clean = {k: v.copy() for k, v in columns.items()}
    for name, (row, value) in SPIKES.items():
        columns[name][row] = value
    path = tmp_path / "spiky.csv"
    with open(path, "w") as out:
        out.write("# sample_rate_hz: 100\n" + ",".join(columns) + "\n")
        for i in range(N):
            out.write(",".join(repr(float(columns[k][i])) for k in columns) + "\n")
    return path, clean


def test_spikes_error_names_file_column_row_and_value(tmp_path):
    path, _ = spiky_csv(tmp_path)
    with pytest.raises(RecordingError) as info:
        read(path)
    message = str(info.value)
    assert message.startswith(str(path))
    assert "column 'rate_dph_y', row 37: 1e+30 °/h" in message
    assert "column 'temperature_c', row 211: -9999 °C" in message
    assert "column 'freq_hz_x', row 402: 5400 Hz" in message
    assert "column 'rate_dph_x', row 450: value nan is not finite" in message
    assert "--spikes drop" in message


def test_spikes_drop_removes_exactly_those_rows(tmp_path):
    path, clean = spiky_csv(tmp_path)
    keep = np.ones(N, bool)
    keep[[row for row, _ in SPIKES.values()]] = False
    with pytest.warns(SpikeWarning, match=r"dropped 4 row\(s\).*column 'rate_dph_y', row 37"):
        rec = read(path, spikes="drop")
    assert len(rec) == N - 4
    assert rec.metadata.extra["spikes_dropped"] == 4
    for name, values in clean.items():
        np.testing.assert_array_equal(rec[name], values[keep])
    with pytest.warns(SpikeWarning, match=r"dropped 4 row\(s\)"):
        chunks = list(iter_chunks(path, chunk_rows=64, spikes="drop"))
    for name, values in clean.items():
        np.testing.assert_array_equal(np.concatenate([c[name] for c in chunks]), values[keep])


def test_clean_file_is_untouched_and_silent(tmp_path):
    path, clean = spiky_csv(tmp_path)
    rec = read(path, validate=False)
    clean_path = write(Recording(clean, rec.metadata), tmp_path / "clean.parquet")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = ReadOptions(spikes="drop").read(clean_path)
    assert "spikes_dropped" not in again.metadata.extra
    for name, values in clean.items():
        np.testing.assert_array_equal(again[name], values)


def test_unknown_spike_policy(tmp_path):
    path, _ = spiky_csv(tmp_path)
    with pytest.raises(InputError, match=r"spikes must be one of \['error', 'drop'\]"):
        read(path, spikes="interpolate")


@pytest.mark.parametrize("rows", [None, 64, 1000])
def test_a_later_error_names_the_file_row_after_spikes_were_dropped(tmp_path, rows):
    """Spikes dropped before validation (rows 37, 211, 402 and 450 of the file) do not shift
    a later problem's row: it is the row of the file (0 = the first data row, as in every
    message), read whole or in chunks (issue 20 item 10)."""
    path, _ = spiky_csv(tmp_path)
    lines = path.read_text().splitlines()
    header = 2  # the metadata comment and the column names
    fields = lines[header + 470].split(",")
    fields[0] = repr(float(fields[0]) - 1.0)  # data row 470: the time steps back 1 s
    lines[header + 470] = ",".join(fields)
    path.write_text("\n".join(lines) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SpikeWarning)
        with pytest.raises(RecordingError) as info:
            if rows is None:
                read(path, spikes="drop")
            else:
                list(iter_chunks(path, chunk_rows=rows, spikes="drop"))
    message = " ".join(str(info.value).split())
    assert "column 'time_s', row 470:" in message, message
    assert "row 466" not in message  # the row among the rows kept (four spikes before it)
    if rows is not None:  # info validates the chunks itself: the same rows
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SpikeWarning)
            report = describe(path, rows=rows, spikes="drop").validation
        assert "column 'time_s', row 470:" in " ".join(report.message.split())
