"""The Allan deviation and the noise model on a real gyro's rates: the VN-100's z axis over
its long still cool-down (s 1860-3250 of its README, 10 Hz, uncompensated), read by numpy.

* the overlapping Allan deviation equals numpy's formula on the phase (the rate's sum);
* the fitted angle random walk is the white rate noise numpy finds in the first differences
  (σ of the differences / √2, times √τ0, in °/√h), within 5 %.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from hrgtc.evaluation.allan import allan_deviation
from hrgtc.evaluation.noise_model import fit_noise_model

VN100 = (Path(__file__).resolve().parents[1] / "data" / "vn100-waves-in-ice"
         / "vn100_F00379-F00383.csv")
RATE_HZ = 10.0
DPH_PER_RADPS = 180.0 / np.pi * 3600.0


@pytest.fixture(scope="module")
def still_z() -> np.ndarray:
    """The z rate at rest during the cool-down [°/h] (the logger's millis / 1000 in s)."""
    c = np.genfromtxt(VN100, delimiter=",", names=True, usecols=("millis", "GyroZ"))
    s = c["millis"] / 1000.0
    return c["GyroZ"][(s >= 1860.0) & (s < 3250.0)] * DPH_PER_RADPS


def _numpy_oadev(rate: np.ndarray, m: int) -> float:
    x = np.concatenate([[0.0], np.cumsum(rate)]) / RATE_HZ
    d = x[2 * m:] - 2.0 * x[m:-m] + x[:-2 * m]
    return float(np.sqrt(np.mean(d * d) / 2.0) / (m / RATE_HZ))


def test_the_allan_deviation_of_a_real_rate_is_numpy_s(still_z):
    allan = allan_deviation(still_z, RATE_HZ, confidence=0.683)
    tau = np.asarray(allan.taus_s)
    assert tau.size >= 8
    for t, value in zip(tau, np.asarray(allan.deviation), strict=True):
        assert value == pytest.approx(_numpy_oadev(still_z, round(t * RATE_HZ)), rel=1e-9)


def test_the_noise_model_s_angle_random_walk_is_the_white_noise_numpy_finds(still_z):
    model = fit_noise_model(allan_deviation(still_z, RATE_HZ, confidence=0.683), bootstrap=50)
    white_dph = np.std(np.diff(still_z)) / np.sqrt(2.0)
    numpy_arw = white_dph * np.sqrt(1.0 / RATE_HZ) / 60.0  # °/h·√s -> °/√h
    assert "angle_random_walk" in model.fitted, model.fitted
    arw = model.terms["angle_random_walk"]
    assert arw == pytest.approx(numpy_arw, rel=0.05), (arw, numpy_arw)
