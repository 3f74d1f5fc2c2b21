"""One classifier of odd time steps: each repaired case reads as the clean file."""

from __future__ import annotations

import numpy as np
import pytest

from bursts import cut_bursts, duplicated_rows, with_time, wrapped_counter_s
from hrgtc.core.errors import InputError, RecordingError
from hrgtc.core.time_steps import WRAP_MODULUS_S, TimeRepairStream, classify_time_steps
from hrgtc.drift.features import EQ21, FeatureSettings
from hrgtc.drift.windows import Windowing, window_means
from hrgtc.recording import Metadata, Recording, iter_chunks, read, write
from hrgtc.recording.validation import validate

from synthetic import ramp_run


@pytest.fixture(scope="module")
def clean():
    """A 2 h, 10 Hz ramp (longer than a µs counter's 71.6 min wrap)."""
    return ramp_run(3, hours=2.0, sample_rate_hz=10.0, ramp_hours=1.0)


def _csv(run: Recording, path, time_column: np.ndarray, fmt: str = "%.17g"):
    data = np.column_stack([time_column, run.freq_hz, run.rate_dph])
    np.savetxt(path, data, delimiter=",", header="t,f,w", comments="", fmt=fmt)
    return path


READ = {"columns": {"time_s": "t", "freq_hz": "f", "rate_dph": "w"},
        "metadata": {"sample_rate_hz": 10.0, "input_rate_dph": 10.0}}


def _windows(run: Recording):
    settings = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, warmup_s=100.0)
    return window_means([run], settings, list(EQ21[:4]), Windowing(10.0))


def test_a_wrapped_microsecond_counter_reads_as_the_clean_file(clean, tmp_path):
    ticks = np.round((clean.time_s - clean.time_s[0] + 4000.0) / 1e-6).astype(np.int64)
    counter = ticks % 2**32  # wraps after 294.967 s and again after 71.6 min
    path = _csv(clean, tmp_path / "wrapped.csv", counter, fmt="%d")
    run = read(path, units={"time": "us"}, **READ)
    np.testing.assert_allclose(np.diff(run.time_s), np.diff(clean.time_s), atol=2e-6)
    assert "wrapped (2 time(s)" in run.metadata.extra["time_repairs"][0]
    # streamed in chunks of any size: the same times, a wrap on a chunk boundary included
    for rows in (1000, 2950, 49_999):
        streamed = np.concatenate([c.time_s for c in iter_chunks(path, chunk_rows=rows,
                                                                 units={"time": "us"}, **READ)])
        np.testing.assert_array_equal(streamed, run.time_s)
    # the training windows are those of the clean file
    a, b = _windows(with_time(clean, run.time_s)), _windows(clean)
    np.testing.assert_allclose(a.terms, b.terms, rtol=1e-12)
    np.testing.assert_allclose(a.bias_dph, b.bias_dph, rtol=1e-12)


def test_a_reset_starts_a_new_segment_like_two_files(clean, tmp_path):
    time = clean.time_s.copy()
    time[36_000:] = time[36_000:] - time[36_000] + 0.0  # the logger restarts at 0
    path = _csv(clean, tmp_path / "reset.csv", time)
    run = read(path, gaps="split", **READ)
    assert "restarts near zero" in run.metadata.extra["time_repairs"][0]
    assert np.all(np.diff(run.time_s) > 0)
    step = np.diff(run.time_s)
    assert np.flatnonzero(step > 0.2).tolist() == [35_999]  # one gap, at the reset
    np.testing.assert_array_equal(run.rate_dph, clean.rate_dph)


def test_duplicated_rows_are_dropped_and_counted(clean, tmp_path):
    doubled = duplicated_rows(clean, 5000, 40)  # a block of 40 rows sent twice
    path = _csv(doubled, tmp_path / "dup.csv", doubled.time_s)
    run = read(path, **READ)
    assert run.metadata.extra["duplicates_dropped"] == 40
    np.testing.assert_array_equal(run.time_s, clean.time_s)
    np.testing.assert_array_equal(run.rate_dph, clean.rate_dph)


def test_a_daylight_saving_step_in_clock_times_is_named(tmp_path):
    start = np.datetime64("2026-10-25T02:30:00")
    stamps = start + (np.arange(200) * 1000).astype("timedelta64[ms]")
    stamps[100:] -= np.timedelta64(3600, "s")  # clocks go back at 03:00 local time
    rng = np.random.default_rng(0)
    lines = [f"{s},{4428.5 + rng.normal(0, 0.002)},{10 + rng.normal(0, 2)}" for s in stamps]
    path = tmp_path / "dst.csv"
    path.write_text("t,f,w\n" + "\n".join(lines) + "\n")
    with pytest.raises(RecordingError, match=r"row 100: .*daylight saving"):
        read(path, columns=READ["columns"], units={"time": "timestamp"})


