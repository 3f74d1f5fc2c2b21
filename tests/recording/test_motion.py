"""The motion / at-rest detector: handling found against its truth, still samples left alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hrgtc.core.errors import InputError
from hrgtc.recording.motion import (
    MotionSettings,
    detect_motion,
    orientation_labels,
    segments_of,
)

PAN = Path(__file__).resolve().parents[1] / "data" / "pan-cold-test" / "pan_tvc_cold_2020-03-07.csv"


def handled(seed: int = 0, fs: float = 10.0, hours: float = 2.0, offset_dps: float = 4.0,
            bursts: int = 6, noise_dps: float = 0.02) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray, np.ndarray]:
    """A MEMS axis at rest (``offset_dps`` from zero, slow thermal drift) with handling bursts.

    Returns time [s], rate [°/s], accelerometer z [g] and the truth mask of the handling.
    Each burst is a turn: a half-sine rate pulse of 20-200 °/s lasting 1-4 s, with a
    shake (±5 °/s at 7 Hz... aliased) and a tilt of the accelerometer during it.
    """
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, hours * 3600.0, 1.0 / fs)
    rate = offset_dps + 0.3 * np.sin(2 * np.pi * t / (hours * 3600.0)) \
        + noise_dps * rng.standard_normal(t.size)
    accel = 1.0 + 0.002 * rng.standard_normal(t.size)
    truth = np.zeros(t.size, dtype=bool)
    starts = np.linspace(0.1, 0.9, bursts) * t[-1]
    for start in starts:
        length = rng.uniform(1.0, 4.0)
        inside = (t >= start) & (t < start + length)
        phase = (t[inside] - start) / length
        rate[inside] += rng.uniform(20.0, 200.0) * np.sin(np.pi * phase) * rng.choice([-1, 1])
        rate[inside] += 5.0 * rng.standard_normal(inside.sum())
        accel[inside] += 0.3 * np.sin(np.pi * phase)
        truth |= inside
    return t, rate, accel, truth


def test_handling_bursts_are_found_and_still_samples_are_kept():
    t, rate, _, truth = handled()
    mask = detect_motion(t, rate * 3600.0)  # in °/h: the detector is unit-free
    assert mask.moving[truth].all()
    # what is marked besides the truth lies within a variance block and a guard of a burst
    near = np.zeros_like(truth)
    for k in np.flatnonzero(truth):
        near[max(k - 10 * 5, 0):k + 10 * 10] = True
    assert not (mask.moving & ~near).any()
    assert mask.n_moving <= truth.sum() + 6 * (5.0 + 1.0 + 2 * 3.2) * 10
    assert mask.counts()["guard"] > 0


def test_a_mems_axis_at_four_dps_at_rest_is_not_motion():
    t, rate, _, _ = handled(bursts=0, offset_dps=4.0)
    mask = detect_motion(t, rate)
    assert mask.n_moving == 0
    assert mask.noise["rate"] == pytest.approx(0.02, rel=0.1)


def test_a_known_input_rate_is_not_motion():
    t, rate, _, _ = handled(bursts=0, offset_dps=0.0)
    table = np.where(t > 3600.0, 36.0, 0.0)  # a rate-table step
    assert detect_motion(t, rate + table, input_rate=table).n_moving == 0
    assert detect_motion(t, rate + table).n_moving > 0


def test_single_sample_spikes_are_not_motion():
    t, rate, _, _ = handled(bursts=0)
    rate[[100, 5000, 40000]] -= 5.7  # -0.1 rad/s, as in the real cold test
    assert detect_motion(t, rate).n_moving == 0


def test_shaking_without_net_rate_is_found_by_the_variance_test():
    t, rate, _, _ = handled(bursts=0)
    shake = (t > 1000.0) & (t < 1030.0)
    rate[shake] += 0.1 * np.random.default_rng(5).standard_normal(shake.sum())  # 5σ spread
    mask = detect_motion(t, rate, settings=MotionSettings(threshold=1e3))  # level test off
    assert mask.reasons["variance"][shake].mean() > 0.8
    block = 3.2  # s: 32 samples, the shortest variance block
    assert not mask.reasons["variance"][(t < 1000.0 - block) | (t > 1030.0 + block)].any()


def test_accelerometer_tilt_marks_motion_the_gyro_misses():
    t, rate, accel, truth = handled(bursts=3)
    quiet = np.where(truth, 4.0, rate)  # the gyro shows nothing
    mask = detect_motion(t, quiet, accel={"accel_z": accel})
    assert mask.reasons["accelerometer"][truth].mean() > 0.5
    assert mask.moving[truth].mean() > 0.9


def test_a_clipped_plateau_is_motion():
    t, rate, _, _ = handled(bursts=0)
    rate[2000:2003] = 300.0  # saturated for three samples (shorter than min_motion_s? no: 0.3 s)
    mask = detect_motion(t, rate, settings=MotionSettings(min_motion_s=10.0))
    assert mask.reasons["clipped"][2000:2003].all()
    assert mask.reasons["level"].sum() == 0


def test_windows_and_guards_never_cross_a_gap():
    t, rate, _, _ = handled(bursts=0, hours=0.5)
    t = np.where(t >= 900.0, t + 300.0, t)  # a 300 s gap at 900 s
    just_before = np.flatnonzero(t < 900.0)[-20:]
    rate[just_before] += 100.0
    mask = detect_motion(t, rate)
    assert mask.moving[just_before].all()
    assert not mask.moving[t >= 1200.0].any()  # the guard stops at the gap
    assert segments_of(t).max() == 1
    periods = mask.still_periods(time_s=t, min_s=60.0)
    assert all(mask.segment[a] == mask.segment[b - 1] for a, b in periods)
    assert len(periods) == 2


def test_burst_recording_each_burst_its_own_baseline():
    # a 5 s burst every 300 s whose level steps between bursts (an offset change): no motion
    fs, rng = 50.0, np.random.default_rng(2)
    t = np.concatenate([300.0 * k + np.arange(0.0, 5.0, 1 / fs) for k in range(20)])
    level = np.repeat(np.linspace(0.0, 2.0, 20), int(5 * fs))
    rate = level + 0.01 * rng.standard_normal(t.size)
    assert detect_motion(t, rate).n_moving == 0


@pytest.mark.skipif(not PAN.exists(), reason="real cold test not in the checkout")
def test_the_real_cold_test_is_at_rest():
    data = np.genfromtxt(PAN, delimiter=",", skip_header=1)
    rates = {axis: data[:, 4 + k] for k, axis in enumerate("xyz")}  # rad/s
    mask = detect_motion(data[:, 0] / 1000.0, rates)
    assert mask.fraction <= 0.005
    assert mask.segment.max() + 1 == 25  # 25 bursts, each its own segment


def test_bad_input_is_refused_with_the_row():
    t = np.arange(100.0)
    rate = np.zeros(100)
    rate[7] = np.nan
    with pytest.raises(InputError, match="row 7"):
        detect_motion(t, rate)
    with pytest.raises(InputError, match="one value per sample"):
        detect_motion(t, np.zeros(99))
    with pytest.raises(InputError, match="guard_s"):
        MotionSettings(guard_s=-1.0)


def test_orientations_cluster_by_angle_and_unknown_is_not_guessed():
    vectors = [[0, 0, 9.81], [0.05, 0, 9.8], [9.81, 0, 0], [0, -9.81, 0], [0, 0, 9.79]]
    labels, centres = orientation_labels(vectors)
    assert labels.tolist() == [0, 0, 1, 2, 0]
    again, _ = orientation_labels([[0, 0, 1], [-1, 0, 0]], centres=centres)
    assert again.tolist() == [0, -1]
