"""Tests of hrgtc.recording.spikes: ``spikes="error"`` names the row, ``"drop"`` removes it.

Truth: the rows the test corrupts. Dropping them must leave exactly the other
rows, bit for bit, whole or streamed in chunks, and say how many went.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from hrgtc.core.errors import InputError, RecordingError, SpikeWarning
from hrgtc.recording import ReadOptions, Recording, iter_chunks, read, write

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
        chunks = list(iter_chunks(path, rows=64, spikes="drop"))
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
