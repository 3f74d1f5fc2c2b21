"""``compensate``'s at-rest flags when the detector's pass reads fewer columns.

The pass reads only the detector's columns (``hrgtc.compensate.at_rest``); the reader can
drop a row because of another column (a slow channel's gap, ``--spikes drop``), which the
pass then keeps. The flags must still be those of the whole file's rows, bit for bit, or
no output at all: never flags shifted by the rows the two passes disagree on.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from hrgtc import drift
from hrgtc import recording as recording_io
from hrgtc.compensate import compensate_file
from hrgtc.compensate.at_rest import FlagsMisaligned, RestFlags
from hrgtc.drift.rest import run_rest
from hrgtc.model import AxisModel, Model
from hrgtc.recording import Recording
from hrgtc.settings.compensation import CompensateSettings

from synthetic import THERMOMETER, ramp_run

CHUNK = 7_000


@pytest.fixture(scope="module")
def unit_model():
    return Model.single(
        AxisModel(THERMOMETER, drift.fit([ramp_run(seed=21, hours=3.0)], THERMOMETER)))


def handled(seed: int = 23) -> Recording:
    """A 1 h 10 Hz run with three handling bursts (5 s at up to 40,000 °/h) after 2000 s."""
    run = ramp_run(seed=seed, start_c=-15.0, end_c=15.0, hours=1.0)
    rate = run.rate_dph.copy()
    t = run.time_s - run.time_s[0]
    for start_s in (2100.0, 2700.0, 3300.0):
        inside = (t >= start_s) & (t < start_s + 5.0)
        rate[inside] += 40_000.0 * np.sin(np.pi * (t[inside] - start_s) / 5.0)
    return run.with_columns(rate_dph=rate)


def whole_file_flags(source, options: recording_io.ReadOptions) -> np.ndarray:
    """The detector's verdicts on the rows of the whole file (every column read)."""
    return run_rest(options.chunks(source, rows=CHUNK), "exclude").keep


def compensated(source, out, model, options, monkeypatch) -> tuple[object, list]:
    """``compensate_file`` and the ``only=`` of each detector's pass it made."""
    passes: list = []
    original = recording_io.iter_chunks

    def spy(*args, **kwargs):
        passes.append(kwargs.get("only"))
        return original(*args, **kwargs)

    monkeypatch.setattr(recording_io, "iter_chunks", spy)
    return compensate_file(source, out, model, settings=CompensateSettings(chunk_rows=CHUNK),
                           read_options=options), passes


def test_a_slow_channels_gap_the_detectors_pass_does_not_read(unit_model, tmp_path,
                                                               monkeypatch):
    """``chamber_c`` logged once a second with a 60 s hole at 1500 s: the whole file's
    reading drops the rows of the hole (a gap of the slow channel); the detector's columns
    alone keep them. The flags are those of the whole file's rows, bit for bit (flags
    found on the longer rows would be 600 rows late after the hole: every burst's flags
    misplaced)."""
    run = handled()
    chamber = np.full(len(run), np.nan)
    chamber[::10] = run["chamber_c"][::10]
    t = run.time_s - run.time_s[0]
    chamber[(t >= 1500.0) & (t < 1560.0)] = np.nan
    source = recording_io.write(run.with_columns(chamber_c=chamber), tmp_path / "slow.parquet")
    options = recording_io.ReadOptions(gaps="split")
    expected = whole_file_flags(source, options)
    assert expected.size < len(run)  # the whole file's reading dropped the hole
    summary, passes = compensated(source, tmp_path / "out.parquet", unit_model, options,
                                  monkeypatch)
    out = recording_io.read(tmp_path / "out.parquet", gaps="split")
    assert len(out) == expected.size == summary.rows
    np.testing.assert_array_equal(out["at_rest"], expected.astype(float))
    assert np.count_nonzero(~expected[t[:expected.size] > 2000.0]) > 3 * 50  # bursts flagged
    # first the detector's columns only (misaligned: found), then every column
    assert passes[0] is not None and passes[-1] is None
    assert summary.accounting.flagged["motion"] == int(np.count_nonzero(~expected))


