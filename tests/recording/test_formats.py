"""Tests of hrgtc.recording.formats: the registry, each format's round trip, sniffing, plugins.

Truth: values written are compared bit for bit with values read; a plugin format is
found through a real entry point (a ``*.dist-info`` folder on the path), by the
library and by ``hrgtc info`` in a fresh process.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from hrgtc.core.errors import RecordingError
from hrgtc.recording import Metadata, Recording, RecordingWriter, iter_chunks, read, write
from hrgtc.recording.formats import (
    ENTRY_POINT_GROUP,
    Format,
    Sink,
    TableSource,
    format_for,
    formats,
    metadata_json,
    open_streams,
    registry,
)

WRITABLE = [fmt for fmt in formats() if fmt.sink is not None]


def recording(n: int = 300) -> Recording:
    rng = np.random.default_rng(7)
    columns = {
        "time_s": np.arange(n) / 10.0,
        "freq_hz": 4425.0 + 0.01 * rng.standard_normal(n),
        "rate_dph": 9.7 + rng.standard_normal(n),
        "housing_c": 21.0 + rng.standard_normal(n),
        "rate_dph_z_raw": rng.standard_normal(n),  # a column outside the contract
    }
    metadata = Metadata(sample_rate_hz=10.0, unit="SN 12 «α»", input_rate_dph=9.67,
                        profile="soak -10 C", extra={"seed": 7, "setpoints": [-10, 0]})
    return Recording(columns, metadata)


def test_the_built_in_formats_are_registered_once_with_their_suffixes():
    names = [fmt.name for fmt in formats()]
    assert names[:3] == ["parquet", "csv", "hdf5"]
    assert registry.suffixes() == {".parquet": "parquet", ".pq": "parquet", ".csv": "csv",
                                   ".csv.gz": "csv", ".h5": "hdf5", ".hdf5": "hdf5",
                                   **{s: f.name for f in formats()[3:] for s in f.suffixes}}
    assert registry.output_suffixes()["h5"] == ".h5"
    with pytest.raises(ValueError, match=r"suffix '\.csv' is already the format 'csv'"):
        registry.register(Format("other", (".csv",), TableSource))
    with pytest.raises(ValueError, match="already registered"):
        registry.register(Format("csv", (".txt",), TableSource))


@pytest.mark.parametrize("fmt", WRITABLE, ids=lambda f: f.name)
def test_every_writable_format_round_trips_table_and_metadata(fmt, tmp_path):
    original = recording()
    path = write(original, tmp_path / f"run{fmt.suffixes[0]}")
    assert format_for(path) is fmt
    back = read(path)
    assert back.names == original.names
    for name in original.names:  # bit for bit
        assert np.array_equal(back[name].view(np.int64), original[name].view(np.int64)), name
    assert back.metadata == original.metadata
    # and streamed: the format's batches, regrouped into chunks of 64 rows, give the same rows
    (stream,) = open_streams(path)
    with stream:
        tables = list(stream.iter_tables(["time_s", "rate_dph"], set(), 64))
    joined = np.concatenate([t.column("rate_dph").to_numpy() for t in tables])
    assert np.array_equal(joined, original.rate_dph)
    chunks = list(iter_chunks(path, chunk_rows=64))
    assert [len(c) for c in chunks] == [64, 64, 64, 64, 44]
    assert np.array_equal(np.concatenate([c["housing_c"] for c in chunks]), original["housing_c"])


def test_unknown_suffix_lists_the_registered_formats(tmp_path):
    path = tmp_path / "run.txt"
    path.write_text("t,f\n1,2\n", encoding="utf-8")
    with pytest.raises(RecordingError) as caught:
        read(path)
    message = str(caught.value)
    assert ("unknown file type '.txt'; use one of .parquet, .pq, .csv, .csv.gz, .h5, "
            ".hdf5") in message
    assert ("registered formats: parquet (.parquet, .pq); csv (.csv, .csv.gz); hdf5 (.h5, "
            ".hdf5)") in message
    with pytest.raises(RecordingError, match=r"unknown file type '\.txt'"):
        RecordingWriter(tmp_path / "out.txt", recording().metadata, ["time_s"])


def test_a_file_of_unknown_suffix_is_read_by_its_signature(tmp_path):
    original = recording()
    for suffix in (".parquet", ".h5", ".csv"):
        path = write(original, tmp_path / f"run{suffix}")
        renamed = path.rename(tmp_path / f"run_{suffix[1:]}.dat")  # a logger's own suffix
        assert np.array_equal(read(renamed).rate_dph, original.rate_dph)


def test_content_of_another_format_than_the_suffix_says_is_refused(tmp_path):
    path = write(recording(), tmp_path / "run.h5")
    wrong = path.rename(tmp_path / "run.parquet")
    with pytest.raises(RecordingError, match=r"run\.parquet: the file's content is hdf5 .* not "
                       r"parquet as its suffix '\.parquet' says; rename it to run\.h5"):
        read(wrong)


# -- a lab's own format through an entry point -----------------------------------------
def documented_plugin() -> str:
    """The example module of docs/architecture.md ("Adding a file format"), as written there."""
    text = (Path(__file__).resolve().parents[2] / "docs" / "architecture.md").read_text(
        encoding="utf-8")
    section = text[text.index("### Adding a file format"):]
    return section[section.index("```python\n") + 10:section.index("\n```", section.index(
        "```python\n"))] + "\n"


PLUGIN = documented_plugin()


@pytest.fixture
def plugin_dir(tmp_path):
    """A tiny installed distribution: a module and a dist-info with an entry point."""
    site = tmp_path / "site"
    (site / "mylab_hrgtc-1.0.dist-info").mkdir(parents=True)
    (site / "mylab_hrgtc.py").write_text(textwrap.dedent(PLUGIN), encoding="utf-8")
    (site / "mylab_hrgtc-1.0.dist-info" / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: mylab-hrgtc\nVersion: 1.0\n", encoding="utf-8")
    (site / "mylab_hrgtc-1.0.dist-info" / "entry_points.txt").write_text(
        f"[{ENTRY_POINT_GROUP}]\nmylab = mylab_hrgtc:FORMAT\n", encoding="utf-8")
    return site


def mylab_file(path: Path, n: int = 200) -> tuple[Path, np.ndarray]:
    rate = np.round(9.0 + np.sin(np.arange(n) / 7.0), 6)
    lines = ["MYLAB1", *(f"{i / 10.0!r} {4425.0 + i * 1e-4:.6f} {float(r)!r}" for i, r in
                        enumerate(rate))]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path, rate


def test_a_plugin_format_is_found_through_its_entry_point(plugin_dir, tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(plugin_dir))
    try:
        assert "mylab" in registry.load_plugins(force=True)
        path, rate = mylab_file(tmp_path / "run.mylab")
        rec = read(path)
        assert format_for(path).name == "mylab"
        np.testing.assert_array_equal(rec.rate_dph, rate)
        assert rec.metadata.unit == "mylab gyro"
        assert rec.metadata.sample_rate_hz == pytest.approx(10.0)  # inferred from time_s
        # sniffed under another suffix too
        other = path.rename(tmp_path / "run.log")
        np.testing.assert_array_equal(read(other).rate_dph, rate)
    finally:
        registry.unregister("mylab")
        sys.modules.pop("mylab_hrgtc", None)


def test_hrgtc_info_reads_a_plugin_format_in_a_fresh_process(plugin_dir, tmp_path):
    path, rate = mylab_file(tmp_path / "run.mylab")
    src = Path(__file__).resolve().parents[2] / "src"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(src), str(plugin_dir)])}
    done = subprocess.run([sys.executable, "-m", "hrgtc.cli", "info", str(path), "--json"],
                          capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    info = json.loads(done.stdout)
    assert info["format"] == "mylab" and info["rows"] == 200
    columns = {c["name"]: c for c in info["columns"]}
    assert info["validation"]["ok"]
    assert columns["rate_dph"]["max"] == pytest.approx(float(rate.max()))


def test_a_broken_plugin_is_left_out_with_a_warning(plugin_dir, monkeypatch):
    from hrgtc.core.errors import FormatPluginWarning

    (plugin_dir / "mylab_hrgtc-1.0.dist-info" / "entry_points.txt").write_text(
        f"[{ENTRY_POINT_GROUP}]\nmylab = mylab_hrgtc:NO_SUCH_NAME\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(plugin_dir))
    try:
        with pytest.warns(FormatPluginWarning, match="'mylab' .* was not loaded"):
            assert registry.load_plugins(force=True) == []
        assert "csv" in [f.name for f in formats()]
    finally:
        registry.unregister("mylab")
        sys.modules.pop("mylab_hrgtc", None)


class NpzSink(Sink):
    """numpy's .npz: chunks gathered, written at close; the metadata as JSON."""

    def __init__(self, path, metadata, names):
        super().__init__(path, metadata, names)
        self.metadata, self.parts = metadata, []

    def write(self, columns):
        self.parts.append({n: np.array(columns[n]) for n in self.names})

    def close(self):
        arrays = {n: np.concatenate([p[n] for p in self.parts]) for n in self.names}
        with open(self.path, "wb") as handle:  # np.savez would add a suffix to the temp name
            np.savez(handle, __metadata__=np.array(metadata_json(self.metadata)), **arrays)


def read_npz(path):
    with np.load(path) as data:
        columns = {n: data[n] for n in data.files if n != "__metadata__"}
        metadata = json.loads(str(data["__metadata__"]))
    return TableSource(path, columns, metadata)


def test_a_format_registered_at_run_time_writes_and_reads_through_the_registry(tmp_path):
    npz = Format("npz", (".npz",), read_npz, sink=NpzSink,
                 sniff=lambda head: head.startswith(b"PK\x03\x04"))
    registry.register(npz)
    try:
        original = recording()
        path = write(original, tmp_path / "run.npz")  # the writer chosen by the suffix
        back = read(path)
        for name in original.names:
            assert np.array_equal(back[name], original[name]), name
        assert back.metadata == original.metadata
        assert registry.output_suffixes()["npz"] == ".npz"
    finally:
        registry.unregister("npz")
    with pytest.raises(RecordingError, match=r"unknown file type '\.npz'"):
        read(path)