@pytest.mark.parametrize(("time_factor", "rate_hz", "hint"), [
    # the time in ms, or the metadata wrong: both named, with what each means
    (1000.0, 200.0, "either the time column is in milliseconds (pass --time-unit ms: every "
                    "duration then shrinks 1000 times) or the metadata's rate is wrong and the "
                    "steps are right: pass --rate-hz 0.2"),
    (1.0, 100.0, "the rate does not change within the file: fix the metadata (--rate-hz 200)"),
    (1e-3, 200.0, "if you passed --time-unit ms, the time column is already in seconds "
                  "(drop it); or the metadata's rate is wrong"),
])
def test_a_wrong_time_unit_or_rate_gives_one_hint_not_gaps_or_rate_changes(time_factor,
                                                                          rate_hz, hint):
    n = 6000
    rng = np.random.default_rng(1)
    run = Recording({"time_s": np.arange(n) * 0.005 * time_factor,
                     "freq_hz": 4425 + rng.normal(0, 0.002, n),
                     "rate_dph": 10 + rng.normal(0, 1, n)}, Metadata(sample_rate_hz=rate_hz))
    report = validate(run, raise_errors=False)
    assert [p.kind for p in report.problems] == ["sample_rate"]
    assert hint in report.problems[0].message
    assert "gap" not in report.problems[0].message


def test_a_rate_that_really_changes_names_the_row(tmp_path):
    n = 6000
    time = np.r_[np.arange(4321) * 0.005, 4320 * 0.005 + np.arange(1, n - 4320) * 0.01]
    rng = np.random.default_rng(2)
    run = Recording({"time_s": time, "freq_hz": 4425 + rng.normal(0, 0.002, n),
                     "rate_dph": 10 + rng.normal(0, 1, n)}, Metadata(sample_rate_hz=200.0))
    path = write(run, tmp_path / "change.parquet")
    for rows in (1000, 777, 6000):
        with pytest.raises(RecordingError, match=r"row 4320: the time step changes to 100 Hz.*"
                                                 r"split it at row 4320"):
            list(iter_chunks(path, chunk_rows=rows))


def test_classifier_cases_directly():
    t = np.arange(20_000) * 0.5
    wrapped = wrapped_counter_s(t, "us", start_s=4000.0)
    d = classify_time_steps(wrapped, time_unit="us")
    assert [e.kind for e in d.events] == ["wrap"] and d.events[0].repaired
    np.testing.assert_allclose(np.diff(d.time_s), 0.5, atol=1e-6)
    assert WRAP_MODULUS_S["us"] / 60 == pytest.approx(71.58, abs=0.01)
    glitch = t.copy()
    glitch[100] = 0.25  # one bad time stamp is neither a reset nor a wrap
    assert [e.kind for e in classify_time_steps(glitch).events] == ["backwards"]
    stream = TimeRepairStream("us")
    parts = [stream.repair(wrapped[k:k + 333])[0] for k in range(0, wrapped.size, 333)]
    np.testing.assert_allclose(np.concatenate(parts), d.time_s, atol=1e-9)


def test_burst_helper_cuts_a_continuous_run(clean):
    bursts = cut_bursts(clean, 5.0, 300.0)
    assert len(bursts) == 24 * 50


def test_info_names_what_the_time_repair_did(clean, tmp_path):
    from typer.testing import CliRunner

    from hrgtc.cli import app

    ticks = np.round((clean.time_s[:20_000] - clean.time_s[0] + 4000.0) / 1e-6).astype(np.int64)
    short = Recording({k: clean[k][:20_000] for k in clean.names}, clean.metadata)
    path = _csv(short, tmp_path / "wrapped.csv", ticks % 2**32, fmt="%d")
    args = ["info", str(path), "--col", "time_s=t,freq_hz=f,rate_dph=w", "--time-unit", "us"]
    result = CliRunner().invoke(app, [*args, "--json"])
    assert result.exit_code == 0, result.stderr
    timeline = __import__("json").loads(result.stdout)["timeline"]
    assert timeline["segments"] == 1 and "wrapped (1 time(s)" in timeline["repairs"][0]
    text = " ".join(CliRunner().invoke(app, args).stdout.split())
    assert "time: row 2950: the 32-bit us time counter wrapped" in text