def test_the_detectors_columns_only_when_the_rows_agree(unit_model, tmp_path, monkeypatch):
    """A plain file: one pass of the detector's columns, the same flags as the whole
    file's, no second run."""
    source = recording_io.write(handled(), tmp_path / "plain.parquet")
    options = recording_io.ReadOptions()
    expected = whole_file_flags(source, options)
    _, passes = compensated(source, tmp_path / "out.parquet", unit_model, options,
                            monkeypatch)
    out = recording_io.read(tmp_path / "out.parquet")
    np.testing.assert_array_equal(out["at_rest"], expected.astype(float))
    assert np.count_nonzero(~expected) > 3 * 50
    assert len(passes) == 1 and set(passes[0]) >= {"time_s", "rate_dph"}
    assert "chamber_c" not in passes[0]


def test_spikes_drop_reads_every_column(unit_model, tmp_path, monkeypatch):
    """``--spikes drop`` drops a row for a bad value in any column: the detector's pass
    reads them all, and the flags are those of the rows kept."""
    run = handled()
    chamber = run["chamber_c"].copy()
    chamber[[9_000, 20_000, 30_000]] = np.nan
    source = recording_io.write(run.with_columns(chamber_c=chamber), tmp_path / "nan.parquet")
    options = recording_io.ReadOptions(spikes="drop")
    expected = whole_file_flags(source, options)
    assert expected.size == len(run) - 3
    _, passes = compensated(source, tmp_path / "out.parquet", unit_model, options,
                            monkeypatch)
    out = recording_io.read(tmp_path / "out.parquet")
    np.testing.assert_array_equal(out["at_rest"], expected.astype(float))
    assert passes == [None]


def chunks_of(recording: Recording, rows: int = CHUNK) -> list[Recording]:
    return [recording.slice(a, a + rows) for a in range(0, len(recording), rows)]


def _refuses_a_rate_changed_by_a_nanodegree(run: Recording) -> None:
    """:meth:`RestFlags.take` refuses the second chunk of ``run`` with one rate 1e-9 °/h
    off what the detector saw."""
    changed = run.rate_dph.copy()
    changed[CHUNK + 5] += 1e-9
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    flags.take(run.slice(0, CHUNK))
    with pytest.raises(FlagsMisaligned, match="rate_dph"):
        flags.take(run.with_columns(rate_dph=changed).slice(CHUNK, 2 * CHUNK))


def test_take_refuses_other_rows_than_the_detector_saw():
    """:meth:`RestFlags.take` and :meth:`RestFlags.finish` raise on a chunk whose detector
    columns differ from those the detector saw at the same rows (a row more, a value
    changed, a column missing) and on rows left over; equal chunks pass."""
    run = handled()
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    for chunk in chunks_of(run):
        flags.take(chunk)
    flags.finish()
    shifted = run.slice(1, len(run))  # a row dropped at the start
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    with pytest.raises(FlagsMisaligned, match=r"run\.parquet.*time_s.*rows 0-6999"):
        flags.take(shifted.slice(0, CHUNK))
    _refuses_a_rate_changed_by_a_nanodegree(run)
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    flags.take(run.slice(0, CHUNK))
    with pytest.raises(FlagsMisaligned, match="7000 rows compensated but 36000"):
        flags.finish()
    accel = run.with_columns(accel_x=np.zeros(len(run)), accel_y=np.zeros(len(run)),
                             accel_z=np.ones(len(run)))
    flags = RestFlags(chunks_of(accel), [""], "exclude", "run.parquet")
    with pytest.raises(FlagsMisaligned, match="columns"):
        flags.take(run.slice(0, CHUNK))


