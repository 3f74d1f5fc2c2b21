"""Tests of hrgtc.recording: formats, users' columns and units, validation, atomic writing.

Truth is independent of the code under test: values written are compared bit for
bit with values read; unit conversions against hand arithmetic (kHz × 1000,
°/s × 3600, rad/s × (180/π) × 3600, ms / 1000); timestamps against
datetime arithmetic; error rows against the rows the test corrupted.
"""

from __future__ import annotations

import datetime as dt
import math
import os
import string
import tempfile
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hrgtc.core.errors import InputError, OutputExistsError, RecordingError
from hrgtc.recording import (
    Metadata,
    Recording,
    RecordingWriter,
    ValidationReport,
    concatenate,
    count_rows,
    iter_chunks,
    parse_unit,
    read,
    split_at_gaps,
    validate,
    write,
)

SUFFIXES = [".parquet", ".csv", ".h5"]
RATE_HZ = 200.0


def make_recording(n: int = 400, seed: int = 0, bias: float = 10.0, noise: float = 2.0):
    rng = np.random.default_rng(seed)
    columns = {
        "time_s": np.arange(n) / RATE_HZ,
        "freq_hz": 4425.0 + 0.01 * rng.standard_normal(n),
        "rate_dph": bias + noise * rng.standard_normal(n),
        "chamber_c": 20.0 + rng.standard_normal(n),
        "housing_c": 21.0 + rng.standard_normal(n),
    }
    metadata = Metadata(
        sample_rate_hz=RATE_HZ,
        unit="HRG-7 «α»",
        input_rate_dph=9.67,
        profile='soak: -10 C, "quoted"\nsecond line',
        extra={"seed": seed, "setpoints": [-10, 0], "note": "x: y"},
    )
    return Recording(columns, metadata)


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def write_csv(path: Path, header: str, rows: np.ndarray, fmt: str = "%.17g") -> Path:
    np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt=fmt)
    return path


# -- round trips -----------------------------------------------------------------
@pytest.mark.parametrize("suffix", SUFFIXES)
def test_round_trip_is_bit_exact_with_metadata(tmp_path, suffix):
    recording = make_recording()
    awkward = np.array([1 / 3, 5e-324, 1.7976931348623157e308, -0.0, 0.1, 2.0**-1074 * 3])
    column = recording["chamber_c"].copy()
    column[: awkward.size] = awkward
    recording = recording.with_columns(chamber_c=column)
    path = write(recording, tmp_path / f"run{suffix}")
    back = read(path, validate=False)  # 1.8e308 °C is kept bit-exact, though implausible
    assert back.names == recording.names
    for name in recording.names:
        assert same_bits(back[name], recording[name]), name
    assert back.metadata == recording.metadata
    assert back.source == str(path)


@pytest.mark.parametrize("suffix", SUFFIXES)
@pytest.mark.parametrize("rows", [1, 37, 400, 1000])
def test_chunked_read_equals_whole_read(tmp_path, suffix, rows):
    recording = make_recording(n=400)
    path = write(recording, tmp_path / f"run{suffix}")
    whole = read(path)
    chunks = list(iter_chunks(path, chunk_rows=rows))
    assert [len(c) for c in chunks][:-1] == [rows] * (len(chunks) - 1)
    assert all(c.metadata == whole.metadata for c in chunks)
    joined = concatenate(chunks)
    for name in whole.names:
        assert same_bits(joined[name], whole[name])


