"""Tests of the robust, time-windowed spike filter (hrgtc.recording.spikes.find_spikes).

Truth: the positions and sizes of the spikes the tests inject into simulated streams
(Gaussian, quantised, pulse-type, with gaps and a drifting level), and the three
single-sample spikes of the real PAN cold-test recording near −0.102 rad/s (rows
2340, 2570 and 3223 of the x gyro, read off the file: its other samples sit within
a few 10^-3 rad/s of their burst's level).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from hrgtc.core.errors import InputError, SpikeWarning
from hrgtc.recording import ReadOptions, read
from hrgtc.recording.spikes import SPIKE_COLUMN, RobustSpikeFilter, find_spikes

PAN = Path(__file__).parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"
PAN_COLUMNS = {"time_s": "time (ms)", "rate_dph_x": "gyrox rad/s", "rate_dph_y": "gyroy rad/s",
               "rate_dph_z": "gyroz rad/s", "temperature_c": "temp"}


def bursts(rng, n_bursts=20, per_burst=250, rate_hz=50.0, period_s=300.0):
    """Time of a burst logger: ``per_burst`` samples at ``rate_hz`` every ``period_s``."""
    one = np.arange(per_burst) / rate_hz
    return np.concatenate([k * period_s + one for k in range(n_bursts)])


def test_injected_spikes_of_known_size_and_position_are_found():
    rng = np.random.default_rng(1)
    time_s = bursts(rng)
    values = 0.002 * time_s + rng.standard_normal(time_s.size)  # drifting level, σ = 1
    where = np.array([0, 17, 251, 1999, 2600, 4999])  # a burst's first, inner, last samples
    sizes = np.array([15.0, -12.0, 40.0, -9.5, 300.0, 20.0])
    values[where] += sizes
    found = find_spikes(time_s, values)
    np.testing.assert_array_equal(np.flatnonzero(found), where)


def test_gaussian_stream_without_spikes_gives_none():
    rng = np.random.default_rng(2)
    time_s = np.arange(1_000_000) / 200.0
    assert not find_spikes(time_s, 5.0 + 0.3 * rng.standard_normal(time_s.size)).any()


def test_handling_at_a_low_sample_rate_is_motion_not_spikes():
    """A unit turned by hand, logged at 2 Hz: for a few seconds every sample is hundreds of
    σ from its neighbours, which do not agree with each other either. That is motion (the
    motion detector's business), not a run of single-sample spikes: none is removed, so no
    gap is made where the logger had none. A lone spike beside it is still found."""
    rng = np.random.default_rng(7)
    time_s = np.arange(4000) / 2.0
    values = rng.standard_normal(time_s.size)
    for start in (1000, 1500, 2200):  # a turn: three samples of rotation in a still stream
        values[start:start + 3] += [600.0, 900.0, 400.0]
    values[3000] += 60.0
    np.testing.assert_array_equal(np.flatnonzero(find_spikes(time_s, values)), [3000])


def test_quantised_pulse_stream_keeps_every_pulse_and_its_mean():
    rng = np.random.default_rng(3)
    time_s = np.arange(200_000) / 100.0
    lsb = 0.0625
    pulses = lsb * rng.poisson(0.05, time_s.size)  # mostly 0, single pulses: MAD = 0
    assert np.median(np.abs(pulses - np.median(pulses))) == 0.0
    assert not find_spikes(time_s, pulses).any()
    counts = lsb * np.round(3.0 + 1.2 * rng.standard_normal(time_s.size))  # ±1 LSB noise
    assert not find_spikes(time_s, counts).any()
    counts[1234] += 40 * lsb  # a real spike on the quantised stream is still found
    assert np.flatnonzero(find_spikes(time_s, counts)).tolist() == [1234]


def test_a_step_is_not_a_spike_and_windows_never_span_a_gap():
    rng = np.random.default_rng(4)
    time_s = np.r_[np.arange(2000) / 100.0, 100.0 + np.arange(2000) / 100.0]
    noise = np.r_[20.0 * rng.standard_normal(2000), 0.1 * rng.standard_normal(2000)]
    values = noise.copy()
    values[2500:] += 50.0  # a step inside the quiet segment: not a spike
    values[3100] += 5.0  # 50 σ of the quiet segment, 0.25 σ of the noisy one
    found = find_spikes(time_s, values, window_s=1000.0)  # one window per segment
    assert np.flatnonzero(found).tolist() == [3100]


def test_real_recording_three_spikes_found_and_removed():
    with pytest.warns(SpikeWarning, match=r"3 row\(s\) .* removed .*rate_dph_x 3.* row 2340"):
        rec = read(PAN, columns=PAN_COLUMNS, units={"time": "ms", "rate": "rad/s"},
                   thermometer="sensor", temp_scale=0.001, temp_offset_c=-40.0,
                   temp_unwrap="off", gaps="split",
                   validate=False, spike_filter="drop")
    assert len(rec) == 6250 - 3 and rec.metadata.extra["spikes_removed"] == 3
    raw = np.genfromtxt(PAN, delimiter=",", skip_header=1)
    kept = np.delete(raw, [2340, 2570, 3223], axis=0)
    np.testing.assert_array_equal(rec.time_s, kept[:, 0] / 1000.0)
    assert raw[[2340, 2570, 3223], 4].tolist() == [-0.102, -0.102, -0.102]


def test_flag_keeps_every_row_and_marks_the_spikes_streamed_in_chunks():
    options = ReadOptions(columns=PAN_COLUMNS, units={"time": "ms", "rate": "rad/s"},
                          thermometer="sensor", temp_scale=0.001, temp_offset_c=-40.0,
                          temp_unwrap="off",
                          gaps="split", spike_filter="flag", chunk_rows=1000)
    with pytest.warns(SpikeWarning, match="flagged in column 'spike'"):
        chunks = list(options.chunks(PAN))
    flags = np.concatenate([c[SPIKE_COLUMN] for c in chunks])
    assert flags.size == 6250 and np.flatnonzero(flags).tolist() == [2340, 2570, 3223]


def test_bad_settings_are_named():
    with pytest.raises(InputError, match="spike_filter must be one of"):
        RobustSpikeFilter("remove")
    with pytest.raises(InputError, match="window_s must be a positive number"):
        RobustSpikeFilter("drop", window_s=0.0)


def test_impossible_values_stay_the_validation_s_business(tmp_path):
    from hrgtc.core.errors import RecordingError
    from hrgtc.recording import Metadata, Recording, write

    rng = np.random.default_rng(6)
    n = 400
    columns = {"time_s": np.arange(n) / 100.0, "freq_hz": 4425.0 + 0.01 * rng.standard_normal(n),
               "rate_dph": rng.standard_normal(n)}
    columns["rate_dph"][123] = 1e30  # beyond 1000 °/s: an error that names the row
    columns["rate_dph"][300] = 60.0  # plausible, 60 σ: a spike
    path = write(Recording(columns, Metadata(sample_rate_hz=100.0)), tmp_path / "run.parquet")
    with pytest.raises(RecordingError, match=r"column 'rate_dph', row 123"):
        read(path, spike_filter="drop")
    with pytest.warns(SpikeWarning, match=r"1 row\(s\) .* removed"):
        rec = read(path, spike_filter="drop", spikes="drop")
    assert len(rec) == n - 2


def test_spikes_evaluate_drops_are_counted_in_its_accounting(tmp_path):
    """Issue 21's audit: a single-sample frequency glitch of 6 % (an excursion from both
    neighbours, not a step) is a spike, and evaluate's default filter drops it; the drop
    was only a warning: the JSON accounting read 8999 of the 9000 rows and counted no
    spike. Every row read is accounted for, the dropped one under 'spikes', in the JSON
    and in the plain output's samples line."""
    import json

    from typer.testing import CliRunner

    from hrgtc.cli import app
    from hrgtc.model import save_model
    from hrgtc.recording import Recording, write

    from fuzzing import make_model
    from synthetic import ramp_run

    run = ramp_run(seed=3, start_c=10.0, end_c=5.0, hours=0.1)
    columns = {k: np.array(run[k]) for k in ("time_s", "freq_hz", "rate_dph")}
    columns["freq_hz"][2500] *= 1.06
    path = write(Recording(columns, run.metadata), tmp_path / "glitch.parquet")
    model = save_model(make_model(), tmp_path / "model.json")
    runner = CliRunner()
    result = runner.invoke(app, ["evaluate", str(path), "-m", str(model), "--json"])
    assert result.exit_code == 0, result.stderr
    accounting = json.loads(result.stdout)["accounting"]
    assert accounting["read"] == len(run) == 3600
    assert accounting["dropped"]["spikes"] == 1
    assert accounting["used"] == 3600 - 1 - accounting["dropped"]["warmup"]
    plain = runner.invoke(app, ["evaluate", str(path), "-m", str(model)])
    assert plain.exit_code == 0, plain.stderr
    line = " ".join(plain.stdout.split())  # the "samples" section of the summary
    assert re.search(r"read │ 3600 │", line) and re.search(r"dropped: spikes │ 1 │", line), line