def test_a_reset_is_a_new_run_its_own_warm_up_filter_and_offset_group(clean, tmp_path):
    """A logger reset starts a new run (issue 20 items 1, 3, 13): the reader lists it
    (``restarts_s``, in every chunk from the one holding it), and training skips the warm-up
    after it again, restarts the df/dt filter there and gives it its own power-on run (the
    groups of ``--offsets run``) -- the windows of two files. A gap does not, unless each
    segment is said to be a restart."""
    time = clean.time_s.copy()
    time[36_000:] = time[36_000:] - time[36_000] + 0.0  # the logger restarts at 0
    path = _csv(clean, tmp_path / "reset.csv", time)
    run = read(path, gaps="bridge", **READ)
    (restart,) = run.metadata.extra["restarts_s"]
    assert restart == run.time_s[36_000]
    for rows in (1000, 36_000, 50_000):
        chunks = list(iter_chunks(path, chunk_rows=rows, gaps="bridge", **READ))
        holding = [c for c in chunks if c.time_s[-1] >= restart]
        assert all(c.metadata.extra["restarts_s"] == [restart] for c in holding)
    windows = _windows(run)
    first, second = clean.slice(0, 36_000), clean.slice(36_000, len(clean))
    settings = FeatureSettings(reference_freq_hz=4432.0, sample_rate_hz=10.0, warmup_s=100.0)
    apart = window_means([first, second], settings, list(EQ21[:4]), Windowing(10.0))
    assert windows.dropped["warmup"] == 2 * 1000  # 100 s at 10 Hz after each power-on
    np.testing.assert_allclose(windows.terms, apart.terms, rtol=1e-9, atol=1e-15)
    np.testing.assert_array_equal(windows.power_run, apart.run)
    assert windows.power_runs == (f"{path} run 1", f"{path} run 2")
    # bursts: one power-on run, unless each segment is a restart
    bursts = cut_bursts(clean, burst_s=600.0, period_s=1200.0)
    one = window_means([bursts], settings, list(EQ21[:4]), Windowing(10.0))
    each = window_means([bursts], settings, list(EQ21[:4]),
                        Windowing(10.0, restart_each_segment=True))
    assert set(one.power_run.tolist()) == {0}
    assert sorted(set(each.power_run.tolist())) == list(range(6))
    assert each.dropped["warmup"] == 6 * 1000


def _local_clock_csv(path, utc_start: str, n: int, zone: str):
    """A 1 Hz file whose clock times are written in local time of ``zone`` (no offset), and
    the clean times in seconds since the first sample."""
    import zoneinfo
    from datetime import UTC, datetime, timedelta

    start = datetime.fromisoformat(utc_start).replace(tzinfo=UTC)
    local = [(start + timedelta(seconds=k)).astimezone(zoneinfo.ZoneInfo(zone))
             .replace(tzinfo=None).isoformat() for k in range(n)]
    rng = np.random.default_rng(4)
    freq = 4428.5 + rng.normal(0, 0.002, n)
    rate = 10 + rng.normal(0, 2, n)
    path.write_text("t,f,w\n" + "".join(f"{t},{float(f)!r},{float(w)!r}\n" for t, f, w in
                                        zip(local, freq, rate, strict=True)))
    return np.arange(n, dtype=np.float64), freq, rate, local


@pytest.mark.parametrize(("utc_start", "name"), [
    ("2026-10-25T00:10:00", "autumn"),  # 03:00 CEST -> 02:00 CET: the hour 02:xx twice
    ("2026-03-29T00:40:00", "spring"),  # 02:00 CET -> 03:00 CEST: the hour 02:xx skipped
])
@pytest.mark.parametrize("rows", [None, 700, 1800])
def test_clock_times_read_in_their_zone_are_the_clean_file(tmp_path, utc_start, name, rows):
    """``--tz`` (issue 20 item 3): clock times written in local time across a daylight saving
    change read as the clean file (seconds, exactly), whole or in chunks (the repeated hour
    cut anywhere); without it the step is an error naming --tz."""
    n = 3600
    clean_s, freq, rate, _local = _local_clock_csv(tmp_path / f"{name}.csv", utc_start, n,
                                                  "Europe/Berlin")
    path = tmp_path / f"{name}.csv"
    options = {"columns": READ["columns"], "units": {"time": "timestamp"},
               "metadata": {"sample_rate_hz": 1.0}}
    if rows is None:
        run = read(path, tz="Europe/Berlin", **options)
    else:
        chunks = list(iter_chunks(path, chunk_rows=rows, tz="Europe/Berlin", **options))
        run = Recording({k: np.concatenate([c[k] for c in chunks]) for k in chunks[0].names},
                        chunks[0].metadata)
    np.testing.assert_array_equal(run.time_s, clean_s)
    np.testing.assert_array_equal(run.freq_hz, freq)
    np.testing.assert_array_equal(run.rate_dph, rate)
    assert run.metadata.extra["time_zone"] == "Europe/Berlin"
    with pytest.raises(RecordingError, match=r"daylight saving.*--tz"):
        read(path, **options)