def test_one_options_object_or_its_fields_by_name(tmp_path):
    """``read``, ``iter_chunks`` and ``describe`` take one ReadOptions and any of its
    fields by name (the name given wins); a name that is no reading option is refused,
    naming the options there are; a column mapping by position is refused."""
    from hrgtc.recording import ReadOptions, describe

    recording = make_recording(n=400)
    recording = recording.with_columns(rate_dph=recording.rate_dph / 3600.0)  # in °/s
    path = write_csv(tmp_path / "run.csv", "t,f,w", np.column_stack(
        [recording.time_s, recording.freq_hz, recording.rate_dph]))
    mapping = {"time_s": "t", "freq_hz": "f", "rate_dph": "w"}
    options = ReadOptions(columns=mapping, units={"rate": "dps"},
                          metadata={"sample_rate_hz": RATE_HZ}, start="0.5")
    by_object = read(path, options)
    by_name = read(path, columns=mapping, units={"rate": "dps"},
                   metadata={"sample_rate_hz": RATE_HZ}, start="0.5")
    overridden = read(path, options, start="1.0")
    assert len(by_object) == len(by_name) == 300 and len(overridden) == 200  # 200 Hz
    assert np.allclose(by_object.rate_dph, recording.rate_dph[100:] * 3600.0, rtol=1e-12)
    assert same_bits(by_object.rate_dph, by_name.rate_dph)
    chunks = list(iter_chunks(path, options, chunk_rows=64))
    assert [len(c) for c in chunks] == [64] * 4 + [44]
    assert same_bits(concatenate(chunks).freq_hz, by_object.freq_hz)
    assert describe(path, options).rows == describe(path, options, start=None).rows - 100
    for function in (read, describe, lambda p, **kw: list(iter_chunks(p, **kw))):
        with pytest.raises(TypeError, match=r"spike_treshold.*are columns, units, .*spike_k"):
            function(path, spike_treshold=3.0)
    with pytest.raises(TypeError, match=r"options must be ReadOptions.*columns="):
        read(path, mapping)


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_writer_streams_chunks_and_file_mode_follows_umask(tmp_path, suffix):
    recording = make_recording(n=1000)
    path = tmp_path / f"stream{suffix}"
    with RecordingWriter(path, recording.metadata, recording.names) as out:
        for start in range(0, 1000, 300):
            out.write(recording.slice(start, start + 300))
    assert out.rows == 1000
    back = read(path)
    assert all(same_bits(back[n], recording[n]) for n in recording.names)
    mask = os.umask(0)
    os.umask(mask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~mask
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_count_rows_without_reading(tmp_path, suffix):
    assert count_rows(write(make_recording(n=123), tmp_path / f"run{suffix}")) == 123


def test_count_rows_of_a_csv_with_blank_lines_and_crlf(tmp_path):
    path = tmp_path / "win.csv"
    path.write_bytes(b"# sample_rate_hz: 2\r\nt,f\r\n1,2\r\n\r\n\n3,4\r\n5,6")
    assert count_rows(path) == 3 == len(read(path, validate=False))


def test_csv_header_and_sidecar_metadata(tmp_path):
    recording = make_recording()
    path = write(recording, tmp_path / "run.csv")
    text = path.read_text(encoding="utf-8")
    assert "# sample_rate_hz: 200.0\n" in text and "# unit: HRG-7 «α»\n" in text
    sidecar = tmp_path / "run.csv.json"
    sidecar.write_text('{"unit": "SN-42", "operator": "ada"}', encoding="utf-8")
    back = read(path)
    assert back.metadata.unit == "SN-42"
    assert back.metadata.extra["operator"] == "ada"
    assert back.metadata.input_rate_dph == 9.67


def test_parquet_metadata_lives_in_the_schema(tmp_path):
    path = write(make_recording(), tmp_path / "run.parquet")
    schema = pq.read_schema(path)
    assert b"hrgtc" in schema.metadata
    assert schema.field("freq_hz").metadata[b"unit"] == b"Hz"


# -- users' columns and units ---------------------------------------------------------
def foreign_rows(n: int = 300, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t_ms = np.arange(n) * 5.0  # 200 Hz in milliseconds
    f_khz = 4.425 + 1e-5 * rng.standard_normal(n)
    return np.column_stack([t_ms, f_khz, 0.003 + 5e-4 * rng.standard_normal(n)])


@pytest.mark.parametrize(
    ("spelling", "scale"),
    [
        ("dps", 3600.0),
        ("°/s", 3600.0),
        ("deg/s", 3600.0),
        ("rad/s", 180.0 / math.pi * 3600.0),
        ("radps", 180.0 / math.pi * 3600.0),
    ],
)
def test_column_mapping_and_unit_conversion(tmp_path, spelling, scale):
    rows = foreign_rows()
    path = write_csv(tmp_path / "logger.csv", "t,f_res,omega", rows)
    recording = read(
        path,
        columns={"time_s": "t", "freq_hz": "f_res", "rate_dph": "omega"},
        units={"time": "ms", "freq": "kHz", "rate": spelling},
    )
    np.testing.assert_allclose(recording.time_s, rows[:, 0] / 1000, rtol=1e-15, atol=0)
    np.testing.assert_allclose(recording.freq_hz, rows[:, 1] * 1000, rtol=1e-15)
    np.testing.assert_allclose(recording.rate_dph, rows[:, 2] * scale, rtol=1e-14)
    assert recording.metadata.sample_rate_hz == pytest.approx(200.0, rel=1e-9)
    assert recording.metadata.extra["sample_rate_inferred"] is True


def test_unit_spellings():
    assert parse_unit("rate", "°/h") == "dph"
    assert parse_unit("rate", "DEG/S") == "dps"
    assert parse_unit("freq", "KHZ") == "kHz"
    assert parse_unit("time", "milliseconds") == "ms"
    with pytest.raises(InputError, match="unknown freq unit 'MHz'; use one of Hz, kHz"):
        parse_unit("freq", "MHz")


def test_iso_timestamps_become_seconds_since_first_sample(tmp_path):
    start = dt.datetime(2024, 5, 1, 23, 59, 59, 990000)
    times = [start + dt.timedelta(milliseconds=5 * k) for k in range(300)]
    rows = foreign_rows()
    lines = ["stamp,f,w"]
    for t, (_, f, w) in zip(times, rows, strict=True):
        lines.append(f"{t.isoformat()}Z,{float(f)!r},{float(w)!r}")
    path = tmp_path / "stamped.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    recording = read(
        path,
        columns={"time_s": "stamp", "freq_hz": "f", "rate_dph": "w"},
        units={"time": "timestamp", "freq": "kHz", "rate": "dps"},
        metadata={"sample_rate_hz": 200, "unit": "SN 9"},
    )
    expected = [(t - start).total_seconds() for t in times]
    np.testing.assert_allclose(recording.time_s, expected, rtol=0, atol=1e-12)
    assert recording.metadata.unit == "SN 9"
    assert recording.metadata.extra["time_origin"].startswith("2024-05-01T23:59:59.99")
    assert "sample_rate_inferred" not in recording.metadata.extra


def test_bad_timestamp_names_its_row(tmp_path):
    lines = ["when,freq_hz,rate_dph"]
    for k in range(300):
        stamp = f"2024-05-01T10:00:{k // 200:02d}.{(k % 200) * 5:03d}"
        lines.append(f"{'2024-05-01T10:00:61.5' if k == 123 else stamp},4425.0,{10 + k % 7}")
    path = tmp_path / "stamps.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(RecordingError, match=r"'when', row 123: '2024-05-01T10:00:61.5' is not an"):
        read(path, columns={"time_s": "when"}, units={"time": "timestamp"})


def test_parquet_datetime_column_is_recognised(tmp_path):
    start = dt.datetime(2023, 1, 2, 3, 4, 5)
    times = [start + dt.timedelta(microseconds=5000 * k) for k in range(300)]
    rows = foreign_rows()
    table = pa.table(
        {
            "when": pa.array(times, pa.timestamp("us")),
            "freq_hz": rows[:, 1] * 1000,
            "rate_dph": rows[:, 2] * 3600,
            "label": ["x"] * 300,
        }
    )
    path = tmp_path / "foreign.parquet"
    pq.write_table(table, path)
    recording = read(path, columns={"time_s": "when"})
    np.testing.assert_allclose(recording.time_s, np.arange(300) * 0.005, atol=1e-12)
    assert recording.names == ("time_s", "freq_hz", "rate_dph")  # text column dropped


def test_foreign_hdf5_at_root_and_chunked(tmp_path):
    import h5py

    rows = foreign_rows()
    path = tmp_path / "foreign.hdf5"
    with h5py.File(path, "w") as handle:
        handle["t"] = rows[:, 0]
        handle["f"] = rows[:, 1]
        handle["w"] = rows[:, 2]
        handle.attrs["sample_rate_hz"] = 200.0
    options = {
        "columns": {"time_s": "t", "freq_hz": "f", "rate_dph": "w"},
        "units": {"time": "ms", "freq": "kHz", "rate": "dps"},
    }
    whole = read(path, **options)
    joined = concatenate(list(iter_chunks(path, chunk_rows=64, **options)))
    assert same_bits(whole.freq_hz, joined.freq_hz)
    np.testing.assert_allclose(whole.freq_hz, rows[:, 1] * 1000, rtol=1e-15)
    assert "sample_rate_inferred" not in whole.metadata.extra


# -- validation: every promised error ----------------------------------------------
def corrupt(recording: Recording, name: str, row: int, value: float) -> Recording:
    column = recording[name].copy()
    column[row] = value
    return recording.with_columns(**{name: column})


def test_clean_recording_validates():
    report = validate(make_recording())
    assert isinstance(report, ValidationReport) and report.ok and report.problems == ()
    assert report.measured_sample_rate_hz == pytest.approx(RATE_HZ)
    assert ValidationReport.from_dict(report.to_dict()) == report
    assert "ok" in report.summary().text()


@pytest.mark.parametrize(
    ("name", "row", "value", "match"),
    [
        ("rate_dph", 17, np.nan, r"run\.h5: column 'rate_dph', row 17: value nan is not finite"),
        ("freq_hz", 3, np.inf, r"column 'freq_hz', row 3: value inf is not finite"),
        ("chamber_c", 399, -np.inf, r"column 'chamber_c', row 399: value -inf .*interpolate"),
        ("time_s", 5, 4 / RATE_HZ, r"'time_s', row 5: 0\.02 s after 0\.02 s is a duplicate time"),
        ("time_s", 9, 0.0, r"row 9: 0\.0 s after 0\.04 s is a step back in time.*neither a "
         r"counter wrap, a reset to zero nor a duplicated block.*split the file"),
    ],
)
def test_bad_values_name_file_column_row_and_fix(tmp_path, name, row, value, match):
    path = write(corrupt(make_recording(), name, row, value), tmp_path / "run.h5")
    with pytest.raises(RecordingError, match=match):
        read(path)
    report = read(path, validate=False)
    assert not validate(report, raise_errors=False).ok


def test_missing_required_column(tmp_path):
    recording = make_recording()
    columns = {k: v for k, v in recording.columns.items() if k != "freq_hz"}
    path = write(Recording(columns, recording.metadata), tmp_path / "run.parquet")
    with pytest.raises(RecordingError, match=r"'freq_hz' missing \(the recording's columns are "
                       r"\['time_s', 'rate_dph'.*\]\); .*--col freq_hz="):
        read(path)


def test_gaps_error_split_and_ignore(tmp_path):
    recording = make_recording(n=400)
    time = recording.time_s.copy()
    short = time.copy()
    short[250:] += 1.5  # 1.5 s without samples before row 250: a dropout, bridged, counted
    path = write(recording.with_columns(time_s=short), tmp_path / "dropout.csv")
    assert len(read(path)) == 400
    report = validate(read(path, validate=False))
    assert report.ok and (report.n_gaps, report.n_dropouts, report.dropout_s) == (1, 1, 5.0)
    time[250:] += 7.5  # 7.5 s: longer than a dropout, the choice changes the result
    path = write(recording.with_columns(time_s=time), tmp_path / "gappy.csv")
    with pytest.raises(RecordingError, match=r"row 250: 1 gap.*7\.505 s after t = 1\.245 s.*split"):
        read(path)
    with pytest.raises(RecordingError, match=r"row 250: 1 gap"):
        read(path.with_name("dropout.csv"), dropout_s=1.0)
    whole = read(path, gaps="split")
    report = validate(whole, gaps="split")
    assert report.ok and report.n_gaps == 1
    assert (report.gaps[0].row, report.gaps[0].duration_s) == (250, pytest.approx(7.505))
    segments = split_at_gaps(whole)
    assert [len(s) for s in segments] == [250, 150]
    assert same_bits(segments[1].time_s, time[250:])
    assert validate(whole, gaps="ignore").ok
    with pytest.raises(RecordingError, match=r"gaps must be one of"):
        validate(whole, gaps="fill")


def test_sample_rate_disagreeing_with_metadata(tmp_path):
    recording = make_recording()
    path = write(recording, tmp_path / "run.parquet")
    assert read(path, metadata={"sample_rate_hz": 199.0}).sample_rate_hz == 199.0  # 0.5 % off
    with pytest.raises(RecordingError, match=r"means 200 Hz but the metadata says .*202.*--rate"):
        read(path, metadata={"sample_rate_hz": 202.5})  # 1.25 % off
    in_ms = recording.with_columns(time_s=recording.time_s * 1000.0)
    write(in_ms, tmp_path / "ms.parquet")
    with pytest.raises(RecordingError, match=r"in milliseconds \(pass --time-unit ms.* or the "
                       r"metadata's rate is wrong.*--rate-hz 0\.2"):
        read(tmp_path / "ms.parquet")
    assert read(tmp_path / "ms.parquet", units={"time": "ms"}).time_s[1] == 0.005


def test_frequency_unit_heuristics(tmp_path):
    recording = make_recording()
    write(recording.with_columns(freq_hz=recording.freq_hz / 1000), tmp_path / "khz.csv")
    with pytest.raises(RecordingError, match=r"freq_hz looks like kHz \(median 4\.425\); pass "):
        read(tmp_path / "khz.csv")
    fixed = read(tmp_path / "khz.csv", units={"freq": "kHz"})
    np.testing.assert_allclose(fixed.freq_hz, recording.freq_hz, rtol=1e-15)
    write(recording.with_columns(freq_hz=recording.freq_hz * 1000), tmp_path / "mhz.csv")
    with pytest.raises(RecordingError, match=r"freq_hz is implausible \(median 4\.425e\+06 Hz"):
        read(tmp_path / "mhz.csv")


@pytest.mark.parametrize(
    ("divisor", "fix"),
    [(3600.0, "--rate-unit dps"), (180.0 / math.pi * 3600.0, "--rate-unit radps")],
)
def test_rate_unit_heuristics(tmp_path, divisor, fix):
    recording = make_recording(bias=10.0, noise=2.0)
    scaled = recording.with_columns(rate_dph=recording.rate_dph / divisor)
    path = write(scaled, tmp_path / "rate.parquet")
    with pytest.raises(RecordingError, match=rf"rate_dph looks like °/s or rad/s.*pass {fix}"):
        read(path)


def test_rate_table_input_in_dps_is_flagged():
    recording = make_recording(bias=360000.0, noise=2.0)  # 100 °/s input, in °/h: fine
    table = Recording(recording.columns, Metadata(RATE_HZ, input_rate_dph=360000.0))
    assert validate(table).ok
    in_dps = table.with_columns(rate_dph=table.rate_dph / 3600.0)
    with pytest.raises(RecordingError, match=r"looks like °/s or rad/s"):
        validate(in_dps)


@settings(max_examples=40, deadline=None)
@given(
    bias=st.floats(-100.0, 100.0),
    earth=st.floats(-15.0, 15.0),
    noise=st.floats(0.01, 5.0),
    seed=st.integers(0, 2**16),
)
def test_rate_heuristic_never_flags_plausible_dph_data(bias, earth, noise, seed):
    # The simulator's output: Earth-rate component + bias up to ±100 °/h + noise 0.01-5 °/h.
    recording = make_recording(n=400, seed=seed, bias=bias + earth, noise=noise)
    assert validate(recording).ok


def test_empty_and_unknown_and_newer_files(tmp_path):
    empty = write(make_recording().slice(0, 0), tmp_path / "empty.csv")
    with pytest.raises(RecordingError, match=r"empty\.csv: the recording has no rows"):
        read(empty)
    (tmp_path / "run.txt").write_text("t,f\n", encoding="utf-8")
    with pytest.raises(RecordingError, match=r"unknown file type '\.txt'; use one of \.parquet"):
        read(tmp_path / "run.txt")
    newer = Metadata(RATE_HZ, schema=99)
    path = write(Recording(make_recording().columns, newer), tmp_path / "new.h5")
    with pytest.raises(RecordingError, match=r"schema 99 is newer .* upgrade hrgtc"):
        read(path)
    with pytest.raises(FileNotFoundError):
        read(tmp_path / "missing.parquet")


def test_bad_mapping_and_metadata(tmp_path):
    path = write(make_recording(), tmp_path / "run.csv")
    with pytest.raises(RecordingError, match=r"column 'f_res' \(given for freq_hz\) not found"):
        read(path, columns={"freq_hz": "f_res"})
    with pytest.raises(InputError, match=r"'freq' is not a recording column \(did you mean"):
        read(path, columns=["freq=freq_hz"])
    with pytest.raises(RecordingError, match=r"sample_rate_hz must be a positive number"):
        Metadata(sample_rate_hz=0.0)
    with pytest.raises(RecordingError, match=r"sample_rate_hz is '200 Hz', not a number"):
        read(path, metadata={"sample_rate_hz": "200 Hz"})
    text = path.read_text(encoding="utf-8").replace("input_rate_dph: 9.67", "input_rate_dph: NaN")
    path.write_text(text, encoding="utf-8")
    with pytest.raises(RecordingError, match=r"input_rate_dph must be a finite number"):
        read(path)


def test_csv_parse_errors_name_line_row_and_value(tmp_path):
    recording = make_recording(n=50)
    lines = write(recording, tmp_path / "ok.csv").read_text(encoding="utf-8").splitlines()
    header_lines = next(i for i, line in enumerate(lines) if not line.startswith("#")) + 1
    bad = list(lines)
    bad[header_lines + 12] = bad[header_lines + 12].rsplit(",", 3)[0]  # row 12 truncated
    (tmp_path / "short.csv").write_text("\n".join(bad) + "\n", encoding="utf-8")
    with pytest.raises(RecordingError, match=rf"line {header_lines + 13} \(row 12\): expected 5"):
        read(tmp_path / "short.csv")
    bad = list(lines)
    fields = bad[header_lines + 30].split(",")
    fields[2] = "5xoops"
    bad[header_lines + 30] = ",".join(fields)
    (tmp_path / "garbage.csv").write_text("\n".join(bad) + "\n", encoding="utf-8")
    with pytest.raises(RecordingError, match=r"column 'rate_dph', row 30: '5xoops' is not a n"):
        read(tmp_path / "garbage.csv")
    with pytest.raises(RecordingError, match=r"row 30: '5xoops' is not a number"):
        list(iter_chunks(tmp_path / "garbage.csv", chunk_rows=7))


# -- chunked validation carries state ------------------------------------------------
def test_chunked_validation_numbers_rows_globally_and_checks_boundaries(tmp_path):
    recording = make_recording(n=400)
    path = write(corrupt(recording, "freq_hz", 250, np.nan), tmp_path / "nan.parquet")
    with pytest.raises(RecordingError, match=r"column 'freq_hz', row 250: value nan"):
        list(iter_chunks(path, chunk_rows=100))
    path = write(corrupt(recording, "time_s", 200, 0.5), tmp_path / "back.parquet")
    with pytest.raises(RecordingError, match=r"row 200: 0\.5 s after 0\.995 s is a step back"):
        list(iter_chunks(path, chunk_rows=100))  # the bad step straddles two chunks
    time = recording.time_s.copy()
    time[300:] += 10.0
    path = write(recording.with_columns(time_s=time), tmp_path / "gap.h5")
    with pytest.raises(RecordingError, match=r"row 300: 1 gap"):
        list(iter_chunks(path, chunk_rows=100))
    assert len(concatenate(list(iter_chunks(path, chunk_rows=100, gaps="split")))) == 400


def test_no_chunk_escapes_before_the_unit_heuristics(tmp_path):
    recording = make_recording(n=400)
    path = write(recording.with_columns(freq_hz=recording.freq_hz / 1000), tmp_path / "k.h5")
    seen = []
    with pytest.raises(RecordingError, match="looks like kHz"):
        for chunk in iter_chunks(path, chunk_rows=50):
            seen.append(chunk)
    assert seen == []


# -- atomic writing ------------------------------------------------------------------
@pytest.mark.parametrize("suffix", SUFFIXES)
def test_never_overwrites_without_force(tmp_path, suffix):
    path = write(make_recording(seed=1), tmp_path / f"run{suffix}")
    before = path.read_bytes()
    with pytest.raises(OutputExistsError, match=rf"run\{suffix} exists; pass --force"):
        write(make_recording(seed=2), path)
    assert path.read_bytes() == before
    write(make_recording(seed=2), path, force=True)
    assert same_bits(read(path).rate_dph, make_recording(seed=2).rate_dph)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


@pytest.mark.parametrize("suffix", SUFFIXES)
def test_failure_leaves_nothing_behind(tmp_path, suffix):
    recording = make_recording()
    path = tmp_path / f"run{suffix}"
    with pytest.raises(RuntimeError):
        with RecordingWriter(path, recording.metadata, recording.names) as out:
            out.write(recording.slice(0, 100))
            raise RuntimeError("simulator crashed")
    with pytest.raises(RecordingError, match=r"chunk columns .* differ"):
        with RecordingWriter(path, recording.metadata, ["time_s", "freq_hz"]) as out:
            out.write(recording)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(InputError, match=r"directory .*nowhere does not exist"):
        write(recording, tmp_path / "nowhere" / f"run{suffix}")


# -- property: corruptions always give an error or a correct read --------------------
BASE = make_recording(n=300, seed=11)
CSV_LINES: list[str] = []


def base_csv_lines() -> list[str]:
    if not CSV_LINES:
        with tempfile.TemporaryDirectory() as directory:
            path = write(BASE, Path(directory) / "base.csv")
            CSV_LINES.extend(path.read_text(encoding="utf-8").splitlines())
    return CSV_LINES


def read_text_csv(lines: list[str]) -> Recording:
    with tempfile.TemporaryDirectory() as directory:
        path = Path(directory) / "corrupt.csv"
        path.write_text("\n".join(lines) + "\n", encoding="utf-8")
        return read(path)


def read_written(recording: Recording, suffix: str) -> Recording:
    with tempfile.TemporaryDirectory() as directory:
        return read(write(recording, Path(directory) / f"corrupt{suffix}"))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    suffix=st.sampled_from(SUFFIXES),
    hits=st.lists(
        st.tuples(
            st.sampled_from(BASE.names), st.integers(0, 299), st.sampled_from([np.nan, np.inf])
        ),
        min_size=1,
        max_size=4,
    ),
)
def test_injected_non_finite_values_are_always_caught(suffix, hits):
    recording = BASE
    for name, row, value in hits:
        recording = corrupt(recording, name, row, value)
    first = min(row for name, row, _ in hits if name == hits[0][0])
    with pytest.raises(RecordingError, match=rf"column '{hits[0][0]}', row {first}: value"):
        read_written(recording, suffix)