def test_only_reads_the_detectors_columns_of_every_axis(tmp_path):
    """``iter_chunks(only=)``: the detector's columns of every axis (``rate_dph_x``,
    ``rate_dph_y``) and the accelerometer's, nothing else, with the whole reading's values;
    a sensor thermometer's temperature too (its ``freq_hz`` is filled from it)."""
    from hrgtc.compensate.at_rest import DETECTOR_COLUMNS

    run = handled()
    n = len(run)
    columns = {"time_s": run.time_s, "rate_dph_x": run.rate_dph, "rate_dph_y": -run.rate_dph,
               "freq_hz_x": run.freq_hz, "freq_hz_y": run.freq_hz + 1.0,
               "accel_x": np.zeros(n), "accel_y": np.zeros(n), "accel_z": np.ones(n),
               "chamber_c": run["chamber_c"]}
    source = recording_io.write(Recording(columns, run.metadata), tmp_path / "xy.parquet")
    whole = recording_io.read(source)
    parts = list(recording_io.iter_chunks(source, chunk_rows=CHUNK, only=DETECTOR_COLUMNS,
                                          validate=False))
    assert parts[0].names == ("time_s", "rate_dph_x", "rate_dph_y", "accel_x", "accel_y",
                              "accel_z")
    for name in parts[0].names:
        np.testing.assert_array_equal(np.concatenate([p[name] for p in parts]), whole[name])
    sensor = recording_io.write(Recording({"time_s": run.time_s, "rate_dph": run.rate_dph,
                                           "temperature_c": run["resonator_c"],
                                           "chamber_c": run["chamber_c"]}, run.metadata),
                                tmp_path / "sensor.parquet")
    part = next(recording_io.iter_chunks(sensor, chunk_rows=CHUNK, only=DETECTOR_COLUMNS,
                                         thermometer="sensor", validate=False))
    assert set(part.names) == {"time_s", "rate_dph", "freq_hz", "temperature_c"}


@pytest.mark.parametrize("column", [False, True])
def test_take_with_a_known_input_rate(column):
    """A known input rate (the metadata's, or an ``input_rate_dph`` column) is subtracted
    in the detector's own buffer (no second array of the run's length): the flags are
    ``run_rest``'s, the chunks handed in are not changed, equal chunks pass and a changed
    rate is still refused."""
    import dataclasses

    run = handled()
    if column:
        run = run.with_columns(input_rate_dph=np.where(run.time_s > run.time_s[0] + 900.0,
                                                       54.0, 0.0))
    else:
        run = Recording(dict(run.columns), dataclasses.replace(run.metadata,
                                                               input_rate_dph=15.0))
    run = run.with_columns(rate_dph=run.rate_dph + (run["input_rate_dph"] if column else 15.0))
    kept = run.rate_dph.copy()
    expected = run_rest(chunks_of(run), "exclude").keep
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    assert np.array_equal(run.rate_dph, kept)  # the pass's own copy was changed
    assert np.array_equal(flags.still[""], expected) and np.count_nonzero(~expected) > 3 * 50
    np.testing.assert_array_equal(
        np.concatenate([flags.take(c)["at_rest"] for c in chunks_of(run)]),
        expected.astype(float))
    flags.finish()
    _refuses_a_rate_changed_by_a_nanodegree(run)


def test_take_checks_rows_cut_otherwise_than_the_detector_read_them():
    """The compensating pass's chunks need not be the detector's: rows cut elsewhere pass;
    one value changed inside a detector chunk that two of its chunks straddle is refused,
    naming the detector chunk's rows (the digests of its columns, bit for bit)."""
    run = handled()
    cuts = [0, 3_000, 12_500, 13_000, 29_000, len(run)]
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    for a, b in itertools.pairwise(cuts):
        flags.take(run.slice(a, b))
    flags.finish()
    changed = run.time_s.copy()
    changed[CHUNK + 100] = np.nextafter(changed[CHUNK + 100], np.inf)
    other = run.with_columns(time_s=changed)
    flags = RestFlags(chunks_of(run), [""], "exclude", "run.parquet")
    flags.take(other.slice(0, 3_000))
    flags.take(other.slice(3_000, 12_500))  # rows 7000-13999 are not complete yet
    with pytest.raises(FlagsMisaligned, match=r"other values of time_s in rows 7000-13999"):
        flags.take(other.slice(12_500, 20_000))