def test_tz_errors_name_the_fix(tmp_path):
    _local_clock_csv(tmp_path / "c.csv", "2026-10-25T00:10:00", 100, "Europe/Berlin")
    options = {"columns": READ["columns"], "metadata": {"sample_rate_hz": 1.0}}
    with pytest.raises(InputError, match=r"--tz 'Mars/Olympus' is not a time zone"):
        read(tmp_path / "c.csv", units={"time": "timestamp"}, tz="Mars/Olympus", **options)
    seconds = tmp_path / "s.csv"
    seconds.write_text("t,f,w\n" + "".join(f"{k},4428.5,10\n" for k in range(100)))
    with pytest.raises(InputError, match=r"drop --tz"):
        read(seconds, tz="Europe/Berlin", **options)
    # a clock time in the hour skipped in spring does not exist there: the row is named
    skipped = tmp_path / "skipped.csv"
    skipped.write_text("t,f,w\n2026-03-29T01:59:59,4428.5,10\n2026-03-29T02:00:00,4428.5,10\n")
    with pytest.raises(RecordingError, match=r"row 1: 2026-03-29 02:00:00 does not exist"):
        read(skipped, units={"time": "timestamp"}, tz="Europe/Berlin", **options)


def test_a_one_hour_pause_in_clock_times_with_their_zone_is_a_gap(tmp_path):
    """Clock times that carry their zone (``Z``, an offset) have no daylight saving step: a
    pause of one hour is a gap; the same times without a zone are an error naming --tz."""
    start = np.datetime64("2026-06-01T10:00:00")
    stamps = start + np.r_[np.arange(100), 3700 + np.arange(100)].astype("timedelta64[s]")
    options = {"columns": READ["columns"], "units": {"time": "timestamp"},
               "metadata": {"sample_rate_hz": 1.0}, "gaps": "bridge"}
    for suffix, fails in (("Z", False), ("+02:00", False), ("", True)):
        path = tmp_path / f"pause{len(suffix)}.csv"
        path.write_text("t,f,w\n" + "".join(f"{s}{suffix},4428.5,10\n" for s in stamps))
        if fails:
            with pytest.raises(RecordingError, match=r"row 100: .*forward by 3600 s.*--tz"):
                read(path, **options)
        else:
            run = read(path, **options)
            assert run.time_s[100] - run.time_s[99] == 3601.0


@pytest.mark.parametrize("event", ["wrap", "reset"])
def test_a_duplicated_row_after_a_wrap_or_a_reset_is_found(event):
    """Rows sent twice after a µs counter wrapped (or the logger restarted) were looked up
    by a binary search over the whole, no longer increasing, file: not found, they stayed
    as "duplicate time" errors (`hrgtc simulate --time-unit us --counter-bits 32
    --restarts 5000 --duplicates 4`: 1 of 4 dropped, calibrate refused the file)."""
    period = 0.2
    true_s = 3000.0 + period * np.arange(8000)  # crosses 2^32 µs = 4294.97 s at row 6475
    if event == "wrap":
        raw = np.mod(np.round(true_s * 1e6), 2.0**32) / 1e6
    else:  # a reset at row 6000: the clock starts again from 0.2 s
        raw = true_s.copy()
        raw[6000:] = period * (1 + np.arange(2000))
    rng = np.random.default_rng(1)
    values = rng.normal(size=(raw.size, 2))
    copies = [6800, 7200, 7900]  # each row written again right after itself
    time_s = np.insert(raw, [c + 1 for c in copies], raw[copies])
    rows = np.insert(values, [c + 1 for c in copies], values[copies], axis=0)
    found = classify_time_steps(time_s, time_unit="us", values=rows)
    kinds = {e.kind: e.count for e in found.events}
    assert kinds.get("duplicate") == 3 and "duplicate_time" not in kinds, found.events
    assert np.count_nonzero(~found.keep) == 3
    np.testing.assert_array_equal(time_s[found.keep], raw)


def test_a_daylight_saving_step_across_a_burst_logger_s_pause_is_named():
    """Clocks back by 1 h while a burst logger pauses: the step is -3600 s + the pause
    (-3544.9 s for 5 s of every 60 s at 10 Hz). It was "a step back in time ... two
    files joined out of order? split the file", not the missing --tz."""
    burst = np.arange(50) * 0.1
    times = np.concatenate([k * 60.0 + burst for k in range(100)])
    clock = times.copy()
    clock[times >= 3000.0] -= 3600.0  # 03:00 local comes again at the 51st burst
    found = classify_time_steps(clock, time_unit="timestamp", naive_clock=True)
    (event,) = [e for e in found.events if e.kind == "dst"]
    assert event.row == 2500 and not event.repaired
    assert "jumps back by 3544.9 s (1 h less a pause of 55.1 s)" in event.message
    assert "--tz" in event.message
    assert not [e for e in found.events if e.kind == "backwards"]