@settings(max_examples=30, deadline=None)
@given(
    suffix=st.sampled_from(SUFFIXES),
    kind=st.sampled_from(["duplicate", "swap", "shuffle"]),
    i=st.integers(1, 298),
    seed=st.integers(0, 1000),
)
def test_disordered_times_are_always_caught(suffix, kind, i, seed):
    order = np.arange(300)
    if kind == "duplicate":
        order[i] = order[i - 1]
    elif kind == "swap":
        order[[i, i + 1]] = order[[i + 1, i]]
    else:
        order[i:] = np.random.default_rng(seed).permutation(order[i:])
        if np.all(order[i:] == np.arange(i, 300)):
            order[[i, i + 1]] = order[[i + 1, i]]
    shuffled = Recording({n: BASE[n][order] for n in BASE.names}, BASE.metadata)
    if kind == "duplicate":  # a repeated row (same time, same values) is dropped and counted
        recording = read_written(shuffled, suffix)
        assert len(recording) == 299 and recording.metadata.extra["duplicates_dropped"] == 1
        assert np.all(np.diff(recording.time_s) > 0)
        return
    with pytest.raises(RecordingError, match=r"column 'time_s', row \d+: .*(duplicate|back)"):
        read_written(shuffled, suffix)


@settings(max_examples=20, deadline=None)
@given(suffix=st.sampled_from(SUFFIXES), drop=st.sets(st.sampled_from(BASE.names), min_size=1))
def test_deleted_columns_give_an_error_or_a_correct_read(suffix, drop):
    kept = {n: v for n, v in BASE.columns.items() if n not in drop}
    if not kept:
        return
    recording = Recording(kept, BASE.metadata)
    if drop & {"time_s", "freq_hz", "rate_dph"}:
        with pytest.raises(RecordingError, match=r"missing|no time_s column"):
            read_written(recording, suffix)
    else:
        back = read_written(recording, suffix)
        assert back.names == recording.names
        assert all(same_bits(back[n], BASE[n]) for n in back.names)


@settings(max_examples=30, deadline=None)
@given(row=st.integers(0, 299), data=st.data())
def test_truncated_csv_lines_are_always_caught(row, data):
    lines = list(base_csv_lines())
    index = next(i for i, line in enumerate(lines) if not line.startswith("#")) + 1 + row
    line = lines[index]
    cut = data.draw(st.integers(1, line.rindex(",")), label="cut")  # lose at least one field
    lines[index] = line[:cut]
    with pytest.raises(RecordingError, match=r"(expected 5 fields|not a number|not finite)"):
        read_text_csv(lines)


@settings(max_examples=30, deadline=None)
@given(
    row=st.integers(0, 299),
    field=st.integers(0, 4),
    garbage=st.text(alphabet=string.ascii_letters + "#@!?/ _-", min_size=1, max_size=8),
)
def test_garbage_in_a_numeric_column_is_always_caught(row, field, garbage):
    lines = list(base_csv_lines())
    index = next(i for i, line in enumerate(lines) if not line.startswith("#")) + 1 + row
    fields = lines[index].split(",")
    fields[field] = garbage
    lines[index] = ",".join(fields)
    with pytest.raises(RecordingError, match=rf"(row {row}: .* is not a number|not finite)"):
        read_text_csv(lines)


@settings(max_examples=12, deadline=None)
@given(
    suffix=st.sampled_from(SUFFIXES),
    scaling=st.sampled_from(
        [("freq_hz", 1e-3, "kHz"), ("freq_hz", 1e3, "implausible"), ("rate_dph", 1 / 3600, "°/s")]
    ),
)
def test_unit_scaling_is_always_caught(suffix, scaling):
    name, factor, match = scaling
    recording = BASE.with_columns(**{name: BASE[name] * factor})
    with pytest.raises(RecordingError, match=match):
        read_written(recording, suffix)
